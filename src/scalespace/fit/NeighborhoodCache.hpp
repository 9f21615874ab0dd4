#pragma once
// NeighborhoodCache: the samples near a group of nearby evaluation points, fetched once.
//
// The multi-scale projection (scales/ScaleSpace, Sec. 1.5) fits at consecutive points of a
// Morton-ordered cloud: at a coarse scale t, dozens of consecutive points lie within a small
// fraction of t of each other and share most of their neighbours. prefetch() copies, with one
// index query, the positions and normals of every sample within R of a centre c; a later fit at
// y with support t then reads them instead of querying the index, whenever |y - c| + t <= R
// (every sample within t of y is then within R of c, by the triangle inequality). The fit keeps
// exactly the samples with |p - y|^2 < t^2, the index's contract, so the result is the same up to
// the order in which the neighbours are summed.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/fit/NeighborColumns.hpp"

namespace scalespace {

struct SurfaceSamples;

class NeighborhoodCache {
 public:
  /// Fetches the samples within `radius` of `center`. A radius <= 0 or a non-finite centre
  /// leaves the cache empty.
  void prefetch(const SurfaceSamples& samples, const Vec3& center, double radius);
  /// Forgets the prefetched ball. The driver must clear (or re-prefetch) the cache before fitting
  /// on other samples: a cache only remembers the address of the index it was filled from.
  void clear() {
    radius_ = 0;
    source_ = nullptr;
  }
  /// True when every sample of `samples` within r of q is in the cache.
  bool covers(const SurfaceSamples& samples, const Vec3& q, double r) const;

  /// The prefetched samples, as columns (fit/NeighborColumns: gatherWithin reads them). The
  /// normal columns are empty when the samples have no normals.
  const SampleColumns& samples() const { return samples_; }

  /// Fits served from the cache / from the index since construction (benchmarks, tests).
  std::size_t hits = 0, misses = 0;

 private:
  const SpatialIndex* source_ = nullptr;
  Vec3 center_ = Vec3::Zero();
  double radius_ = 0;
  SampleColumns samples_;
  std::vector<Neighbor> found_;
};

/// How far apart the evaluation points of one prefetched block may be: the half-diagonal of
/// their bounding box is at most kBlockSpread t. Larger spreads make fewer index queries but
/// longer candidate lists to scan (on a surface the list grows like (1 + spread + slack)^2).
/// 0.5 balances the two: the projection time is flat around it (bench/fig_1_10 --mode timing
/// --threads 1).
constexpr double kBlockSpread = 0.5;

/// Evaluation points are walked in fixed groups of kPrefetchGroup consecutive (Morton-ordered)
/// points, each cut into blocks: the groups, hence the blocks and the order in which neighbours
/// are summed, do not depend on the thread count.
constexpr std::size_t kPrefetchGroup = 64;
/// How far (a fraction of t) MLS steps may move a point out of its block and still read the
/// prefetched samples.
constexpr double kMlsSlack = 0.1;

/// Forms the block of evaluation points points[k..end) that starts at k, ends at most at
/// `last` and spans at most kBlockSpread t, and prefetches the samples that the radius-t fits of
/// the whole block need: a ball of radius t (1 + slack) + half-diagonal around the block's
/// centre. A single-point block empties the cache instead (a plain query is cheaper). Returns end.
std::size_t prefetchBlock(const std::vector<Vec3>& points, std::size_t k, std::size_t last,
                          const SurfaceSamples& samples, double t, double slack,
                          NeighborhoodCache& cache);

/// Calls fit(k, count) for the points of group g (points [g kPrefetchGroup, ...)), block by
/// block, each block's samples prefetched into `cache` first, in runs of `maxRun` consecutive
/// points (count <= maxRun; the last run of a block may be shorter). Returns the number of points
/// of the group.
template <class Fit>
std::size_t fitGroupInRuns(const std::vector<Vec3>& points, std::size_t g,
                           const SurfaceSamples& samples, double t, double slack,
                           NeighborhoodCache& cache, std::size_t maxRun, Fit&& fit) {
  const std::size_t begin = g * kPrefetchGroup;
  const std::size_t end = std::min(points.size(), begin + kPrefetchGroup);
  for (std::size_t k = begin; k < end;) {
    const std::size_t blockEnd = prefetchBlock(points, k, end, samples, t, slack, cache);
    for (; k < blockEnd; k += std::min(maxRun, blockEnd - k))
      fit(k, std::min(maxRun, blockEnd - k));
  }
  return end - begin;
}

/// fitGroupInRuns one point at a time: fit(k) for every point of group g.
template <class Fit>
std::size_t fitGroupByBlocks(const std::vector<Vec3>& points, std::size_t g,
                             const SurfaceSamples& samples, double t, double slack,
                             NeighborhoodCache& cache, Fit&& fit) {
  return fitGroupInRuns(points, g, samples, t, slack, cache, 1,
                        [&](std::size_t k, std::size_t) { fit(k); });
}

}  // namespace scalespace
