#include "scalespace/planes/PlaneDetection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "scalespace/core/Error.hpp"

namespace scalespace {

namespace {
RegionFilterOptions filterOptionsOf(const PlaneDetectionOptions& options) {
  RegionFilterOptions filter;
  filter.alphaFactor = options.alphaFactor;
  return filter;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

void validatePlaneDetectionOptions(const PlaneDetectionOptions& options) {
  validateRegionGrowingOptions(options.growing);
  validateRegionFilterOptions(filterOptionsOf(options));
  validate(options.planarity);
  validate(options.merging);
  validate(options.refinement);
  if (!(options.minJaccard >= 0 && options.minJaccard < 1))
    throw OptionError("PlaneDetectionOptions::minJaccard must be in [0, 1)");
}

RegionLevel segmentScale(const std::vector<Vec3>& positions, const KnnGraph& knn,
                         const ScaleFeatures& scale, double noiseRms,
                         const PlaneDetectionOptions& options, PlaneDetectionTimings& timings) {
  auto start = std::chrono::steady_clock::now();
  Segmentation seg = growRegions(knn, scale, options.growing);
  std::vector<RegionOrigin> origins;
  if (options.merging.maxRelativeRms > 0)
    seg = mergeCoplanarRegions(positions, knn, std::move(seg), scale.t,
                               std::pow(options.alphaFactor * scale.t, 2), noiseRms,
                               options.merging, &origins);
  timings.segmentation += secondsSince(start);
  start = std::chrono::steady_clock::now();
  RegionLevel level;
  level.t = scale.t;
  level.regions = filterRegions(positions, seg, scale.t, filterOptionsOf(options));
  timings.filtering += secondsSince(start);
  if (options.refinement.maxRelativeDistance > 0 &&
      std::find(origins.begin(), origins.end(), RegionOrigin::merged) != origins.end()) {
    // Among the regions the filter kept, so that no point leaves a kept region for a union that
    // the filter then drops (and only where there is a union: no relabelling copy otherwise).
    start = std::chrono::steady_clock::now();
    Segmentation kept;
    kept.labels.assign(positions.size(), -1);
    std::vector<RegionOrigin> keptOrigins;
    for (std::vector<Index>& region : level.regions) {
      if (region.empty()) continue;
      keptOrigins.push_back(origins[std::size_t(seg.labels[region.front()])]);
      for (const Index i : region) kept.labels[i] = int(kept.regions.size());
      kept.regions.push_back(std::move(region));
    }
    kept = refineRegionBoundaries(positions, knn, std::move(kept), keptOrigins, scale.t, noiseRms,
                                  options.refinement);
    level.regions = std::move(kept.regions);
    timings.segmentation += secondsSince(start);
  }
  return level;
}

PlaneDetection buildPlaneDetection(const std::vector<Vec3>& positions,
                                   std::vector<RegionLevel> levels, double noiseRms,
                                   const PlaneDetectionOptions& options,
                                   PlaneDetectionTimings timings,
                                   const ProgressCallback& progress) {
  PlaneDetection result;
  result.timings = timings;
  auto start = std::chrono::steady_clock::now();
  if (!(noiseRms >= 0) || !std::isfinite(noiseRms))
    throw OptionError("plane detection: the noise RMS must be finite and >= 0");
  result.noiseRms = noiseRms;
  result.planaritySplit = options.planarity.maxRelativeRms > 0;
  const auto planar = regionPlanarity(positions, levels, result.noiseRms, options.planarity);
  for (const auto& level : planar)
    result.nonPlanarRegions += std::size_t(std::count(level.begin(), level.end(), 0));
  RegionLinkOptions linking;
  linking.minJaccard = options.minJaccard;
  linking.kinds = &planar;
  result.graph = buildRegionGraph(std::move(levels), positions.size(), linking);
  result.timings.graph = secondsSince(start);
  start = std::chrono::steady_clock::now();
  ComponentOptions componentOptions;
  componentOptions.alphaFactor = options.alphaFactor;
  componentOptions.outlines = options.outlines;
  componentOptions.maxRelativeRms = options.planarity.maxRelativeRms > 0
                                        ? options.planarity.maxRelativeRms
                                        : componentOptions.maxRelativeRms;
  componentOptions.noiseFactor = options.planarity.noiseFactor;
  componentOptions.noiseRms = result.noiseRms;
  result.components = extractComponents(result.graph, positions, componentOptions, progress);
  result.timings.components = secondsSince(start);
  return result;
}

PlaneDetection detectPlanes(const std::vector<Vec3>& positions, const KnnGraph& knn,
                            const std::vector<ScaleFeatures>& scales,
                            const PlaneDetectionOptions& options,
                            const ProgressCallback& progress) {
  validatePlaneDetectionOptions(options);
  if (knn.size() != positions.size())
    throw OptionError("plane detection: the neighbour graph was built on another cloud");
  checkScaleFeatures(scales, positions.size());
  const double noise = pointNoiseRms(positions, knn);
  PlaneDetectionTimings timings;
  std::vector<RegionLevel> levels;
  for (std::size_t j = 0; j < scales.size(); ++j) {
    if (progress && !progress(double(j) / double(scales.size()), "planar segmentations"))
      throw Cancelled();
    levels.push_back(segmentScale(positions, knn, scales[j], noise, options, timings));
  }
  return buildPlaneDetection(positions, std::move(levels), noise, options, timings, progress);
}

}  // namespace scalespace
