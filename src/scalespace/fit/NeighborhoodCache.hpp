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
#include <cstddef>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

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

  const std::vector<Vec3>& positions() const { return positions_; }
  const std::vector<Vec3>& normals() const { return normals_; }

  /// Fits served from the cache / from the index since construction (benchmarks, tests).
  std::size_t hits = 0, misses = 0;

 private:
  const SpatialIndex* source_ = nullptr;
  Vec3 center_ = Vec3::Zero();
  double radius_ = 0;
  std::vector<Vec3> positions_, normals_;
  std::vector<Neighbor> found_;
};

}  // namespace scalespace
