#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "scalespace/planes/AlphaShapeArea.hpp"

using namespace scalespace;

namespace {
double perimeter(const std::vector<Vec2>& loop) {
  double p = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) p += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  return p;
}
double signedArea(const std::vector<Vec2>& loop) {
  double a = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec2& p = loop[i];
    const Vec2& q = loop[(i + 1) % loop.size()];
    a += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  return a;
}
}  // namespace

TEST(AlphaShape, GridSquareHasItsAreaAndOneOutline) {
  std::vector<Vec2> pts;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j) pts.emplace_back(i / 40.0, j / 40.0);
  const double radius = 0.1;
  const AlphaShape shape = alphaShape2(pts, radius * radius, true);
  EXPECT_NEAR(shape.area, 1.0, 1e-9);
  ASSERT_EQ(shape.outlines.size(), 1u);
  EXPECT_NEAR(perimeter(shape.outlines[0]), 4.0, 1e-9);
  EXPECT_NEAR(signedArea(shape.outlines[0]), 1.0, 1e-9);  // counter-clockwise, encloses the square
}

TEST(AlphaShape, RandomSquareAreaAndSeparateParts) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec2> pts;
  for (int i = 0; i < 4000; ++i) pts.emplace_back(u(rng), u(rng));
  // Two unit squares 5 apart: with a radius far below the gap, two parts and twice the area.
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) pts.push_back(pts[i] + Vec2(6, 0));
  const AlphaShape shape = alphaShape2(pts, 0.1 * 0.1, true);
  EXPECT_NEAR(shape.area, 2.0, 0.05);
  EXPECT_LT(shape.area, 2.0 + 1e-12);  // never more than the convex hulls
  EXPECT_EQ(shape.outlines.size(), 2u);
  // A huge radius gives the convex hull: one part, bridging the gap.
  const AlphaShape hull = alphaShape2(pts, 1e4, true);
  EXPECT_GT(hull.area, 6.5);
  EXPECT_EQ(hull.outlines.size(), 1u);
  EXPECT_EQ(alphaShape2({Vec2(0, 0), Vec2(1, 0)}, 1.0).area, 0.0);
}

TEST(AlphaShape, MatchesCgalAlphaShape2Regularized) {
  // Our shape is read off the Delaunay triangulation; it must be CGAL's Alpha_shape_2 in
  // REGULARIZED mode: same interior area, same boundary (regular) edges, for any alpha.
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Tds = CGAL::Triangulation_data_structure_2<CGAL::Alpha_shape_vertex_base_2<K>,
                                                   CGAL::Alpha_shape_face_base_2<K>>;
  using Shape = CGAL::Alpha_shape_2<CGAL::Delaunay_triangulation_2<K, Tds>>;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0, 1);
  std::vector<Vec2> pts;
  std::vector<K::Point_2> cgalPts;
  for (int i = 0; i < 3000; ++i) {
    pts.emplace_back(g(rng), 0.3 * g(rng));
    cgalPts.emplace_back(pts.back().x(), pts.back().y());
  }
  for (double radius : {0.02, 0.05, 0.1, 0.3, 1.0, 10.0}) {
    const AlphaShape ours = alphaShape2(pts, radius * radius, true);
    EXPECT_EQ(alphaShape2(pts, radius * radius, false).area, ours.area);
    const Shape cgal(cgalPts.begin(), cgalPts.end(), K::FT(radius * radius), Shape::REGULARIZED);
    double area = 0;
    for (auto f = cgal.finite_faces_begin(); f != cgal.finite_faces_end(); ++f)
      if (cgal.classify(f) == Shape::INTERIOR)
        area += std::abs(CGAL::to_double(cgal.triangle(f).area()));
    EXPECT_NEAR(ours.area, area, 1e-12 * std::max(1.0, area)) << radius;
    std::size_t edges = 0, loopEdges = 0;
    double signedSum = 0;
    for (auto e = cgal.alpha_shape_edges_begin(); e != cgal.alpha_shape_edges_end(); ++e) ++edges;
    for (const auto& loop : ours.outlines) {
      loopEdges += loop.size();
      signedSum += signedArea(loop);
    }
    EXPECT_EQ(loopEdges, edges) << radius;
    // Counter-clockwise outer loops and clockwise holes enclose exactly the interior area.
    EXPECT_NEAR(signedSum, ours.area, 1e-9 * std::max(1.0, ours.area)) << radius;
    if (radius > 0.02) {
      EXPECT_GT(ours.area, 0.0);
    }
  }
}

