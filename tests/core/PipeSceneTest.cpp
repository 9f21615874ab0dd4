// The scenes of the cylinders (core/PipeScene): every straight pipe's points lie on it with
// radial normals, the poles' missing band and unseen side are missing, the floor has nothing
// under what stands on it, and a one-sided scan faces its scanner.
#include <gtest/gtest.h>

#include <cmath>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/PipeScene.hpp"

using namespace scalespace;

namespace {

PointCloud scene(PipeLayout layout, std::size_t n, bool oneSided = false) {
  PipeSceneOptions options;
  options.layout = layout;
  options.pointCount = n;
  options.oneSided = oneSided;
  return generatePipeScene(options);
}

// The worst distance of a straight pipe's points from its surface, and the worst angle (degrees)
// between their normals and the radial direction.
void straightPipeErrors(const PointCloud& cloud, const PipeTruth& t, double& distance,
                        double& angle) {
  const auto& pipe = cloud.findAttribute("gt_pipe")->values;
  distance = angle = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (int(pipe[i]) != t.id) continue;
    const Vec3 v = cloud.absolutePosition(i) - t.axisPoint;
    const double along = v.dot(t.axisDirection);
    const Vec3 radial = v - along * t.axisDirection;
    distance = std::max(distance, std::abs(radial.norm() - t.radius));
    EXPECT_GE(along, -1e-9);
    EXPECT_LE(along, t.length + 1e-9);
    const double c = std::clamp(radial.normalized().dot(cloud.normals()[i]), -1.0, 1.0);
    angle = std::max(angle, std::acos(c) * 180 / kPi);
  }
}

double azimuth(const Vec3& p, const Vec3& foot) {
  const double a = std::atan2(p.y() - foot.y(), p.x() - foot.x());
  return a < 0 ? a + 2 * kPi : a;
}

}  // namespace

TEST(PipeScene, TheRacksStraightPipesLieOnTheirTubesWithRadialNormals) {
  const PointCloud cloud = scene(PipeLayout::Rack, 60000);
  ASSERT_EQ(cloud.size(), 60000u);
  const std::vector<PipeTruth> truth = pipeSceneTruth(PipeLayout::Rack);
  ASSERT_EQ(truth.size(), 6u);
  int straight = 0;
  for (const PipeTruth& t : truth) {
    if (t.kind != PipeKind::Straight) continue;
    ++straight;
    double distance = 0, angle = 0;
    straightPipeErrors(cloud, t, distance, angle);
    EXPECT_LT(distance, 1e-9) << t.name;
    EXPECT_LT(angle, 1e-3) << t.name;
  }
  EXPECT_EQ(straight, 3);
}

TEST(PipeScene, ThePolesStandOnTheFloorWithTheirBandAndUnseenSideMissing) {
  const PointCloud cloud = scene(PipeLayout::Poles, 80000);
  const std::vector<PipeTruth> truth = pipeSceneTruth(PipeLayout::Poles);
  ASSERT_EQ(truth.size(), 4u);
  const auto& pipe = cloud.findAttribute("gt_pipe")->values;
  std::vector<std::size_t> count(4, 0), inBand(4, 0);
  std::vector<double> widestFromSouth(4, 0);  // the most azimuth (radians) from -y
  std::size_t floor = 0, box = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.absolutePosition(i);
    const int id = int(pipe[i]);
    if (id < 0) {
      // The floor (z = 0, normal up) outside every pole, or the box 1 x 0.6 x 0.8 standing on it.
      if (std::abs(p.z()) < 1e-12) {
        ++floor;
        EXPECT_GT(cloud.normals()[i].z(), 0.999);
        for (const PipeTruth& t : truth)
          EXPECT_GE(std::hypot(p.x() - t.axisPoint.x(), p.y() - t.axisPoint.y()), t.radius);
      } else {
        ++box;
        EXPECT_LE(p.z(), 0.8 + 1e-9);
      }
      continue;
    }
    ++count[std::size_t(id)];
    const double a = azimuth(p, truth[std::size_t(id)].axisPoint);
    const double fromSouth = std::abs(std::remainder(a - 1.5 * kPi, 2 * kPi));
    widestFromSouth[std::size_t(id)] = std::max(widestFromSouth[std::size_t(id)], fromSouth);
    inBand[std::size_t(id)] += p.z() > 0.8 && p.z() < 1.0 && a < 2.0;
  }
  EXPECT_GT(floor, 10 * box);
  EXPECT_GT(box, 0u);
  for (const PipeTruth& t : truth) {
    const std::size_t k = std::size_t(t.id);
    EXPECT_GT(count[k], 100u) << t.name;
    EXPECT_EQ(inBand[k], 0u) << t.name;
    EXPECT_EQ(t.axisDirection, Vec3::UnitZ());
    double distance = 0, angle = 0;
    straightPipeErrors(cloud, t, distance, angle);
    EXPECT_LT(distance, 1e-9) << t.name;
    EXPECT_LT(angle, 1e-3) << t.name;
    // The half pole is seen over 4 rad of azimuth centred on the south, the others all round.
    const bool half = t.name.rfind("half", 0) == 0;
    if (half)
      EXPECT_LE(widestFromSouth[k], 2.0 + 1e-9);
    else
      EXPECT_GT(widestFromSouth[k], kPi - 0.05);
  }
  EXPECT_EQ(truth[2].name, "half pole r 0.5");
  // Sampled by area: the pole of radius 0.2, 3 m tall, less a 0.2 x 0.4 m band, against the
  // 0.05 one, 2 m tall, less its 0.2 x 0.1 m band.
  const double expected =
      (2 * kPi * 0.2 * 3 - 0.2 * 0.2 * 2) / (2 * kPi * 0.05 * 2 - 0.2 * 0.05 * 2);
  EXPECT_NEAR(double(count[1]) / double(count[0]), expected, 0.1 * expected);
}

TEST(PipeScene, AOneSidedScanFacesItsScannerAndTheSeedRepeatsTheScene) {
  for (const PipeLayout layout : {PipeLayout::Rack, PipeLayout::Poles}) {
    const PointCloud cloud = scene(layout, 20000, true);
    ASSERT_TRUE(cloud.viewpoint().has_value());
    const Vec3 scanner = *cloud.viewpoint();
    for (std::size_t i = 0; i < cloud.size(); ++i)
      ASSERT_GT(cloud.normals()[i].dot(scanner - cloud.absolutePosition(i)), 0) << i;
    const PointCloud again = scene(layout, 20000, true);
    EXPECT_EQ(again.absolutePosition(123), cloud.absolutePosition(123));
  }
  PipeSceneOptions bad;
  bad.layout = PipeLayout::Poles;
  bad.noise = -1;
  EXPECT_THROW(generatePipeScene(bad), OptionError);
}
