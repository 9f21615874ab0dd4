#include "scalespace/planes/StackPlanes.hpp"

#include <chrono>

#include "scalespace/core/Error.hpp"

namespace scalespace {

ScaleFeatures scaleFeaturesFromLayer(const ScaleLayer& layer, double t) {
  const std::size_t n = layer.size();
  if (layer.normal.size() != 3 * n || layer.kMax.size() != n || layer.kMin.size() != n)
    throw Error("scale layer arrays have inconsistent sizes");
  ScaleFeatures f;
  f.t = t;
  f.normals.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    f.normals[i] = Vec3(layer.normal[3 * i], layer.normal[3 * i + 1], layer.normal[3 * i + 2]);
  f.kMax = layer.kMax;
  f.kMin = layer.kMin;
  f.valid = layer.valid;
  return f;
}

StackPlaneDetection detectPlanesInCloud(const PointCloud& cloud,
                                        const ScaleSpaceOptions& stackOptions,
                                        const PlaneDetectionOptions& options,
                                        const ProgressCallback& progress) {
  const auto begin = std::chrono::steady_clock::now();
  StackPlaneDetection out;
  const auto& positions = cloud.positions();
  auto start = std::chrono::steady_clock::now();
  const KnnGraph knn = buildKnnGraph(positions, 10);  // k = 10 (Sec. 2.3.1)
  out.knnSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PlaneDetectionTimings timings;
  std::vector<RegionLevel> levels;
  const ScaleSink sink = [&](std::size_t, const ScaleLayer& layer, const ScaleStats& stats) {
    levels.push_back(
        segmentScale(positions, knn, scaleFeaturesFromLayer(layer, stats.t), options, timings));
  };
  start = std::chrono::steady_clock::now();
  ScaleSpaceOptions stack = stackOptions;
  // The graph's queries are those of the automatic t_min when its k is the series' K (both 10:
  // Sec. 1.5.1 and 2.3.1).
  if (!knn.kthDistance.empty() && stack.series.K > 0 &&
      std::size_t(stack.series.K) * knn.size() == knn.neighbors.size())
    stack.series.knownMedianKnnRadius = lowerMedian(knn.kthDistance);
  stack.layerContents = LayerContents::NormalAndCurvatures;  // what scaleFeaturesFromLayer reads
  out.stack = runScaleSpace(cloud, stack, sink, progress);
  out.stackSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() -
      timings.segmentation - timings.filtering;
  out.detection = buildPlaneDetection(positions, std::move(levels), options, timings, progress);
  out.totalSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return out;
}

PlaneDetection detectPlanesFromStack(const PointCloud& cloud, const ScaleStackReader& stack,
                                     const PlaneDetectionOptions& options,
                                     const ProgressCallback& progress) {
  stack.checkInput(cloud, "the input cloud");
  const auto& positions = cloud.positions();
  const KnnGraph knn = buildKnnGraph(positions, 10);
  PlaneDetectionTimings timings;
  std::vector<RegionLevel> levels;
  const std::size_t m = stack.scaleCount();
  for (std::size_t j = 0; j < m; ++j) {
    if (progress && !progress(double(j) / double(m), "planar segmentations")) throw Cancelled();
    levels.push_back(segmentScale(
        positions, knn, scaleFeaturesFromLayer(stack.readScale(j), stack.info().scales[j]), options,
        timings));
  }
  return buildPlaneDetection(positions, std::move(levels), options, timings, progress);
}

}  // namespace scalespace