TEST(AlphaShape, AnnulusHasTwoLoops) {
  std::vector<Vec2> pts;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j <= 60; ++j) {
      const Vec2 p(i / 20.0 - 1.5, j / 20.0 - 1.5);
      if (p.cwiseAbs().maxCoeff() > 0.5) pts.push_back(p);  // 3x3 square minus a 1x1 hole
    }
  const AlphaShape shape = alphaShape2(pts, 0.08 * 0.08, true);
  // The hole's edge points are 0.05 inside it; its corners are cut by a few half cells.
  EXPECT_NEAR(shape.area, 9.0 - 1.1 * 1.1, 0.025);
  EXPECT_EQ(shape.outlines.size(), 2u);
}

TEST(PlaneFit, TiltedPlaneExact) {
  std::vector<Vec3> pts;
  std::vector<Index> idx;
  const Vec3 n = Vec3(1, 2, 2) / 3.0;
  const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      pts.push_back(Vec3(1, 1, 1) + i * 0.1 * a + j * 0.1 * b + 0.5 * n);
      idx.push_back(Index(pts.size() - 1));
    }
  const PlaneFit fit = fitPlane(pts, idx);
  ASSERT_TRUE(fit.valid);
  EXPECT_NEAR(std::abs(fit.normal.dot(n)), 1.0, 1e-12);
  EXPECT_NEAR(fit.rms, 0.0, 1e-12);
  for (Index i : idx) EXPECT_NEAR(fit.normal.dot(pts[i]), fit.offset, 1e-12);
  const auto flat = projectOnPlane(fit, pts, idx);
  for (std::size_t k = 0; k < idx.size(); ++k)
    EXPECT_NEAR((liftFromPlane(fit, flat[k]) - pts[idx[k]]).norm(), 0, 1e-12);
  EXPECT_FALSE(fitPlane(pts, {0, 1}).valid);
}

TEST(AlphaShape, AreaAtLeastAgreesWithTheFullShape) {
  // Early answers (bounding box, convex hull, a thinned or a certified patch) must equal the full
  // shape's.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::vector<Vec2>> sets(5);
  for (int i = 0; i < 4000; ++i) sets[0].emplace_back(20 * u(rng), u(rng));  // long strip
  for (int i = 0; i < 3000; ++i) {  // L shape: its hull is much larger than its area
    const Vec2 p(u(rng), 6 * u(rng));
    sets[1].push_back(i % 2 ? p : Vec2(p.y(), p.x()));
  }
  for (int i = 0; i < 40; ++i) sets[2].emplace_back(u(rng), u(rng));    // small: no patch
  for (int i = 0; i < 8000; ++i) sets[3].emplace_back(u(rng), u(rng));  // dense: thinned patch
  for (int i = 0; i < 4000; ++i) {  // annulus: its middle is a hole, so no patch there
    const double a = 6.283185307179586 * u(rng), r = 1 + 0.1 * u(rng);
    sets[4].emplace_back(r * std::cos(a), r * std::sin(a));
  }
  for (const auto& pts : sets)
    for (double radius : {0.03, 0.07, 0.1, 0.5, 3.0}) {
      const double alpha = radius * radius;
      const double area = alphaShape2(pts, alpha).area;
      for (double f : {0.3, 0.97, 1.03, 3.0}) {
        const double minArea = f * area + (area == 0 ? f : 0);
        EXPECT_EQ(alphaShapeAreaAtLeast(pts, alpha, minArea), area >= minArea)
            << pts.size() << " points, radius " << radius << ", threshold x" << f;
      }
      // The region filter's question (area >= radius^2): on the large sets a patch around the
      // middle answers it.
      EXPECT_EQ(alphaShapeAreaAtLeast(pts, alpha, alpha), area >= alpha) << radius;
    }
  EXPECT_FALSE(alphaShapeAreaAtLeast({Vec2(0, 0), Vec2(1, 0)}, 1.0, 1e-9));
  EXPECT_TRUE(alphaShapeAreaAtLeast({Vec2(0, 0), Vec2(1, 0)}, 1.0, 0.0));
}

