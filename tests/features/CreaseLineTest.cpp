// The crease through a point as the line where the planes of its two sides meet
// (features/CreaseLine): exact on a sharp edge of any turn, along the middle of a rounded edge,
// none on a flat face or beyond the end of a thin part.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/features/CreaseLine.hpp"

using namespace scalespace;

namespace {

constexpr double kSpacing = 0.01;

struct Sample {
  std::vector<Vec3> positions, normals;
  void add(const Vec3& p, const Vec3& n) {
    positions.push_back(p);
    normals.push_back(n.normalized());
  }
};

// Two half-planes meeting along the x axis, turning by `turnDegrees` (a convex edge: the normals
// point away from the solid), `count` random points on each within 0.1 of the axis.
Sample sharpEdge(double turnDegrees, std::uint64_t seed, int count = 4000) {
  const double half = (180 - turnDegrees) / 2 * M_PI / 180;  // half the opening
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> along(-0.1, 0.1), away(0.0, 0.1);
  Sample s;
  for (int i = 0; i < 2 * count; ++i) {
    const double side = i % 2 ? 1.0 : -1.0, d = away(rng);
    const Vec3 direction(0, side * std::sin(half), -std::cos(half));  // down the face
    const Vec3 normal(0, side * std::cos(half), std::sin(half));
    s.add(Vec3(along(rng), 0, 0) + d * direction, normal);
  }
  return s;
}

CreaseLineOptions options() {
  CreaseLineOptions o;
  o.reach = 2 * kSpacing;
  o.maxRms = 0.1 * kSpacing;
  o.maxGap = 0.25 * kSpacing;
  return o;
}

double distanceToXAxis(const Vec3& p) { return std::hypot(p.y(), p.z()); }

}  // namespace

TEST(CreaseLine, ASharpEdgeOfAnyTurnIsFoundExactly) {
  for (double turn : {30.0, 90.0, 150.0}) {
    const Sample s = sharpEdge(turn, 11);
    const auto index = makeSpatialIndex(s.positions);
    // From points beside the edge, and with the salient vertices' direction 10 degrees off.
    const Vec3 along = Vec3(1, std::tan(10 * M_PI / 180), 0).normalized();
    for (std::size_t i = 0; i < 200; ++i) {
      const Vec3& x = s.positions[i];
      if (std::abs(x.x()) > 0.05 || distanceToXAxis(x) > 1.5 * kSpacing) continue;
      const auto line = fitCreaseLine(s.positions, s.normals, *index, x, along, options());
      ASSERT_TRUE(line) << turn << " " << i;
      EXPECT_NEAR(std::abs(line->direction.x()), 1.0, 1e-9);
      EXPECT_LT(distanceToXAxis(line->point), 1e-9);
      EXPECT_NEAR(line->point.x(), x.x(), 1e-9) << "the point of the line nearest x";
      EXPECT_NEAR(line->turnDegrees, turn, 1e-6);
    }
  }
}

TEST(CreaseLine, NoneOnAFlatFaceAndAFilletsMiddleOnAFillet) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-0.1, 0.1), angle(0, M_PI / 2);
  Sample flat, fillet;
  const double radius = 1.5 * kSpacing;  // a quarter cylinder, within the reach all through
  for (int i = 0; i < 8000; ++i) {
    flat.add(Vec3(u(rng), u(rng), 0), Vec3::UnitZ());
    const double a = angle(rng);
    fillet.add(Vec3(u(rng), radius * std::sin(a), radius * std::cos(a)),
               Vec3(0, std::sin(a), std::cos(a)));
  }
  const Vec3 along = Vec3::UnitX();
  const auto flatIndex = makeSpatialIndex(flat.positions);
  EXPECT_FALSE(
      fitCreaseLine(flat.positions, flat.normals, *flatIndex, Vec3::Zero(), along, options()));
  // Its two halves are flat within the tolerance: their planes meet along the middle of the
  // rounded edge, on the surface (the rounded edge's feature line at coarse scales).
  const auto filletIndex = makeSpatialIndex(fillet.positions);
  const Vec3 middle(0, radius * std::sin(M_PI / 4), radius * std::cos(M_PI / 4));
  const auto line =
      fitCreaseLine(fillet.positions, fillet.normals, *filletIndex, middle, along, options());
  ASSERT_TRUE(line);
  EXPECT_NEAR(std::abs(line->direction.x()), 1.0, 1e-4);
  EXPECT_LT((line->point - middle).norm(), 0.1 * kSpacing);
  CreaseLineOptions strict = options();
  strict.maxRms = 0.01 * kSpacing;
  EXPECT_FALSE(fitCreaseLine(fillet.positions, fillet.normals, *filletIndex, middle, along, strict))
      << "curved beyond a strict flatness";
}

