// Curves split into edges at their corners (features/CurveEdges): an L of two straight arms is two
// edges, a gently curved arc one, a gap along a straight edge does not split it.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <cmath>
#include <set>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/features/CurveEdges.hpp"

using namespace scalespace;

namespace {

constexpr double kSpacing = 0.01;

// A band of points along the polyline through `corners`, 5 across (1.8 spacings wide, as the
// feature band is), one row every spacing.
std::vector<Vec3> bandAlong(const std::vector<Vec3>& corners) {
  std::vector<Vec3> points;
  for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
    const Vec3 d = corners[k + 1] - corners[k];
    const Vec3 across = d.cross(Vec3::UnitZ()).normalized();
    const int steps = int(std::lround(d.norm() / kSpacing));
    for (int s = k == 0 ? 0 : 1; s <= steps; ++s)
      for (int w = -2; w <= 2; ++w)  // offsets staggered along: a uniform band, as the votes'
        points.push_back(corners[k] + d * ((s + 0.2 * w) / steps) + 0.45 * kSpacing * w * across);
  }
  return points;
}

CurveEdgeOptions options() { return {4 * kSpacing, 0.15, 1.5 * kSpacing}; }

}  // namespace

TEST(CurveEdges, AnLIsTwoEdgesSplitAtItsCorner) {
  const std::vector<Vec3> points = bandAlong({Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(0, 1, 0)});
  const CurveEdges edges = splitCurvesAtCorners(points, buildKnnGraph(points, 10),
                                                std::vector<int>(points.size(), 0), options());
  ASSERT_EQ(edges.points.size(), 2u);
  EXPECT_EQ(edges.curveOf, (std::vector<int>{0, 0}));
  // Away from the corner each arm is one edge; the corner's points went to one of the two.
  std::set<int> armX, armY;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].x() > 0.1) armX.insert(edges.edgeId[i]);
    if (points[i].y() > 0.1) armY.insert(edges.edgeId[i]);
    EXPECT_GE(edges.edgeId[i], 0);
  }
  EXPECT_EQ(armX.size(), 1u);
  EXPECT_EQ(armY.size(), 1u);
  EXPECT_NE(*armX.begin(), *armY.begin());
}

TEST(CurveEdges, AGentleArcAndAGapDoNotSplit) {
  std::vector<Vec3> arc;
  for (int k = 0; k <= 16; ++k) {
    const double a = 1.5707963 * k / 16;
    arc.push_back(Vec3(std::cos(a), std::sin(a), 0));  // radius 100 spacings
  }
  std::vector<Vec3> points = bandAlong(arc);
  // A straight edge with a gap of one spacing in it, beside the arc as a second curve.
  std::vector<Vec3> line = bandAlong({Vec3(0, 0, 1), Vec3(1, 0, 1)});
  std::vector<int> curve(points.size(), 0);
  for (const Vec3& p : line)
    if (std::abs(p.x() - 0.5) > 0.004) points.push_back(p), curve.push_back(3);
  const CurveEdges edges =
      splitCurvesAtCorners(points, buildKnnGraph(points, 10), curve, options());
  ASSERT_EQ(edges.points.size(), 2u);
  EXPECT_EQ(edges.curveOf, (std::vector<int>{0, 3}));
  // Points in no curve are in no edge; bad options are refused.
  curve[0] = -1;
  EXPECT_EQ(splitCurvesAtCorners(points, buildKnnGraph(points, 10), curve, options()).edgeId[0],
            -1);
  CurveEdgeOptions bad = options();
  bad.radius = 0;
  EXPECT_THROW(splitCurvesAtCorners(points, buildKnnGraph(points, 10), curve, bad), OptionError);
  bad = options();
  bad.maxSpread = 2;
  EXPECT_THROW(splitCurvesAtCorners(points, buildKnnGraph(points, 10), curve, bad), OptionError);
  EXPECT_THROW(splitCurvesAtCorners(points, buildKnnGraph(points, 10), {0}, options()),
               OptionError);
}

TEST(CurveEdges, AStraightEdgeBrokenByWideSpotsIsJoinedAgainButNotRoundACorner) {
  // An L whose long arm's band widens into a disc every 15 spacings (a scan's noisy band): the
  // linearity test fails at each disc and cuts the arm; the pieces lie along one line.
  std::vector<Vec3> points = bandAlong({Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(0, 0.5, 0)});
  for (int spot = 1; spot <= 5; ++spot)
    for (int u = -3; u <= 3; ++u)
      for (int v = -3; v <= 3; ++v)
        if (u * u + v * v <= 9)
          points.push_back(Vec3(0.15 * spot + 0.8 * kSpacing * u, 0.8 * kSpacing * v, 0));
  const std::vector<int> curve(points.size(), 0);
  const KnnGraph graph = buildKnnGraph(points, 10);
  CurveEdgeOptions apart = options();
  apart.mergeAngleDegrees = 0;
  const CurveEdges pieces = splitCurvesAtCorners(points, graph, curve, apart);
  EXPECT_GE(pieces.points.size(), 4u);  // the discs cut the long arm
  const CurveEdges edges = splitCurvesAtCorners(points, graph, curve, options());
  ASSERT_EQ(edges.points.size(), 2u);
  std::set<int> armX, armY;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].x() > 0.1) armX.insert(edges.edgeId[i]);
    if (points[i].y() > 0.1) armY.insert(edges.edgeId[i]);
  }
  EXPECT_EQ(armX.size(), 1u);
  EXPECT_EQ(armY.size(), 1u);
  EXPECT_NE(*armX.begin(), *armY.begin());
  {  // the joining is sequential: one thread gives the same edges
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(splitCurvesAtCorners(points, graph, curve, options()).edgeId, edges.edgeId);
  }
  CurveEdgeOptions bad = options();
  bad.mergeThickening = 0.5;
  EXPECT_THROW(splitCurvesAtCorners(points, graph, curve, bad), OptionError);
  bad = options();
  bad.mergeAngleDegrees = 120;
  EXPECT_THROW(splitCurvesAtCorners(points, graph, curve, bad), OptionError);
}

TEST(CurveEdges, AStraightLineIsNotJoinedAcrossAJunction) {
  // A T: where the stem meets the bar, the bar is two edges, as on a mesh (its vertex there joins
  // three sharp edges), though its two halves lie along one line.
  std::vector<Vec3> points = bandAlong({Vec3(-0.6, 0, 0), Vec3(0.6, 0, 0)});
  for (const Vec3& p : bandAlong({Vec3(0, 0.5, 0), Vec3(0, 0.015, 0)})) points.push_back(p);
  const CurveEdges edges = splitCurvesAtCorners(points, buildKnnGraph(points, 10),
                                                std::vector<int>(points.size(), 0), options());
  ASSERT_EQ(edges.points.size(), 3u);
  std::set<int> left, right, stem;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].x() < -0.1) left.insert(edges.edgeId[i]);
    if (points[i].x() > 0.1) right.insert(edges.edgeId[i]);
    if (points[i].y() > 0.1) stem.insert(edges.edgeId[i]);
  }
  ASSERT_EQ(left.size(), 1u);
  ASSERT_EQ(right.size(), 1u);
  ASSERT_EQ(stem.size(), 1u);
  EXPECT_EQ((std::set<int>{*left.begin(), *right.begin(), *stem.begin()}).size(), 3u);
}
