#include "scalespace/planes/PlaneDetection.hpp"

#include <chrono>

#include "scalespace/core/Error.hpp"

namespace scalespace {

namespace {
double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

PlaneDetection detectPlanes(const std::vector<Vec3>& positions, const KnnGraph& knn,
                            const std::vector<ScaleFeatures>& scales,
                            const PlaneDetectionOptions& options,
                            const ProgressCallback& progress) {
  if (knn.size() != positions.size())
    throw OptionError("plane detection: the neighbour graph was built on another cloud");
  checkScaleFeatures(scales, positions.size());
  PlaneDetection result;
  std::vector<RegionLevel> levels(scales.size());
  // Progress of the per-scale loop: one tick per scale, the filter's own progress is not nested.
  for (std::size_t j = 0; j < scales.size(); ++j) {
    if (progress && !progress(double(j) / double(scales.size()), "planar segmentations"))
      throw Cancelled();
    auto start = std::chrono::steady_clock::now();
    const Segmentation seg = growRegions(knn, scales[j], options.growing);
    result.timings.segmentation += secondsSince(start);
    start = std::chrono::steady_clock::now();
    RegionFilterOptions filter;
    filter.alphaFactor = options.alphaFactor;
    levels[j].t = scales[j].t;
    levels[j].regions = filterRegions(positions, seg, scales[j].t, filter);
    result.timings.filtering += secondsSince(start);
  }
  auto start = std::chrono::steady_clock::now();
  result.graph = buildRegionGraph(std::move(levels), positions.size(), options.minJaccard);
  result.timings.graph = secondsSince(start);
  start = std::chrono::steady_clock::now();
  ComponentOptions componentOptions;
  componentOptions.alphaFactor = options.alphaFactor;
  componentOptions.outlines = options.outlines;
  result.components = extractComponents(result.graph, positions, componentOptions, progress);
  result.timings.components = secondsSince(start);
  return result;
}

}  // namespace scalespace