// Normals blended across the crease, as a neighbourhood straddling it estimates them: within
// half a spacing of the edge each point's normal turns past the bisector, 10 degrees towards the
// other face (55 degrees off its own). Split by normals, those points join the wrong side, which
// is then no longer flat; split by position (the plane through a point on the edge, holding
// `along` and the mean normal), the sides are the faces, their normals within the 60 degrees
// that split allows, and the line is the edge. With a margin the points nearest that plane are
// left out.
TEST(CreaseLine, SidesByPositionStandBlendedNormals) {
  Sample s = sharpEdge(90, 14);
  const double past = 10 * M_PI / 180;
  for (std::size_t i = 0; i < s.positions.size(); ++i)
    if (distanceToXAxis(s.positions[i]) < 0.5 * kSpacing) {
      const double side = s.normals[i].y() > 0 ? 1.0 : -1.0;
      s.normals[i] = Vec3(0, -side * std::sin(past), std::cos(past));
    }
  const auto index = makeSpatialIndex(s.positions);
  const Vec3 along = Vec3::UnitX(), onEdge = Vec3::Zero();
  const Vec3 x(0, 0, -0.5 * kSpacing);  // inside the convex edge, where the APSS puts vertices
  const auto byNormals = fitCreaseLine(s.positions, s.normals, *index, x, along, options());
  EXPECT_TRUE(!byNormals || distanceToXAxis(byNormals->point) > 0.05 * kSpacing);
  CreaseLineOptions position = options();
  position.splitByPosition = true;
  for (const double margin : {0.0, 0.3 * kSpacing}) {
    position.sideMargin = margin;
    const auto line = fitCreaseLine(s.positions, s.normals, *index, x, along, position, &onEdge);
    ASSERT_TRUE(line) << margin;
    EXPECT_LT(distanceToXAxis(line->point), 1e-9);
    EXPECT_NEAR(line->turnDegrees, 90, 1e-6);
  }
  // A margin wider than the reach leaves no side.
  position.sideMargin = 3 * kSpacing;
  EXPECT_FALSE(fitCreaseLine(s.positions, s.normals, *index, x, along, position, &onEdge));
}

// A wedge half a spacing thick at its end, its faces tilted by 10 degrees each, its end (the rim)
// not sampled, as a scan can leave it: within the reach of a point at the end lie both faces, and
// their planes meet beyond the end, where no point lies.
TEST(CreaseLine, NoneBeyondTheEndOfAThinPart) {
  const double thickness = 0.5 * kSpacing, tilt = 10 * M_PI / 180;
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> along(-0.1, 0.1), depth(0.0, 0.1);
  Sample s;
  for (int i = 0; i < 12000; ++i) {
    const double d = depth(rng), side = i % 2 ? 1.0 : -1.0;
    // faces: z = +-(thickness / 2 + d tan(tilt)), y = -d (the end at y = 0)
    s.add(Vec3(along(rng), -d, side * (0.5 * thickness + d * std::tan(tilt))),
          Vec3(0, std::sin(tilt), side * std::cos(tilt)));
  }
  const auto index = makeSpatialIndex(s.positions);
  const Vec3 x(0, 0, 0), direction = Vec3::UnitX();
  EXPECT_FALSE(fitCreaseLine(s.positions, s.normals, *index, x, direction, options()));
  CreaseLineOptions unchecked = options();
  unchecked.maxGap = 0;
  const auto beyond = fitCreaseLine(s.positions, s.normals, *index, x, direction, unchecked);
  ASSERT_TRUE(beyond) << "without the gap check the faces' planes give a line";
  EXPECT_GT(beyond->point.y(), kSpacing) << "beyond the end";
}

