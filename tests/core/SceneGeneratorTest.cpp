#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SceneGenerator.hpp"

using namespace scalespace;

namespace {
// Signed distance of every sample to the plane of its labelled face (through its first vertex).
double maxPlaneDistance(const PointCloud& cloud, const std::vector<SceneFace>& faces) {
  const AttributeColumn* gt = cloud.findAttribute("gt_face");
  double worst = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const SceneFace& f = faces[std::size_t(gt->values[i])];
    worst = std::max(worst, std::abs((cloud.absolutePosition(i) - f.triangles[0]).dot(f.normal)));
  }
  return worst;
}
}  // namespace

TEST(SceneGenerator, EveryScenePointLiesOnItsLabelledFaceWithItsNormal) {
  for (SceneKind kind : {SceneKind::Tri, SceneKind::Stairs, SceneKind::Cubes, SceneKind::Box}) {
    SceneOptions opt;
    opt.pointCount = 3000;
    const PointCloud cloud = generateScene(kind, opt);
    const auto faces = sceneFaces(kind, opt);
    ASSERT_EQ(cloud.size(), 3000u);
    ASSERT_TRUE(cloud.hasNormals());
    EXPECT_LT(maxPlaneDistance(cloud, faces), 1e-12) << sceneKindName(kind);
    const AttributeColumn* gt = cloud.findAttribute("gt_face");
    ASSERT_NE(gt, nullptr);
    EXPECT_EQ(gt->type, ScalarType::Int32);
    for (std::size_t i = 0; i < cloud.size(); ++i)
      EXPECT_NEAR((cloud.normals()[i] - faces[std::size_t(gt->values[i])].normal).norm(), 0, 1e-15);
  }
}

TEST(SceneGenerator, SamplingIsUniformByArea) {
  // Box 1 x 2 x 4: face areas 8, 8, 4, 4, 2, 2 (x, y, z normals) of 28 in total.
  SceneOptions opt;
  opt.pointCount = 56000;
  opt.boxSize = Vec3(1, 2, 4);
  const PointCloud cloud = generateScene(SceneKind::Box, opt);
  const auto faces = sceneFaces(SceneKind::Box, opt);
  std::map<int, int> count;
  for (double v : cloud.findAttribute("gt_face")->values) ++count[int(v)];
  ASSERT_EQ(count.size(), 6u);
  for (const SceneFace& f : faces) {
    const double expected = 56000 * f.area() / 28.0;
    EXPECT_NEAR(count[f.label], expected, 5 * std::sqrt(expected)) << f.label;
  }
}

TEST(SceneGenerator, FaceCountsAndOutwardNormals) {
  EXPECT_EQ(sceneFaces(SceneKind::Box).size(), 6u);
  EXPECT_EQ(sceneFaces(SceneKind::Tri).size(), 5u);
  SceneOptions opt;
  opt.stairSteps = 5;
  EXPECT_EQ(sceneFaces(SceneKind::Stairs, opt).size(), 10u);
  EXPECT_EQ(sceneFaces(SceneKind::Cubes).size(), 1u + 4u * 5u);
  // Box: the outward normal points away from the centre (origin).
  for (const SceneFace& f : sceneFaces(SceneKind::Box)) EXPECT_GT(f.triangles[0].dot(f.normal), 0);
  // Triangle winding agrees with the declared normal.
  for (SceneKind kind : {SceneKind::Tri, SceneKind::Stairs, SceneKind::Cubes, SceneKind::Box})
    for (const SceneFace& f : sceneFaces(kind))
      for (std::size_t t = 0; t < f.triangles.size(); t += 3) {
        const Vec3 n =
            (f.triangles[t + 1] - f.triangles[t]).cross(f.triangles[t + 2] - f.triangles[t]);
        EXPECT_GT(n.normalized().dot(f.normal), 0.999)
            << sceneKindName(kind) << " face " << f.label;
      }
  // Cubes: the four levels' areas add up: base bottom 4, sides 4*4*(1 + 1/4 + 1/16 + 1/64),
  // tops: rings + last top = base top area 4.
  double area = 0;
  for (const SceneFace& f : sceneFaces(SceneKind::Cubes)) area += f.area();
  EXPECT_NEAR(area, 4 + 16 * (1 + 0.25 + 0.0625 + 0.015625) + 4, 1e-12);
}

TEST(SceneGenerator, DeterministicAndNoiseScalesWithDiagonal) {
  SceneOptions opt;
  opt.pointCount = 20000;
  opt.seed = 7;
  const PointCloud a = generateScene(SceneKind::Box, opt), b = generateScene(SceneKind::Box, opt);
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_EQ(a.absolutePosition(i), b.absolutePosition(i));
  opt.noise = 25e-5;
  const PointCloud noisy = generateScene(SceneKind::Box, opt);
  const auto faces = sceneFaces(SceneKind::Box, opt);
  const AttributeColumn* gt = noisy.findAttribute("gt_face");
  double sumSq = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    const SceneFace& f = faces[std::size_t(gt->values[i])];
    sumSq += std::pow((noisy.absolutePosition(i) - f.triangles[0]).dot(f.normal), 2);
  }
  const double sigma = 25e-5 * std::sqrt(3.0);  // unit box diagonal
  EXPECT_NEAR(std::sqrt(sumSq / noisy.size()), sigma, 0.05 * sigma);
  EXPECT_THROW(sceneKindFromName("sphere"), OptionError);
  EXPECT_EQ(sceneKindFromName("stairs"), SceneKind::Stairs);
}
