#include <gtest/gtest.h>

#include <cmath>

#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/core/Error.hpp"

using namespace scalespace;

namespace {
const SurfaceShape kShapes[] = {SurfaceShape::Sphere, SurfaceShape::Cylinder, SurfaceShape::Saddle,
                                SurfaceShape::Torus, SurfaceShape::Ellipsoid};
}

TEST(AnalyticSurface, OriginIsOnEveryShapeWithNormalUpAndTable11Curvatures) {
  const double expected[][2] = {{1, 1}, {1, 0}, {2, -1}, {2, 0}, {0.75, 1.0 / 3}};
  for (int i = 0; i < 5; ++i) {
    const SurfacePoint p = evaluateSurface(kShapes[i], Vec3::Zero());
    EXPECT_NEAR(surfaceImplicit(kShapes[i], Vec3::Zero()), 0, 1e-14);
    EXPECT_NEAR(p.normal.z(), 1, 1e-14) << surfaceShapeName(kShapes[i]);
    EXPECT_NEAR(p.kMax, expected[i][0], 1e-12) << surfaceShapeName(kShapes[i]);
    EXPECT_NEAR(p.kMin, expected[i][1], 1e-12) << surfaceShapeName(kShapes[i]);
  }
  // Cylinder: maximal curvature around the circle (x), none along the axis (y).
  const SurfacePoint c = evaluateSurface(SurfaceShape::Cylinder, Vec3::Zero());
  EXPECT_NEAR(std::abs(c.dirMax.x()), 1, 1e-12);
  EXPECT_NEAR(std::abs(c.dirMin.y()), 1, 1e-12);
}

TEST(AnalyticSurface, SamplesLieOnTheSurfaceInsideTheBallWithUnitTangentFrames) {
  for (SurfaceShape s : kShapes) {
    const auto pts = sampleInBall(s, Vec3::Zero(), 1.0, 2000, 7);
    ASSERT_EQ(pts.size(), 2000u);
    for (const SurfacePoint& p : pts) {
      EXPECT_LE(p.position.norm(), 1.0 + 1e-12);
      EXPECT_NEAR(surfaceImplicit(s, p.position), 0, 1e-9) << surfaceShapeName(s);
      EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
      EXPECT_NEAR(p.dirMax.norm(), 1, 1e-12);
      EXPECT_NEAR(p.dirMax.dot(p.dirMin), 0, 1e-12);
      EXPECT_NEAR(p.dirMax.dot(p.normal), 0, 1e-12);
      EXPECT_GE(p.kMax, p.kMin);
    }
  }
}

TEST(AnalyticSurface, TorusAndCylinderCurvaturesAwayFromTheOrigin) {
  // Torus outer equator (theta = 0): kappa = 1/r (tube) and 1/(R + r) (ring).
  const Vec3 outer(-2 + 2.5, 0, -0.5);
  const SurfacePoint t = evaluateSurface(SurfaceShape::Torus, outer);
  EXPECT_NEAR(t.kMax, 2, 1e-12);
  EXPECT_NEAR(t.kMin, 1 / 2.5, 1e-12);
  // Inner equator: the ring curvature is negative, -1/(R - r).
  const SurfacePoint ti = evaluateSurface(SurfaceShape::Torus, Vec3(-2 + 1.5, 0, -0.5));
  EXPECT_NEAR(ti.kMin, -1 / 1.5, 1e-12);
  const SurfacePoint c = evaluateSurface(SurfaceShape::Cylinder, Vec3(1, 3, -1));
  EXPECT_NEAR(c.kMax, 1, 1e-12);
  EXPECT_NEAR(c.kMin, 0, 1e-12);
}

TEST(AnalyticSurface, SamplingIsUniformByAreaAndSeeded) {
  // On the whole unit sphere, the upper hemisphere holds half of the points (Archimedes).
  const auto pts = sampleInBall(SurfaceShape::Sphere, Vec3::Zero(), 10, 20000, 3);
  int upper = 0;
  for (const auto& p : pts) upper += p.position.z() > -1;
  EXPECT_NEAR(upper / 20000.0, 0.5, 0.015);
  // Saddle: density per unit (x, y) area grows like sqrt(1 + |grad h|^2) away from the origin.
  const auto a = sampleInBall(SurfaceShape::Saddle, Vec3::Zero(), 1, 100, 5);
  const auto b = sampleInBall(SurfaceShape::Saddle, Vec3::Zero(), 1, 100, 5);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(a[i].position, b[i].position);
}

TEST(AnalyticSurface, SampleSurfaceCloudAndNoise) {
  SurfaceSampleOptions o;
  o.shape = SurfaceShape::Cylinder;
  o.count = 1000;
  o.normalNoiseDegrees = 10;
  const PointCloud c = sampleSurface(o);
  ASSERT_EQ(c.size(), 1000u);
  ASSERT_TRUE(c.hasNormals());
  ASSERT_NE(c.findAttribute("k1"), nullptr);
  double meanAngle = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Vec3 p = c.absolutePosition(i);
    EXPECT_NEAR(surfaceImplicit(SurfaceShape::Cylinder, p), 0, 1e-9);
    const Vec3 exact = evaluateSurface(SurfaceShape::Cylinder, p).normal;
    meanAngle += std::acos(std::min(1.0, exact.dot(c.normals()[i])));
    EXPECT_NEAR(c.findAttribute("k1")->values[i], 1, 1e-12);
  }
  // E|N(0, s)| = s sqrt(2/pi) for the rotation angle; the angle between normals is at most that.
  meanAngle = meanAngle / 1000 * 180 / 3.14159265358979;
  EXPECT_GT(meanAngle, 3);
  EXPECT_LT(meanAngle, 10 * std::sqrt(2 / 3.14159265358979) + 0.5);
  o.count = 0;
  EXPECT_THROW(sampleSurface(o), OptionError);
  EXPECT_THROW(parseSurfaceShape("cube"), OptionError);
  EXPECT_EQ(parseSurfaceShape("torus"), SurfaceShape::Torus);
}
