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

// Root mean square of the same distances (the noise's sigma along the normal).
double rmsPlaneDistance(const PointCloud& cloud, const std::vector<SceneFace>& faces) {
  const AttributeColumn* gt = cloud.findAttribute("gt_face");
  double sumSq = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const SceneFace& f = faces[std::size_t(gt->values[i])];
    sumSq += std::pow((cloud.absolutePosition(i) - f.triangles[0]).dot(f.normal), 2);
  }
  return std::sqrt(sumSq / double(cloud.size()));
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
  const double sigma = 25e-5 * std::sqrt(3.0);  // unit box diagonal
  EXPECT_NEAR(rmsPlaneDistance(noisy, sceneFaces(SceneKind::Box, opt)), sigma, 0.05 * sigma);
  EXPECT_THROW(sceneKindFromName("sphere"), OptionError);
  EXPECT_EQ(sceneKindFromName("stairs"), SceneKind::Stairs);
}

namespace {
// Per face, the number of points carrying its label.
std::vector<int> faceCounts(const PointCloud& cloud, std::size_t faceCount) {
  std::vector<int> count(faceCount, 0);
  for (double v : cloud.findAttribute("gt_face")->values) {
    EXPECT_GE(v, 0);
    EXPECT_LT(v, double(faceCount));
    if (v >= 0 && v < double(faceCount)) ++count[std::size_t(v)];
  }
  return count;
}

double totalArea(const std::vector<SceneFace>& faces) {
  double area = 0;
  for (const SceneFace& f : faces) area += f.area();
  return area;
}
}  // namespace

TEST(SceneGenerator, HouseAndYardLabelsNormalsAndAreaSampling) {
  for (SceneKind kind : {SceneKind::House, SceneKind::Yard}) {
    SceneOptions opt;
    opt.pointCount = 200000;
    const PointCloud cloud = generateScene(kind, opt);
    const auto faces = sceneFaces(kind, opt);
    ASSERT_EQ(cloud.size(), opt.pointCount);
    EXPECT_LT(maxPlaneDistance(cloud, faces), 1e-12) << sceneKindName(kind);
    const AttributeColumn* gt = cloud.findAttribute("gt_face");
    const AttributeColumn* group = cloud.findAttribute("gt_group");
    ASSERT_NE(group, nullptr);
    EXPECT_EQ(group->type, ScalarType::Int32);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const SceneFace& f = faces[std::size_t(gt->values[i])];
      ASSERT_EQ(group->values[i], f.group) << sceneKindName(kind) << " point " << i;
      ASSERT_NEAR(cloud.normals()[i].norm(), 1, 1e-12);
      ASSERT_NEAR((cloud.normals()[i] - f.normal).norm(), 0, 1e-15);
    }
    // Every face gets points in proportion to its area (binomial, 6 standard deviations).
    const std::vector<int> count = faceCounts(cloud, faces.size());
    const double total = totalArea(faces);
    for (const SceneFace& f : faces) {
      const double p = f.area() / total, expected = double(opt.pointCount) * p;
      EXPECT_GT(count[std::size_t(f.label)], 0) << sceneKindName(kind) << " face " << f.label;
      EXPECT_NEAR(count[std::size_t(f.label)], expected, 6 * std::sqrt(expected * (1 - p)) + 1)
          << sceneKindName(kind) << " face " << f.label;
    }
    // Groups: ids 0..names-1, each the union of several faces (the labels are per face above).
    const auto names = sceneGroupNames(kind);
    std::vector<int> facesInGroup(names.size(), 0);
    for (const SceneFace& f : faces) {
      ASSERT_LT(f.group, int(names.size()));
      ASSERT_GE(f.group, -1);
      if (f.group >= 0) ++facesInGroup[std::size_t(f.group)];
      // Triangles wound with the declared normal.
      for (std::size_t t = 0; t < f.triangles.size(); t += 3)
        ASSERT_GT((f.triangles[t + 1] - f.triangles[t])
                      .cross(f.triangles[t + 2] - f.triangles[t])
                      .normalized()
                      .dot(f.normal),
                  0.999);
    }
    for (int n : facesInGroup) EXPECT_GE(n, 2);
  }
}