TEST(AlphaShape, SubsetLowerBoundNeverExceedsTheArea) {
  // Sets with holes, concave corners, sparse and dense parts; cells from coarse to fine.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::vector<Vec2>> sets(4);
  for (int i = 0; i < 6000; ++i) sets[0].emplace_back(u(rng), u(rng));  // dense square
  for (int i = 0; i < 6000; ++i) {                                      // annulus
    const double a = 6.283185307179586 * u(rng), r = 1 + 0.5 * u(rng);
    sets[1].emplace_back(r * std::cos(a), r * std::sin(a));
  }
  for (int i = 0; i < 4000; ++i) {  // L shape
    const Vec2 p(u(rng), 4 * u(rng));
    sets[2].push_back(i % 2 ? p : Vec2(p.y(), p.x()));
  }
  for (int i = 0; i < 3000; ++i)  // clusters with gaps between them
    sets[3].emplace_back(double(i % 5) + 0.6 * u(rng), 0.6 * u(rng));
  for (const auto& pts : sets)
    for (double radius : {0.05, 0.2, 0.7, 3.0}) {
      const double alpha = radius * radius;
      const double area = alphaShape2(pts, alpha).area;
      for (double cell : {radius / 2, radius / 8, radius / 32, 1e-4}) {
        const double bound = alphaShapeAreaLowerBound(pts, alpha, cell);
        EXPECT_LE(bound, area * (1 + 1e-12))
            << pts.size() << " radius " << radius << " cell " << cell;
        EXPECT_GE(bound, 0);
      }
    }
  // Dense points, cell << radius: the bound is nearly the area (what makes it useful).
  const double alpha = 0.3 * 0.3;
  EXPECT_GT(alphaShapeAreaLowerBound(sets[0], alpha, 0.3 / 32),
            0.9 * alphaShape2(sets[0], alpha).area);
  // A cell finer than the spacing keeps every point: only the segments are subtracted.
  const double full = alphaShape2(sets[0], alpha).area;
  EXPECT_GT(alphaShapeAreaLowerBound(sets[0], alpha, 1e-6), 0.95 * full);
  EXPECT_EQ(alphaShapeAreaLowerBound({Vec2(0, 0), Vec2(1, 0)}, 1.0, 0.1), 0.0);
}

TEST(AlphaShape, SubsetLowerBoundSubtractsTheBoundarySegments) {
  // The subset {a, b, c} (d shares c's cell of side 0.95) is one interior triangle of area 0.891
  // (circumradius 0.994 <= 1). With d just inside the long edge ab, the flat triangle abd
  // (circumradius 4.95) leaves the full shape, whose area is 0.792 < 0.891: only the circular
  // segment on ab keeps the bound below it.
  const std::vector<Vec2> pts = {Vec2(-0.99, 0), Vec2(0.99, 0), Vec2(0, -0.9), Vec2(0, -0.1)};
  const double area = alphaShape2(pts, 1.0).area;
  EXPECT_NEAR(area, 0.891 - 0.099, 1e-9);
  EXPECT_NEAR(alphaShape2({pts[0], pts[1], pts[2]}, 1.0).area, 0.891, 1e-9);
  EXPECT_LE(alphaShapeAreaLowerBound(pts, 1.0, 0.95), area);
}
