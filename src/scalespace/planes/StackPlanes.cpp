#include "scalespace/planes/StackPlanes.hpp"

#include <tbb/task_group.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "scalespace/core/Error.hpp"

namespace scalespace {

ScaleFeatures scaleFeaturesFromLayer(const ScaleLayer& layer, double t) {
  const std::size_t n = layer.size();
  if (layer.normal.size() != 3 * n || layer.kMax.size() != n || layer.kMin.size() != n ||
      (!layer.projection.empty() && layer.projection.size() != 3 * n))
    throw Error("scale layer arrays have inconsistent sizes");
  ScaleFeatures f;
  f.t = t;
  f.normals.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    f.normals[i] = Vec3(layer.normal[3 * i], layer.normal[3 * i + 1], layer.normal[3 * i + 2]);
  f.kMax = layer.kMax;
  f.kMin = layer.kMin;
  f.valid = layer.valid;
  if (!layer.projection.empty()) {
    f.projections.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      f.projections[i] =
          Vec3(layer.projection[3 * i], layer.projection[3 * i + 1], layer.projection[3 * i + 2]);
  }
  return f;
}

StackPlaneDetection detectPlanesInCloud(const PointCloud& cloud,
                                        const ScaleSpaceOptions& stackOptions,
                                        const PlaneDetectionOptions& options,
                                        const ProgressCallback& progress) {
  validatePlaneDetectionOptions(options);
  const auto begin = std::chrono::steady_clock::now();
  StackPlaneDetection out;
  const auto& positions = cloud.positions();
  auto start = std::chrono::steady_clock::now();
  const KnnGraph knn = buildKnnGraph(positions, 10);  // k = 10 (Sec. 2.3.1)
  const double noise = pointNoiseRms(positions, knn);
  out.knnSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Scale j is segmented and filtered in a task while the stack projects scale j+1: region
  // growing is sequential and the filter's time goes to a few large regions, so done in the sink
  // they kept the other cores idle. Each task owns its copy of the features and its slot
  // (deque: stable references), so the levels do not depend on the scheduling.
  struct Slot {
    RegionLevel level;
    PlaneDetectionTimings timings;
  };
  std::deque<Slot> slots;
  tbb::task_group segmentations;
  std::atomic<int> pending{0};
  // The sink only copies what the features are made of (four float arrays, into a buffer
  // reused from scale to scale): the conversion to ScaleFeatures runs in the task. Made in the
  // sink, it held up the next scale's projection with the other cores idle (mostly first-touch
  // page faults of a fresh array at every scale).
  std::mutex poolMutex;
  std::vector<std::unique_ptr<ScaleLayer>> pool;
  const ScaleSink sink = [&](std::size_t, const ScaleLayer& layer, const ScaleStats& stats) {
    // At most two scales wait: each holds a copy of its layer's features (~21 MB per 1M points).
    if (pending.load() >= 2) segmentations.wait();
    Slot& slot = slots.emplace_back();
    std::shared_ptr<ScaleLayer> copy;
    {
      std::lock_guard<std::mutex> lock(poolMutex);
      if (pool.empty()) pool.push_back(std::make_unique<ScaleLayer>());
      copy.reset(pool.back().release(), [&](ScaleLayer* buffer) {
        std::lock_guard<std::mutex> back(poolMutex);
        pool.emplace_back(buffer);
      });
      pool.pop_back();
    }
    copy->normal = layer.normal;
    copy->kMax = layer.kMax;
    copy->kMin = layer.kMin;
    copy->valid = layer.valid;
    copy->projection = layer.projection;
    ++pending;
    // The buffer goes back to the pool when the task's functor is destroyed, which TBB does
    // before the task counts as finished: the pool outlives every task (all are waited for).
    segmentations.run([&, &slot = slot, copy, t = stats.t] {
      const ScaleFeatures features = scaleFeaturesFromLayer(*copy, t);
      slot.level = segmentScale(positions, knn, features, noise, options, slot.timings);
      --pending;
    });
  };
  start = std::chrono::steady_clock::now();
  ScaleSpaceOptions stack = stackOptions;
  // The graph's queries are those of the automatic t_min when its k is the series' K (both 10:
  // Sec. 1.5.1 and 2.3.1).
  if (!knn.kthDistance.empty() && stack.series.K > 0 &&
      std::size_t(stack.series.K) * knn.size() == knn.neighbors.size())
    stack.series.knownMedianKnnRadius = lowerMedian(knn.kthDistance);
  // What scaleFeaturesFromLayer reads: the projections only when a criterion needs them.
  const bool projections = options.growing.maxStep > 0;
  stack.layerContents = projections ? LayerContents::NormalCurvaturesAndProjection
                                    : LayerContents::NormalAndCurvatures;
  try {
    out.stack = runScaleSpace(cloud, stack, sink, progress);
  } catch (...) {
    // The tasks hold references to this frame: they must end before it unwinds.
    segmentations.cancel();
    segmentations.wait();
    throw;
  }
  out.stackSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  start = std::chrono::steady_clock::now();
  segmentations.wait();
  out.segmentationWaitSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PlaneDetectionTimings timings;
  std::vector<RegionLevel> levels;
  levels.reserve(slots.size());
  for (Slot& slot : slots) {
    timings.segmentation += slot.timings.segmentation;
    timings.filtering += slot.timings.filtering;
    levels.push_back(std::move(slot.level));
  }
  out.detection =
      buildPlaneDetection(positions, std::move(levels), noise, options, timings, progress);
  out.totalSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return out;
}

PlaneDetection detectPlanesFromStack(const PointCloud& cloud, const ScaleStackReader& stack,
                                     const PlaneDetectionOptions& options,
                                     const ProgressCallback& progress) {
  validatePlaneDetectionOptions(options);
  stack.checkInput(cloud, "the input cloud");
  const auto& positions = cloud.positions();
  const KnnGraph knn = buildKnnGraph(positions, 10);
  const double noise = pointNoiseRms(positions, knn);
  PlaneDetectionTimings timings;
  std::vector<RegionLevel> levels;
  const std::size_t m = stack.scaleCount();
  for (std::size_t j = 0; j < m; ++j) {
    if (progress && !progress(double(j) / double(m), "planar segmentations")) throw Cancelled();
    levels.push_back(segmentScale(
        positions, knn, scaleFeaturesFromLayer(stack.readScale(j), stack.info().scales[j]), noise,
        options, timings));
  }
  return buildPlaneDetection(positions, std::move(levels), noise, options, timings, progress);
}

}  // namespace scalespace
