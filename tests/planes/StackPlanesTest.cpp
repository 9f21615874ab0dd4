#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/planes/StackPlanes.hpp"
#include "scalespace/scales/ScaleStackCompute.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"

using namespace scalespace;

namespace {
// Per ground-truth face, the highest persistence of a component matching it (IoU >= 0.8 with the
// face's points) at some level; faces never matched are absent.
std::map<int, int> facePersistence(const PlaneModel& model, const std::vector<int>& gt) {
  std::map<int, std::size_t> faceSize;
  for (int f : gt) ++faceSize[f];
  std::map<int, int> bestPersistence;  // per face, the persistence of its matching component
  for (int level = 0; level < model.scaleCount(); ++level) {
    std::map<std::pair<int, int>, std::size_t> common;  // (component, face) -> points
    std::map<int, std::size_t> componentSize;
    for (std::size_t i = 0; i < gt.size(); ++i) {
      const int c = model.membership.at(level, i);
      if (c < 0) continue;
      ++common[{c, gt[i]}];
      ++componentSize[c];
    }
    for (const auto& [key, k] : common) {
      const double iou = double(k) / double(componentSize[key.first] + faceSize[key.second] - k);
      if (iou >= 0.8)
        bestPersistence[key.second] = std::max(
            bestPersistence[key.second], model.components[std::size_t(key.first)].persistence);
    }
  }
  return bestPersistence;
}
}  // namespace

// End to end (Fig. 2.4): the robust APSS stack of a clean box, segmented per scale. Every face
// must be found as one component (IoU >= 0.8 with the face's points at some level), and the
// most persistent face components must be the larger faces.
TEST(StackPlanes, BoxFacesAreFoundFromTheStack) {
  SceneOptions scene;
  scene.pointCount = 1500;
  scene.boxSize = Vec3(4, 2, 1);
  const PointCloud cloud = generateScene(SceneKind::Box, scene);
  std::vector<int> gt;
  for (double v : cloud.findAttribute("gt_face")->values) gt.push_back(int(v));
  ScaleSpaceOptions stack;
  stack.series.count = 8;
  stack.fit.robust = true;  // as `scalespace planes` (Sec. 2.3)
  const StackPlaneDetection result = detectPlanesInCloud(cloud, stack);
  const PlaneModel model = makePlaneModel(result.detection);
  ASSERT_EQ(model.scaleCount(), 8);
  // t_min came from the k-NN graph's distances: the same series as the stack computes alone.
  const ScaleSeriesResult alone = makeScaleSeries(cloud.positions(), stack.series);
  EXPECT_TRUE(result.stack.series.tMinAuto);
  EXPECT_EQ(result.stack.series.tMin, alone.tMin);
  EXPECT_EQ(result.stack.series.scales, alone.scales);

  const std::map<int, int> bestPersistence = facePersistence(model, gt);
  EXPECT_EQ(bestPersistence.size(), 6u);
  // Faces 4, 5 (4 x 2) outlive faces 0, 1 (2 x 1).
  EXPECT_GE(bestPersistence.at(4), bestPersistence.at(0));
  EXPECT_GE(bestPersistence.at(5), bestPersistence.at(1));
  EXPECT_GT(bestPersistence.at(4) + bestPersistence.at(5),
            bestPersistence.at(0) + bestPersistence.at(1));

  // The same pipeline on the stack written to disk finds the same faces; another cloud is
  // refused (checksum).
  const auto path = std::filesystem::temp_directory_path() / "scalespace_planes_test.stack";
  std::filesystem::remove_all(path);
  computeScaleStackToDisk(cloud, stack, path.string());
  {
    const ScaleStackReader reader(path.string());
    const PlaneModel fromDisk = makePlaneModel(detectPlanesFromStack(cloud, reader));
    EXPECT_EQ(fromDisk.scales, model.scales);
    EXPECT_EQ(facePersistence(fromDisk, gt).size(), 6u);
    SceneOptions other = scene;
    other.seed = 99;
    EXPECT_THROW(detectPlanesFromStack(generateScene(SceneKind::Box, other), reader), FileError);
  }
  std::filesystem::remove_all(path);
}

