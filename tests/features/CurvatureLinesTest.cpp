// Curvature lines (Sec. 3.3) on surfaces whose lines are known: the rulings of a cylinder, the
// parallels of a torus; none on a sphere or a plane (umbilic everywhere); options checked.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/features/CurvatureLines.hpp"

using namespace scalespace;

namespace {

double angleDegrees(const Vec3& a, const Vec3& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::min(1.0, c)) * 180 / M_PI;
}

PointCloud surface(SurfaceShape shape, std::size_t count, double ball = 0) {
  SurfaceSampleOptions options;
  options.shape = shape;
  options.count = count;
  options.ballRadius = ball;
  return sampleSurface(options);
}

CurvatureLineOptions atScale(double t) {
  CurvatureLineOptions options;
  options.scale = t;
  return options;
}

/// The longest edge of `set` over delta, the closing edges of closed lines included.
double longestEdgeInSteps(const CurvatureLineSet& set, const CurvatureLineOptions& options) {
  double longest = 0;
  for (const auto& line : set.lines) {
    const auto& v = line.vertices;
    for (std::size_t i = 1; i < v.size(); ++i)
      longest = std::max(longest, (v[i].position - v[i - 1].position).norm());
    if (line.closed) longest = std::max(longest, (v.front().position - v.back().position).norm());
  }
  return longest / (options.gamma * options.scale);
}

/// A thin wedge: two 1 x 1 sheets meeting at the edge x = z = 0 along y, opening `degrees`,
/// normals outwards. Near the edge both sheets lie within t of a point.
PointCloud wedge(double degrees, std::size_t count) {
  const double half = degrees / 2 * M_PI / 180;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<Vec3> positions, normals;
  for (std::size_t i = 0; i < count; ++i) {
    const double x = u01(rng), y = u01(rng), side = i % 2 ? 1 : -1;
    positions.emplace_back(x, y, side * x * std::tan(half));
    normals.emplace_back(-std::sin(half), 0, side * std::cos(half));
  }
  PointCloud cloud;
  cloud.setRelativePositions(positions, Vec3::Zero());
  cloud.setNormals(normals);
  return cloud;
}

std::size_t vertexCount(const CurvatureLineSet& set) {
  std::size_t n = 0;
  for (const auto& line : set.lines) n += line.vertices.size();
  return n;
}

}  // namespace

TEST(CurvatureLines, OnACylinderTheLinesAreItsRulings) {
  // Radius 1, axis y through (0, 0, -1); a patch within 1 of the origin.
  const PointCloud cloud = surface(SurfaceShape::Cylinder, 40000);
  const CurvatureLineSet set = traceCurvatureLines(cloud, atScale(0.1));
  ASSERT_GT(set.lines.size(), 10u);
  double worst = 0;
  std::size_t checked = 0;
  for (const auto& line : set.lines) {
    EXPECT_FALSE(line.closed);
    for (std::size_t i = 0; i < line.vertices.size(); ++i) {
      const CurvatureLineVertex& v = line.vertices[i];
      // The patch ends at distance 1 from the origin: nearer than t to its border a fit sees a
      // one-sided neighbourhood.
      if (v.position.norm() > 1 - 1.5 * 0.1) continue;
      // On the surface, with the cylinder's curvatures (kappa1 = 1 convex, kappa2 = 0).
      EXPECT_NEAR(std::hypot(v.position.x(), v.position.z() + 1), 1.0, 1e-3);
      EXPECT_NEAR(v.kappa1, 1.0, 0.1);
      EXPECT_NEAR(v.kappa2, 0.0, 0.1);
      worst = std::max(worst, angleDegrees(v.tangent, Vec3::UnitY()));
      if (i > 0) {  // the tangent follows the line, oriented forward
        const Vec3 chord = line.vertices[i].position - line.vertices[i - 1].position;
        EXPECT_GT(chord.dot(v.tangent), 0);
        EXPECT_NEAR(chord.norm(), 0.05, 0.005);  // delta = gamma t
      }
      ++checked;
    }
  }
  EXPECT_LT(worst, 1.0) << checked << " vertices";
}