// A thin part as above, its faces tilted by 5 degrees (within 2 spacings its points are one sheet,
// RimLineOptions::maxVariation), its end sampled or not: the rim is the line through its outermost
// points, in its mid-plane, along the end.
TEST(CreaseLine, TheRimOfAThinPartIsItsOutermostPoints) {
  const double thickness = 0.5 * kSpacing, tilt = 5 * M_PI / 180;
  for (bool endSampled : {false, true}) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> along(-0.1, 0.1), depth(0.0, 0.1), unit(-0.5, 0.5);
    std::vector<Vec3> points;
    for (int i = 0; i < 12000; ++i) {
      const double d = depth(rng), side = i % 2 ? 1.0 : -1.0;
      points.push_back(Vec3(along(rng), -d, side * (0.5 * thickness + d * std::tan(tilt))));
    }
    if (endSampled)
      for (int i = 0; i < 300; ++i) points.push_back(Vec3(along(rng), 0, thickness * unit(rng)));
    const auto index = makeSpatialIndex(points);
    RimLineOptions o;
    o.reach = 2 * kSpacing;
    o.maxInset = kSpacing;
    const Vec3 centre(0.01, -0.3 * kSpacing, 0.001);
    // 1 degree off in the plane (the outermost point across it lies up to reach x sin(1 degree)
    // out)
    const Vec3 slanted = Vec3(1, 0.02, 0.3).normalized();
    const auto rim = fitRimLine(points, *index, centre, slanted, o);
    ASSERT_TRUE(rim) << "end sampled " << endSampled;
    EXPECT_NEAR(rim->point.y(), 0, 0.05 * kSpacing);
    EXPECT_NEAR(rim->point.z(), 0, 0.1 * kSpacing) << "in the mid-plane";
    EXPECT_GT(std::abs(rim->direction.x()), std::cos(6 * M_PI / 180));
    EXPECT_GT(rim->across.y(), 0.99) << "outward";
    // Far inside the sheet the points surround the centre: no rim. Nor beyond maxInset of it.
    EXPECT_FALSE(fitRimLine(points, *index, Vec3(0, -5 * kSpacing, 0), slanted, o));
    RimLineOptions near = o;
    near.maxInset = 0.4 * kSpacing;
    EXPECT_FALSE(fitRimLine(points, *index, Vec3(0, -0.5 * kSpacing, 0), slanted, near));
    EXPECT_TRUE(fitRimLine(points, *index, Vec3(0, -0.5 * kSpacing, 0), slanted, o));
    // Salient vertices running across the sheet's plane are no rim's.
    EXPECT_FALSE(fitRimLine(points, *index, centre, Vec3(1, 0, 1.1).normalized(), o));
  }
}

// Points filling a ball are no sheet (surface variation 0.17), nor points along a line; beside a
// crease of 90 degrees (variation about 0.09: nearly one sheet) the points do not stop across the
// salient vertices' direction: no rim.
TEST(CreaseLine, NoRimInAVolumeNorOnARightAngle) {
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<Vec3> ball;
  while (ball.size() < 5000) {
    const Vec3 p(unit(rng), unit(rng), unit(rng));
    if (p.norm() <= 1) ball.push_back(0.05 * p);
  }
  RimLineOptions o;
  o.reach = 2 * kSpacing;
  o.maxInset = kSpacing;
  EXPECT_FALSE(fitRimLine(ball, *makeSpatialIndex(ball), Vec3(0.045, 0, 0), Vec3::UnitY(), o));
  std::vector<Vec3> line;
  for (int i = 0; i < 200; ++i) line.push_back(Vec3(0.0002 * i, 0, 0));
  EXPECT_FALSE(fitRimLine(line, *makeSpatialIndex(line), Vec3(0.02, 0, 0), Vec3::UnitX(), o));
  const Sample edge = sharpEdge(90, 23);
  EXPECT_FALSE(fitRimLine(edge.positions, *makeSpatialIndex(edge.positions),
                          Vec3(0, 0, -0.3 * kSpacing), Vec3::UnitX(), o));
}

// The band around a rim: inset, beyond and off the mid-plane, each by at most the half-width.
TEST(CreaseLine, WithinTheRimIsOnTheSheetNearItsBorder) {
  RimLine rim;
  rim.point = Vec3(0, 0, 0);
  rim.direction = Vec3::UnitX();
  rim.across = Vec3::UnitY();
  rim.normal = Vec3::UnitZ();
  EXPECT_TRUE(withinRim(rim, Vec3(5, -0.9, 0.2), 1));
  EXPECT_TRUE(withinRim(rim, Vec3(-5, 0.5, -0.9), 1));
  EXPECT_FALSE(withinRim(rim, Vec3(0, -1.1, 0), 1)) << "too far inside";
  EXPECT_FALSE(withinRim(rim, Vec3(0, 1.1, 0), 1)) << "beyond the rim";
  EXPECT_FALSE(withinRim(rim, Vec3(0, -0.2, 1.1), 1)) << "another surface beside the sheet";
}
