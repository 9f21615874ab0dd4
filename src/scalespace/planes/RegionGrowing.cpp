#include "scalespace/planes/RegionGrowing.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/planes/AlphaShapeArea.hpp"

namespace scalespace {

namespace {
// Sec. 2.3.1's criterion: a neighbour joins when its normal is within theta of the SEED's normal
// (not the neighbour's), so the region stays planar.
struct SeedNormalCriterion {
  using Normal = std::array<double, 3>;
  const std::vector<Vec3>& normals;
  double cosTheta;
  Normal payload(Index point) const {
    const Vec3& n = normals[point];
    return {n.x(), n.y(), n.z()};
  }
  bool accept(const Normal& seed, const Normal&, const Normal& normal) const {
    // Vec3::dot's order of operations, so the regions are those of the Vec3 version.
    return normal[0] * seed[0] + normal[1] * seed[1] + normal[2] * seed[2] >= cosTheta;
  }
};

/// The same, and a step may not cross more than maxStep along the seed's normal: the projection
/// of the point joining and that of the region point it is reached from lie in planes (with the
/// seed's orientation) at most max(maxStep, |edge| sin(theta)) apart. Parallel faces offset by a
/// few centimetres (a tile on a roof, a tread above the ground) have the same normal, so the angle
/// alone joins them through any graph edge that spans the step (docs/THESIS_NOTES.md, region
/// growing offset).
struct SeedNormalAndStepCriterion {
  struct Slot {
    double normal[3];
    double position[3];
  };
  const std::vector<Vec3>& normals;
  const std::vector<Vec3>& projections;
  double cosTheta, sinTheta, maxStep;
  Slot payload(Index point) const {
    const Vec3 &n = normals[point], &p = projections[point];
    return {{n.x(), n.y(), n.z()}, {p.x(), p.y(), p.z()}};
  }
  bool accept(const Slot& seed, const Slot& from, const Slot& candidate) const {
    const double* n = seed.normal;
    const double* m = candidate.normal;
    if (!(m[0] * n[0] + m[1] * n[1] + m[2] * n[2] >= cosTheta)) return false;
    const double d[3] = {candidate.position[0] - from.position[0],
                         candidate.position[1] - from.position[1],
                         candidate.position[2] - from.position[2]};
    const double step = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    // A face tilted by theta against the seed's normal, which the angle test accepts, rises by
    // up to |d| sin(theta) over the edge: at the finest scales the edges to the 10th neighbour
    // are about t long, so 0.087 t of rise is no step.
    const double tilt = sinTheta * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return std::abs(step) <= std::max(maxStep, tilt);
  }
};
}  // namespace

void validateRegionGrowingOptions(const RegionGrowingOptions& options) {
  if (!(options.maxAngleDegrees > 0 && options.maxAngleDegrees < 180))
    throw OptionError("RegionGrowingOptions::maxAngleDegrees must be in (0, 180)");
  if (!(options.maxStep >= 0) || !std::isfinite(options.maxStep))
    throw OptionError("RegionGrowingOptions::maxStep must be finite and >= 0");
}

void validateRegionFilterOptions(const RegionFilterOptions& options) {
  if (!(options.alphaFactor > 0) || !std::isfinite(options.alphaFactor))
    throw OptionError("RegionFilterOptions::alphaFactor must be positive");
}

Segmentation growRegions(const KnnGraph& graph, const ScaleFeatures& scale,
                         const RegionGrowingOptions& options) {
  const std::size_t n = graph.size();
  if (scale.normals.size() != n || scale.kMax.size() != n || scale.kMin.size() != n ||
      scale.valid.size() != n)
    throw OptionError("region growing: the scale features and the neighbour graph differ in size");
  validateRegionGrowingOptions(options);
  if (options.maxStep > 0 && scale.projections.size() != n)
    throw OptionError(
        "RegionGrowingOptions::maxStep needs the projections of the scale (ScaleFeatures)");
  const double cosTheta = std::cos(options.maxAngleDegrees * M_PI / 180.0);
  const double sinTheta = std::sin(options.maxAngleDegrees * M_PI / 180.0);
  // Seeds by decreasing planarity (k1^2 + k2^2)^-1 = increasing k1^2 + k2^2, ties by increasing
  // point index, so the result does not depend on anything else. A point with a non-finite
  // normal or curvature seeds nothing.
  std::vector<Index> seeds = seedsByIncreasingKey(n, [&](Index i) {
    if (!scale.valid[i] || !scale.normals[i].allFinite())
      return std::numeric_limits<double>::quiet_NaN();
    return double(scale.kMax[i]) * scale.kMax[i] + double(scale.kMin[i]) * scale.kMin[i];
  });
  if (options.maxStep > 0)
    return growRegionsFromSeeds(
        graph, std::move(seeds), scale.valid,
        SeedNormalAndStepCriterion{scale.normals, scale.projections, cosTheta, sinTheta,
                                   options.maxStep * scale.t});
  return growRegionsFromSeeds(graph, std::move(seeds), scale.valid,
                              SeedNormalCriterion{scale.normals, cosTheta});
}

std::vector<std::vector<Index>> filterRegions(const std::vector<Vec3>& positions,
                                              const Segmentation& segmentation, double t,
                                              const RegionFilterOptions& options,
                                              const ProgressCallback& progress) {
  if (!(t > 0)) throw OptionError("region filter: the scale t must be positive");
  validateRegionFilterOptions(options);
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
  std::vector<std::vector<Index>> kept;
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (keep[r]) kept.push_back(regions[r]);
  return kept;
}

}  // namespace scalespace