TEST(CurvatureLines, LinesStopAtTheBorderOfTheData) {
  // The cylinder patch ends 1 from the origin: beyond, the APSS extrapolates.
  const PointCloud cloud = surface(SurfaceShape::Cylinder, 40000);
  CurvatureLineOptions options = atScale(0.1);
  auto beyond = [&](double& farthest) {
    std::size_t count = 0;
    farthest = 0;
    for (const auto& line : traceCurvatureLines(cloud, options).lines)
      for (const auto& v : line.vertices) {
        farthest = std::max(farthest, v.position.norm());
        count += v.position.norm() > 1;
      }
    return count;
  };
  double farthest = 0, farthestWithout = 0;
  EXPECT_GT(traceCurvatureLines(cloud, options).stops[std::size_t(LineStop::Border)], 0u);
  const std::size_t with = beyond(farthest);
  // The test trips on the first vertex past the border: within one step of it.
  EXPECT_LT(farthest, 1.0 + options.gamma * options.scale);
  options.borderOffset = 0;
  const std::size_t without = beyond(farthestWithout);
  EXPECT_GT(farthestWithout, farthest);
  EXPECT_LT(2 * with, without) << "vertices past the border";
}

TEST(CurvatureLines, OnATorusTheLinesAreItsParallelsAndClose) {
  // Major radius 2, minor 0.5, axis z through (-2, 0, -0.5).
  const PointCloud cloud = surface(SurfaceShape::Torus, 150000);
  const CurvatureLineSet set = traceCurvatureLines(cloud, atScale(0.12));
  ASSERT_GT(set.lines.size(), 5u);
  const Vec3 centre(-2, 0, -0.5);
  double worst = 0;
  std::size_t closed = 0;
  for (const auto& line : set.lines) {
    closed += line.closed;
    for (const CurvatureLineVertex& v : line.vertices) {
      const Vec3 p = v.position - centre;
      const Vec3 parallel(-p.y(), p.x(), 0);
      worst = std::max(worst, angleDegrees(v.tangent, parallel));
      EXPECT_NEAR(v.kappa1, 2.0, 0.3);  // around the tube (t / r = 0.24 biases it)
    }
  }
  EXPECT_LT(worst, 2.0);
  EXPECT_GT(closed, 0u) << "a parallel is a closed curve";
}

TEST(CurvatureLines, AClosedLineClosesOnlyWhereItsEndsMeet) {
  // On a torus at coarse scales the traced parallels drift across the tube (Euler steps), so a
  // line can wind more than once around and run into its own earlier turn: a self collision, not
  // a closed loop. Flagged closed, its closing edge would cut across the torus (28-134 delta in
  // `scalespace lines` on generated tori before this was fixed).
  const PointCloud cloud = surface(SurfaceShape::Torus, 150000);
  std::size_t closed = 0, selfCollisions = 0;
  for (const double t : {0.05, 0.06, 0.07}) {
    const CurvatureLineOptions options = atScale(t);
    const CurvatureLineSet set = traceCurvatureLines(cloud, options);
    const double delta = options.gamma * t;
    for (const auto& line : set.lines) {
      if (!line.closed) continue;
      ++closed;
      EXPECT_TRUE(line.stopBackward == LineStop::Loop || line.stopForward == LineStop::Loop);
      EXPECT_LE((line.vertices.front().position - line.vertices.back().position).norm(),
                (1 + 2 * options.collisionFraction) * delta)
          << "t = " << t;
    }
    EXPECT_LE(longestEdgeInSteps(set, options), 2.0) << "t = " << t;
    selfCollisions += set.stops[std::size_t(LineStop::SelfCollision)];
  }
  EXPECT_GT(closed, 0u);
  EXPECT_GT(selfCollisions, 0u) << "the case this test is about did not occur";
}