namespace {
PointCloud smallStairs() {
  SceneOptions scene;
  scene.pointCount = 4000;
  scene.noise = 1e-4;
  return generateScene(SceneKind::Stairs, scene);
}

ScaleSpaceOptions robustStack(int scales) {
  ScaleSpaceOptions stack;
  stack.series.count = scales;
  stack.fit.robust = true;
  return stack;
}

void expectSameDetection(const PlaneDetection& a, const PlaneDetection& b) {
  ASSERT_EQ(a.scaleCount(), b.scaleCount());
  ASSERT_EQ(a.components.size(), b.components.size());
  for (int level = 0; level < a.scaleCount(); ++level)
    EXPECT_EQ(a.graph.componentLabels(level), b.graph.componentLabels(level)) << level;
  for (std::size_t c = 0; c < a.components.size(); ++c) {
    EXPECT_EQ(a.components[c].birthLevel, b.components[c].birthLevel);
    EXPECT_EQ(a.components[c].deathLevel, b.components[c].deathLevel);
    EXPECT_EQ(a.components[c].area, b.components[c].area);
  }
}
}  // namespace

// The pipeline segments scale j while the stack projects scale j+1 (tasks): its result must be
// the sequential one (the whole stack first, then detectPlanes on every scale in order), for one
// thread and for two.
TEST(StackPlanes, OverlappedSegmentationEqualsTheSequentialPipeline) {
  const PointCloud cloud = smallStairs();
  const ScaleSpaceOptions stack = robustStack(12);
  const ScaleStack layers = computeScaleStackInMemory(cloud, stack);
  std::vector<ScaleFeatures> features;
  for (std::size_t j = 0; j < layers.layers.size(); ++j)
    features.push_back(scaleFeaturesFromLayer(layers.layers[j], layers.summary.series.scales[j]));
  const PlaneDetection sequential =
      detectPlanes(cloud.positions(), buildKnnGraph(cloud.positions(), 10), features);
  ASSERT_GT(sequential.components.size(), 2u);
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    ThreadLimit limit(threads);
    const StackPlaneDetection overlapped = detectPlanesInCloud(cloud, stack);
    expectSameDetection(sequential, overlapped.detection);
    EXPECT_GE(overlapped.segmentationWaitSeconds, 0);
    EXPECT_GT(overlapped.detection.timings.segmentation, 0);
  }
}

// Cancelling the stack while segmentations are pending: the tasks, which refer to the caller's
// frame, end before it unwinds (the sanitizer build would report a use after return), and the
// exception is the cancellation.
TEST(StackPlanes, CancellingWhileSegmentingThrowsCancelled) {
  const PointCloud cloud = smallStairs();
  for (double stopAt : {0.05, 0.5, 0.95}) {
    const ProgressCallback cancel = [stopAt](double f, std::string_view) { return f < stopAt; };
    EXPECT_THROW(detectPlanesInCloud(cloud, robustStack(10), {}, cancel), Cancelled) << stopAt;
  }
}

// The planarity split end to end, on the Tri scene (a ground carrying a prism) with noise: a
// component is flagged exactly when its regions are not planar, so every component flagged
// planar has a plane RMS within max(5% of its representative scale, 2 x the noise), and no chain
// mixes planar and non-planar regions.
TEST(StackPlanes, ComponentsFlaggedPlanarAreDescribedByTheirPlane) {
  SceneOptions scene;
  scene.pointCount = 4000;
  scene.noise = 5e-4;
  const PointCloud cloud = generateScene(SceneKind::Tri, scene);
  ScaleSpaceOptions stack;
  stack.series.count = 10;
  stack.fit.robust = true;
  const PlaneDetectionOptions options;
  const PlaneDetection detection = detectPlanesInCloud(cloud, stack, options).detection;
  const RegionGraph& graph = detection.graph;
  const auto planar =
      regionPlanarity(cloud.positions(), graph.levels, detection.noiseRms, options.planarity);
  EXPECT_GT(detection.noiseRms, 0.0);
  std::size_t flagged = 0;
  for (const PlaneComponent& c : detection.components) {
    const GraphComponent& g = graph.components[std::size_t(c.id)];
    for (int level = g.birthLevel; level <= g.deathLevel; ++level)
      EXPECT_EQ(bool(planar[std::size_t(level)]
                           [std::size_t(g.regionAt[std::size_t(level - g.birthLevel)])]),
                c.planar);
    if (c.planar) {
      EXPECT_LE(c.plane.rms,
                std::max(0.05 * c.representativeScale, 2 * detection.noiseRms) + 1e-12);
    }
    flagged += !c.planar;
  }
  std::size_t nonPlanar = 0;
  for (const auto& level : planar)
    nonPlanar += std::size_t(std::count(level.begin(), level.end(), 0));
  EXPECT_EQ(nonPlanar, detection.nonPlanarRegions);
  EXPECT_LE(flagged, nonPlanar);
}
