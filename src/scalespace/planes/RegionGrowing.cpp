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
  // What the walk reads of a neighbour, its label and normal, in one 32-byte slot: the walk is
  // bound by these reads (two cache misses per edge with separate arrays).
  struct alignas(32) Vertex {
    double normal[3];
    int label;  // -1 free, -2 invalid (joins no region), else the region
  };
  std::vector<Vertex> vertex(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t v) {
    const Index i = pointOf(Index(v));
    const Vec3& normal = scale.normals[i];
    vertex[v] = {{normal.x(), normal.y(), normal.z()}, scale.valid[i] ? -1 : -2};
  });

  // The walk labels the regions; their point lists are then filled in one pass over the points
  // in index order, which gives the increasing lists without sorting each region.
  std::vector<Index> frontier;
  std::vector<std::size_t> regionSize;
  for (const KeyedIndex& item : order) {
    const Index seed = local ? graph.rank[item.index] : item.index;
    if (vertex[seed].label != -1) continue;
    const int id = int(regionSize.size());
    const double* seedNormal = vertex[seed].normal;
    const double sx = seedNormal[0], sy = seedNormal[1], sz = seedNormal[2];
    std::size_t size = 1;
    vertex[seed].label = id;
    frontier.assign(1, seed);
    while (!frontier.empty()) {
      const Index p = frontier.back();
      frontier.pop_back();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        Vertex& q = vertex[adjacency[e]];
        if (q.label != -1) continue;
        // Against the seed's normal, not the neighbour's: the region stays planar (Sec. 2.3.1).
        // (Vec3::dot's order of operations, so the regions are those of the Vec3 version.)
        if (!(q.normal[0] * sx + q.normal[1] * sy + q.normal[2] * sz >= cosTheta)) continue;
        q.label = id;
        ++size;
        frontier.push_back(adjacency[e]);
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