TEST(CurvatureLines, AWayStopsWhereTheProjectionLeavesItsSheet) {
  // Near the edge of a thin wedge (5 degrees) the other sheet is within t: the MLS projection of
  // a step can land on it or between the sheets, far from q + delta v; the way stops there
  // instead of drawing an edge of 2.5-3 delta across the wedge.
  const PointCloud cloud = wedge(5, 60000);
  std::size_t jumps = 0;
  for (const double t : {0.0127, 0.0232, 0.0775}) {
    const CurvatureLineOptions options = atScale(t);
    const CurvatureLineSet set = traceCurvatureLines(cloud, options);
    EXPECT_LE(longestEdgeInSteps(set, options), 2.0) << "t = " << t;
    jumps += set.stops[std::size_t(LineStop::Jump)];
  }
  EXPECT_GT(jumps, 0u);
  // On a smooth sheet the projection moves a step by about kappa2 delta^2 / 2: the default bound
  // never trips on a torus; a bound below that stops ways there.
  const PointCloud torus = surface(SurfaceShape::Torus, 30000);
  CurvatureLineOptions options = atScale(0.12);
  const CurvatureLineSet smooth = traceCurvatureLines(torus, options);
  EXPECT_EQ(smooth.stops[std::size_t(LineStop::Jump)], 0u);
  options.maxProjectionShift = 1e-4;
  const CurvatureLineSet tight = traceCurvatureLines(torus, options);
  EXPECT_GT(tight.stops[std::size_t(LineStop::Jump)], 0u);
  EXPECT_LT(vertexCount(tight), vertexCount(smooth));
}

TEST(CurvatureLines, UmbilicSurfacesHaveNoLines) {
  for (const SurfaceShape shape : {SurfaceShape::Sphere}) {
    const CurvatureLineSet set = traceCurvatureLines(surface(shape, 30000), atScale(0.15));
    EXPECT_EQ(set.lines.size(), 0u);
    EXPECT_GT(set.stops[std::size_t(LineStop::Umbilic)], 0u);
    EXPECT_EQ(set.seedKappa1.size(), 0u) << "no seed has a minimal direction";
  }
  // A plane: a square of points with normals +z.
  PointCloud plane;
  std::vector<Vec3> positions, normals;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j) {
      positions.emplace_back(0.01 * i, 0.01 * j, 0);
      normals.emplace_back(0, 0, 1);
    }
  plane.setRelativePositions(positions, Vec3::Zero());
  plane.setNormals(normals);
  EXPECT_EQ(traceCurvatureLines(plane, atScale(0.05)).lines.size(), 0u);
}

TEST(CurvatureLines, LinesOfOneScaleKeepApart) {
  const PointCloud cloud = surface(SurfaceShape::Cylinder, 40000);
  CurvatureLineOptions options = atScale(0.1);
  const CurvatureLineSet set = traceCurvatureLines(cloud, options);
  const double minDistance = options.collisionFraction * options.gamma * options.scale;
  // Every vertex of a line is at least the collision distance from the vertices of earlier lines,
  // except the vertex that stopped on them (at most one per way).
  for (std::size_t a = 0; a < set.lines.size(); ++a) {
    std::size_t close = 0;
    for (const auto& va : set.lines[a].vertices)
      for (std::size_t b = 0; b < a; ++b)
        for (const auto& vb : set.lines[b].vertices)
          if ((va.position - vb.position).norm() < 0.999 * minDistance) ++close;
    EXPECT_EQ(close, 0u) << "line " << a;
  }
}

TEST(CurvatureLines, SameResultForAnyThreadCount) {
  const PointCloud cloud = surface(SurfaceShape::Torus, 30000);
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return traceCurvatureLines(cloud, atScale(0.15));
  };
  const CurvatureLineSet one = run(1), many = run(4);
  ASSERT_EQ(one.lines.size(), many.lines.size());
  ASSERT_EQ(vertexCount(one), vertexCount(many));
  for (std::size_t l = 0; l < one.lines.size(); ++l)
    for (std::size_t v = 0; v < one.lines[l].vertices.size(); ++v) {
      EXPECT_EQ(one.lines[l].vertices[v].position, many.lines[l].vertices[v].position);
      EXPECT_EQ(one.lines[l].vertices[v].kappa1, many.lines[l].vertices[v].kappa1);
    }
}

