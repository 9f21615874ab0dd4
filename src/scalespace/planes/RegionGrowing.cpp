#include "scalespace/planes/RegionGrowing.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "scalespace/core/Error.hpp"
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

  // Seeds by decreasing planarity (k1^2 + k2^2)^-1 = increasing k1^2 + k2^2; a stable sort of
  // indices keeps the lower index first on ties, so the result does not depend on anything else.
  // Sorted as (key, index) pairs: the same order as a stable sort of the indices, with the key
  // next to its index (no indirection) and both cores at work.
  std::vector<std::pair<double, Index>> order;
  order.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double c = double(scale.kMax[i]) * scale.kMax[i] + double(scale.kMin[i]) * scale.kMin[i];
    if (scale.valid[i] && std::isfinite(c) && scale.normals[i].allFinite())
      order.emplace_back(c, Index(i));
  }
  tbb::parallel_sort(order.begin(), order.end());
  std::vector<Index> seeds(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) seeds[k] = order[k].second;

  Segmentation seg;
  seg.labels.assign(n, -1);
  std::vector<Index> frontier;
  for (Index seed : seeds) {
    if (seg.labels[seed] >= 0) continue;
    const int label = int(seg.regions.size());
    const Vec3 seedNormal = scale.normals[seed];
    std::vector<Index> region{seed};
    seg.labels[seed] = label;
    frontier.assign(1, seed);
    while (!frontier.empty()) {
      const Index p = frontier.back();
      frontier.pop_back();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        const Index q = graph.neighbors[e];
        if (seg.labels[q] >= 0 || !scale.valid[q]) continue;
        // Against the seed's normal, not the neighbour's: the region stays planar (Sec. 2.3.1).
        if (!(scale.normals[q].dot(seedNormal) >= cosTheta)) continue;
        seg.labels[q] = label;
        region.push_back(q);
        frontier.push_back(q);
      }
    }
    std::sort(region.begin(), region.end());
    seg.regions.push_back(std::move(region));
  }
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