TEST(SceneGenerator, HouseContents) {
  const auto faces = sceneFaces(SceneKind::House);
  // Ground 14 x 10 minus the house 8 x 6 and the staircase 1.2 x 3; walls with gables minus ten
  // 1.2 x 1.2 windows; panes and 6 cm reveals; roof sides 8 x sqrt(13) minus 24 tiles 0.8 x 0.5,
  // tile tops and 2.5 cm sides; treads, risers, stepped sides and back of 10 steps 0.3 x 0.18.
  const double expected = (140 - 48 - 3.6) + (48 + 36 + 12 - 14.4) + 14.4 + 10 * 4 * 1.2 * 0.06 +
                          16 * std::sqrt(13.0) + 24 * 2 * 1.3 * 0.025 + 3.6 + 2.16 +
                          2 * 0.3 * 0.18 * 55 + 2.16;
  EXPECT_NEAR(totalArea(faces), expected, 1e-9);
  EXPECT_EQ(faces.size(), 1u + 23u + 4u + 10u * 5u + 1u + 24u * 5u + 1u);
  // The tiled roof side: the roof plane, 24 tops 2.5 cm proud of it and their sides.
  const Vec3 roofNormal = Vec3(0, -2, 3).normalized();
  const SceneFace* roof = nullptr;
  int tops = 0, groupFaces = 0;
  for (const SceneFace& f : faces) {
    if (f.group != 0) continue;
    ++groupFaces;
    if ((f.normal - roofNormal).norm() > 1e-12) continue;
    if (!roof) {
      roof = &f;
      continue;
    }
    ++tops;
    EXPECT_NEAR((f.triangles[0] - roof->triangles[0]).dot(roofNormal), 0.025, 1e-12);
    EXPECT_NEAR(f.area(), 0.4, 1e-12);
  }
  ASSERT_NE(roof, nullptr);
  EXPECT_EQ(tops, 24);
  EXPECT_EQ(groupFaces, 1 + 24 * 5);
  EXPECT_NEAR(roof->area(), 8 * std::sqrt(13.0) - 24 * 0.4, 1e-9);
  // The staircase's ramp: 10 treads and 10 risers.
  int treads = 0, risers = 0;
  for (const SceneFace& f : faces)
    if (f.group == 1) (f.normal.z() > 0.5 ? treads : risers) += 1;
  EXPECT_EQ(treads, 10);
  EXPECT_EQ(risers, 10);
  // Nothing of the ground is sampled under the house or the staircase.
  SceneOptions opt;
  opt.pointCount = 50000;
  const PointCloud cloud = generateScene(SceneKind::House, opt);
  const AttributeColumn* gt = cloud.findAttribute("gt_face");
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (gt->values[i] != 0) continue;
    const Vec3 p = cloud.absolutePosition(i);
    EXPECT_FALSE(p.x() > -5.5 && p.x() < 2.5 && p.y() > -3 && p.y() < 3) << i;
    EXPECT_FALSE(p.x() > 4 && p.x() < 5.2 && p.y() > -1.5 && p.y() < 1.5) << i;
  }
  EXPECT_EQ(sceneGroupNames(SceneKind::House).size(), 2u);
}

TEST(SceneGenerator, YardContents) {
  const auto faces = sceneFaces(SceneKind::Yard);
  // Ground 10 x 8 minus the footprints; ramp slope, back and sides; 4 steps 0.3 x 0.2, 1 m wide;
  // the low wall 6 x 0.25 x 0.8 and three boxes, each top and four sides.
  const double expected = (80 - 4.5 - 1.2 - 1.5 - 1 - 0.36 - 1.2) + 1.5 * std::sqrt(9.36) + 0.9 +
                          1.8 + (1.2 + 0.8 + 2 * 0.3 * 0.2 * 10 + 0.8) + (1.5 + 10) + 3 + 1.8 +
                          2.96;
  EXPECT_NEAR(totalArea(faces), expected, 1e-9);
  EXPECT_EQ(faces.size(), 1u + 4u + 11u + 4u * 5u);
  int ramp = 0;
  for (const SceneFace& f : faces) ramp += f.group == 0;
  EXPECT_EQ(ramp, 8);
  EXPECT_EQ(sceneKindFromName("yard"), SceneKind::Yard);
  EXPECT_STREQ(sceneKindName(SceneKind::House), "house");
}

TEST(SceneGenerator, HouseDeterministicAndNoisy) {
  SceneOptions opt;
  opt.pointCount = 30000;
  opt.seed = 3;
  const PointCloud a = generateScene(SceneKind::House, opt);
  const PointCloud b = generateScene(SceneKind::House, opt);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.absolutePosition(i), b.absolutePosition(i));
    ASSERT_EQ(a.findAttribute("gt_group")->values[i], b.findAttribute("gt_group")->values[i]);
  }
  opt.noise = 2.5e-4;
  const PointCloud noisy = generateScene(SceneKind::House, opt);
  const double sigma = 2.5e-4 * std::sqrt(14.0 * 14 + 10 * 10 + 5 * 5);  // bounding box diagonal
  EXPECT_NEAR(rmsPlaneDistance(noisy, sceneFaces(SceneKind::House, opt)), sigma, 0.05 * sigma);
  // The Table 2.1 scenes keep their columns: no group column.
  EXPECT_EQ(generateScene(SceneKind::Stairs, opt).findAttribute("gt_group"), nullptr);
}