TEST(CurvatureLines, CoarseScalesReadThePyramid) {
  const PointCloud cloud = surface(SurfaceShape::Cylinder, 40000);
  CurvatureLineOptions options = atScale(0.3);
  const CurvatureLineSet pyramid = traceCurvatureLines(cloud, options);
  options.alpha = 0;
  const CurvatureLineSet full = traceCurvatureLines(cloud, options);
  EXPECT_EQ(full.samples, cloud.size());
  EXPECT_LT(pyramid.samples, cloud.size() / 4);
  ASSERT_GT(pyramid.lines.size(), 0u);
  double worst = 0;
  for (const auto& line : pyramid.lines)
    for (const auto& v : line.vertices)
      if (v.position.norm() < 1 - 1.5 * options.scale)  // away from the patch's border
        worst = std::max(worst, angleDegrees(v.tangent, Vec3::UnitY()));
  EXPECT_LT(worst, 1.0);
}

TEST(CurvatureLines, InvalidOptionsAndInputsAreRefused) {
  const PointCloud cloud = surface(SurfaceShape::Cylinder, 2000);
  auto refused = [&](auto change, const char* field) {
    CurvatureLineOptions options = atScale(0.1);
    change(options);
    try {
      traceCurvatureLines(cloud, options);
      ADD_FAILURE() << field << " accepted";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  refused([](auto& o) { o.scale = 0; }, "CurvatureLineOptions::scale");
  refused([](auto& o) { o.scale = NAN; }, "CurvatureLineOptions::scale");
  refused([](auto& o) { o.beta = -1; }, "CurvatureLineOptions::beta");
  refused([](auto& o) { o.gamma = INFINITY; }, "CurvatureLineOptions::gamma");
  refused([](auto& o) { o.alpha = 0.7; }, "CurvatureLineOptions::alpha");
  refused([](auto& o) { o.fit.estimator = EstimatorKind::W1; }, "fit.estimator");
  refused([](auto& o) { o.fit.mls = false; }, "fit.mls");
  refused([](auto& o) { o.maxSteps = 0; }, "CurvatureLineOptions::maxSteps");
  refused([](auto& o) { o.maxTurnDegrees = 0; }, "CurvatureLineOptions::maxTurnDegrees");
  refused([](auto& o) { o.maxProjectionShift = 0; }, "CurvatureLineOptions::maxProjectionShift");
  PointCloud noNormals;
  noNormals.setRelativePositions(cloud.positions(), Vec3::Zero());
  EXPECT_THROW(traceCurvatureLines(noNormals, atScale(0.1)), OptionError);
  // Cancelled through the progress callback.
  EXPECT_THROW(
      traceCurvatureLines(cloud, atScale(0.1), [](double, std::string_view) { return false; }),
      Cancelled);
  // An empty cloud and a scale far beyond it give no lines, no crash.
  PointCloud empty;
  empty.setNormals({});
  EXPECT_EQ(traceCurvatureLines(empty, atScale(0.1)).lines.size(), 0u);
}

TEST(CurvatureLines, TheLineOnACreaseIsTracedFirst) {
  // A 90-degree wedge: its crease is the y axis (x = z = 0), which the APSS rounds over about
  // 0.3 t (|kappa1| t about 3 at 0.13 t from the axis, 2 at 0.27 t, 1 at 0.45 t). With
  // curvedSeedsFirst the most curved seed starts the first line: on the crease and along it. In
  // the random order the first line is a random seed's (here 0.5-1 t beside the crease).
  const PointCloud cloud = wedge(90, 60000);
  const double t = 0.06;
  CurvatureLineOptions options = atScale(t);
  for (const bool curvedFirst : {true, false}) {
    options.curvedSeedsFirst = curvedFirst;
    const CurvatureLineSet set = traceCurvatureLines(cloud, options);
    ASSERT_GE(set.lines.size(), 10u);
    double farthest = 0, turned = 0;
    for (const auto& v : set.lines.front().vertices) {
      farthest = std::max(farthest, std::hypot(v.position.x(), v.position.z()));
      turned = std::max(turned, angleDegrees(v.tangent, Vec3::UnitY()));
    }
    if (curvedFirst) {
      EXPECT_LT(farthest, 0.25 * t);
      EXPECT_LT(turned, 20.0);
      EXPECT_GT(std::abs(set.lines.front().vertices[1].kappa1) * t, 2.5);
    } else {
      EXPECT_GT(farthest, 0.25 * t);  // the known answer of the random order, for contrast
    }
  }
}
