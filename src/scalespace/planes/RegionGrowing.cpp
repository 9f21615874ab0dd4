#include "scalespace/planes/RegionGrowing.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/RadixSort.hpp"
#include "scalespace/planes/AlphaShapeArea.hpp"

namespace scalespace {

Segmentation growRegions(const KnnGraph& graph, const ScaleFeatures& scale,
                         const RegionGrowingOptions& options) {
  const std::size_t n = graph.size();
  if (scale.normals.size() != n || scale.kMax.size() != n || scale.kMin.size() != n ||
      scale.valid.size() != n)
    throw OptionError("region growing: the scale features and the neighbour graph differ in size");
  if (!(options.maxAngleDegrees > 0 && options.maxAngleDegrees < 180))
    throw OptionError("region growing angle must be in (0, 180) degrees");
  const double cosTheta = std::cos(options.maxAngleDegrees * M_PI / 180.0);

  // Seeds by decreasing planarity (k1^2 + k2^2)^-1 = increasing k1^2 + k2^2, ties by increasing
  // point index, so the result does not depend on anything else: a stable radix sort of the
  // keys' bits (monotone for doubles >= 0) over increasing indices.
  std::vector<KeyedIndex> order;
  order.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double c = double(scale.kMax[i]) * scale.kMax[i] + double(scale.kMin[i]) * scale.kMin[i];
    if (scale.valid[i] && std::isfinite(c) && scale.normals[i].allFinite())
      order.push_back({orderedKey(c), Index(i)});
  }
  radixSortStable(order);

  // The walk runs over the graph's vertices: the Morton-ordered copy when there is one (see
  // KnnGraph), so that the per-vertex arrays below are read near where they were last read.
  // The regions (which points, which seed first) are the same in either numbering.
  const bool local =
      graph.order.size() == n && graph.localNeighbors.size() == graph.neighbors.size();
  const std::vector<Index>& adjacency = local ? graph.localNeighbors : graph.neighbors;
  auto pointOf = [&](Index v) { return local ? graph.order[v] : v; };
  // What the walk reads of a free neighbour, its label and normal, in one 32-byte slot (two
  // cache misses per edge with separate arrays).
  struct alignas(32) Vertex {
    double normal[3];
    int label;  // -1 free, -2 invalid (joins no region), else the region
  };
  std::vector<Vertex> vertex(n);
  // One bit per vertex, set once it is taken (labelled or invalid): the walk tests it before
  // reading the slot. Most tests are of taken vertices (a vertex has ~10 in-edges and is
  // labelled through one; most seeds were reached by an earlier region), and the bits of 1M
  // vertices (125 KB) stay in cache where their slots (32 MB) do not.
  std::vector<std::uint64_t> taken((n + 63) / 64, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, taken.size()), [&](const auto& r) {
    for (std::size_t w = r.begin(); w != r.end(); ++w) {
      std::uint64_t bits = 0;
      for (std::size_t v = 64 * w; v < std::min(n, 64 * w + 64); ++v) {
        const Index i = pointOf(Index(v));
        const Vec3& normal = scale.normals[i];
        vertex[v] = {{normal.x(), normal.y(), normal.z()}, scale.valid[i] ? -1 : -2};
        if (!scale.valid[i]) bits |= std::uint64_t(1) << (v - 64 * w);
      }
      taken[w] = bits;
    }
  });
  auto isTaken = [&](Index v) { return (taken[v >> 6] >> (v & 63)) & 1; };
  auto take = [&](Index v, int id) {
    vertex[v].label = id;
    taken[v >> 6] |= std::uint64_t(1) << (v & 63);
  };
  // The seeds as vertices, mapped in one parallel pass (a random read each) before the walk.
  std::vector<Index> seeds(order.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 4096), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s)
      seeds[s] = local ? graph.rank[order[s].index] : order[s].index;
  });

  // The walk labels the regions; their point lists are then filled in one pass over the points
  // in index order, which gives the increasing lists without sorting each region.
  std::vector<Index> frontier;
  std::vector<std::size_t> regionSize;
  for (const Index seed : seeds) {
    if (isTaken(seed)) continue;
    const int id = int(regionSize.size());
    const double* seedNormal = vertex[seed].normal;
    const double sx = seedNormal[0], sy = seedNormal[1], sz = seedNormal[2];
    std::size_t size = 1;
    take(seed, id);
    frontier.assign(1, seed);
    while (!frontier.empty()) {
      const Index p = frontier.back();
      frontier.pop_back();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        const Index v = adjacency[e];
        if (isTaken(v)) continue;
        const double* normal = vertex[v].normal;
        // Against the seed's normal, not the neighbour's: the region stays planar (Sec. 2.3.1).
        // (Vec3::dot's order of operations, so the regions are those of the Vec3 version.)
        if (!(normal[0] * sx + normal[1] * sy + normal[2] * sz >= cosTheta)) continue;
        take(v, id);
        ++size;
        frontier.push_back(v);
      }
    }
    regionSize.push_back(size);
  }
  Segmentation seg;
  seg.labels.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v) seg.labels[pointOf(Index(v))] = std::max(vertex[v].label, -1);
  seg.regions.resize(regionSize.size());
  for (std::size_t r = 0; r < regionSize.size(); ++r) seg.regions[r].reserve(regionSize[r]);
  for (std::size_t i = 0; i < n; ++i)
    if (seg.labels[i] >= 0) seg.regions[std::size_t(seg.labels[i])].push_back(Index(i));
  return seg;
}

std::vector<FilteredRegion> filterRegions(const std::vector<Vec3>& positions,
                                          const Segmentation& segmentation, double t,
                                          const RegionFilterOptions& options,
                                          const ProgressCallback& progress) {
  if (!(t > 0) || !(options.alphaFactor > 0))
    throw OptionError("region filter: scale and alpha factor must be positive");
  const double radius = options.alphaFactor * t;
  const auto& regions = segmentation.regions;
  std::vector<std::uint8_t> keep(regions.size(), 0);
  ProgressTracker tracker(progress, "region filter", regions.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, regions.size(), 1), [&](const auto& range) {
    for (std::size_t r = range.begin(); r != range.end(); ++r) {
      // A region whose point count cannot reach the area is skipped without an alpha shape:
      // fewer than 3 points have zero area.
      if (regions[r].size() < 3) continue;
      const PlaneFit plane = fitPlane(positions, regions[r]);
      keep[r] = alphaShapeAreaAtLeast(projectOnPlane(plane, positions, regions[r]), radius * radius,
                                      radius * radius);
    }
    tracker.advance(range.size());
  });
  tracker.finish();
  std::vector<FilteredRegion> kept;
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (keep[r]) kept.push_back({regions[r]});
  return kept;
}

}  // namespace scalespace
