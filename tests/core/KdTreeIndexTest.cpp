#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/CoreTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/KdTreeIndex.hpp"
#include "scalespace/core/PointCloud.hpp"

using namespace scalespace;

namespace {

std::vector<Neighbor> byIndex(std::vector<Neighbor> v) {
  std::sort(v.begin(), v.end(),
            [](const Neighbor& a, const Neighbor& b) { return a.index < b.index; });
  return v;
}

void expectSame(const std::vector<Neighbor>& expected, const std::vector<Neighbor>& actual,
                const char* what) {
  ASSERT_EQ(expected.size(), actual.size()) << what;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(expected[i].index, actual[i].index) << what << " rank " << i;
    EXPECT_EQ(expected[i].distSq, actual[i].distSq) << what << " rank " << i;
  }
}

// Compares every query of the kd-tree with BruteForceIndex: radius results as sets (same indices
// and bit-identical distances), knn results rank by rank.
void compareWithBruteForce(const std::vector<Vec3>& points, const std::vector<Vec3>& queries,
                           const std::vector<double>& radii, const std::vector<std::size_t>& ks,
                           const KdTreeOptions& options = {}) {
  const KdTreeIndex tree(points, options);
  const BruteForceIndex brute(points);
  ASSERT_EQ(tree.size(), points.size());
  std::vector<Neighbor> a, b;
  for (const Vec3& q : queries) {
    for (double r : radii) {
      brute.radiusSearch(q, r, a);
      tree.radiusSearch(q, r, b);
      expectSame(byIndex(a), byIndex(b), "radius");
    }
    for (std::size_t k : ks) {
      brute.knnSearch(q, k, a);
      tree.knnSearch(q, k, b);
      expectSame(a, b, "knn");
    }
  }
}

std::vector<Vec3> withDataPoints(std::vector<Vec3> queries, const std::vector<Vec3>& points,
                                 std::size_t count) {
  for (std::size_t i = 0; i < count && i < points.size(); ++i)
    queries.push_back(points[(i * 7919) % points.size()]);
  return queries;
}

}  // namespace

TEST(KdTreeIndex, MatchesBruteForceOnRandomCloud) {
  const auto points = testclouds::uniformCube(3000, 1);
  const auto queries = withDataPoints(testclouds::uniformCube(60, 2, 1.2), points, 60);
  compareWithBruteForce(points, queries, {0.0, 0.01, 0.07, 0.3, 5.0}, {0, 1, 5, 10, 40, 5000});
}

TEST(KdTreeIndex, LeafSizeDoesNotChangeResults) {
  const auto points = testclouds::sphere(2000, 1.0, 3);
  const auto queries = withDataPoints(testclouds::uniformCube(20, 4), points, 30);
  for (std::size_t leaf : {1, 3, 10, 50, 5000})
    compareWithBruteForce(points, queries, {0.05, 0.2}, {1, 10, 40}, KdTreeOptions{leaf});
  EXPECT_THROW(KdTreeIndex(points, KdTreeOptions{0}), OptionError);
}

TEST(KdTreeIndex, ManyDuplicatesTieBrokenByIndex) {
  std::vector<Vec3> points(600, Vec3(0.5, 0.5, 0.5));
  const auto others = testclouds::uniformCube(200, 5);
  points.insert(points.begin() + 300, others.begin(), others.end());
  const KdTreeIndex tree(points, KdTreeOptions{4});
  std::vector<Neighbor> out;
  tree.knnSearch(Vec3(0.5, 0.5, 0.5), 10, out);
  ASSERT_EQ(out.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(out[i].index, Index(i));
    EXPECT_EQ(out[i].distSq, 0.0);
  }
  tree.radiusSearch(Vec3(0.5, 0.5, 0.5), 1e-12, out);
  EXPECT_EQ(out.size(), 600u);
  compareWithBruteForce(points, withDataPoints(testclouds::uniformCube(20, 6), points, 40),
                        {0.0, 1e-9, 0.1, 0.4}, {1, 10, 599, 600, 601, 2000});
}

TEST(KdTreeIndex, DuplicateGroupsOfEverySizeInAnyOrder) {
  // Scans repeat points: groups of 1-12 copies of 150 positions, shuffled, with -0 beside +0; each
  // group is one slot of the tree and must answer as the brute force does.
  std::mt19937 rng(11);
  const auto base = testclouds::uniformCube(150, 9);
  std::vector<Vec3> points;
  for (std::size_t g = 0; g < base.size(); ++g)
    for (std::size_t c = 0; c < 1 + g % 12; ++c) points.push_back(base[g]);
  points.push_back(Vec3(0.0, 0.25, 0.5));
  points.push_back(Vec3(-0.0, 0.25, 0.5));
  std::shuffle(points.begin(), points.end(), rng);
  const auto queries = withDataPoints(testclouds::uniformCube(30, 10), points, 60);
  for (std::size_t leaf : {1, 4, 16})
    compareWithBruteForce(points, queries, {0.0, 1e-12, 0.05, 0.3}, {1, 2, 7, 13, 40, 900, 5000},
                          KdTreeOptions{leaf});
}

TEST(KdTreeIndex, GridCoplanarAndColinearWithExactTies) {
  // An integer grid in a plane: many neighbours at exactly equal distances, and points at exactly
  // the search radius (which must be excluded: |p - q| < r is strict).
  std::vector<Vec3> grid;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) grid.emplace_back(i, j, 0.0);
  std::vector<Vec3> queries = withDataPoints({Vec3(10.5, 10.5, 0), Vec3(3, 4, 1)}, grid, 40);
  compareWithBruteForce(grid, queries, {1.0, 1.5, 2.0, 5.0}, {1, 4, 5, 9, 13, 25});
  const KdTreeIndex tree(grid);
  std::vector<Neighbor> out;
  tree.radiusSearch(Vec3(10, 10, 0), 1.0, out);
  ASSERT_EQ(out.size(), 1u);  // only the point itself; the 4 at distance exactly 1 excluded
  tree.knnSearch(Vec3(10, 10, 0), 5, out);
  ASSERT_EQ(out.size(), 5u);
  EXPECT_EQ(out[1].index, Index(9 * 30 + 10));  // ties at distance 1 in index order
  EXPECT_EQ(out[4].index, Index(11 * 30 + 10));

  std::vector<Vec3> line;
  for (int i = 0; i < 500; ++i) line.emplace_back(0.25 * i, 0.5 * i, -0.125 * i);
  compareWithBruteForce(line, withDataPoints({Vec3(1, 1, 1)}, line, 30), {0.3, 0.6, 3.0},
                        {1, 2, 3, 10});
}

TEST(KdTreeIndex, FarFromOriginAndRecentred) {
  std::vector<Vec3> absolute = testclouds::uniformCube(2000, 7, 10.0);
  for (Vec3& p : absolute) p += Vec3(1e6, 2e6, 300.0);
  // Raw georeferenced coordinates and the recentred ones both match brute force exactly.
  compareWithBruteForce(absolute, withDataPoints({}, absolute, 40), {0.3, 1.0}, {1, 10, 40});
  PointCloud cloud;
  cloud.setAbsolutePositions(absolute);
  compareWithBruteForce(cloud.positions(), withDataPoints({}, cloud.positions(), 40), {0.3, 1.0},
                        {1, 10, 40});
}

TEST(KdTreeIndex, EmptySinglePointAndBadQueries) {
  const std::vector<Vec3> none;
  const KdTreeIndex empty(none);
  std::vector<Neighbor> out{{1, 1.0}};
  empty.radiusSearch(Vec3::Zero(), 10.0, out);
  EXPECT_TRUE(out.empty());
  empty.knnSearch(Vec3::Zero(), 3, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(empty.size(), 0u);

  const std::vector<Vec3> one{Vec3(1, 2, 3)};
  const KdTreeIndex single(one);
  single.knnSearch(Vec3::Zero(), 3, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].index, 0u);
  EXPECT_DOUBLE_EQ(out[0].distSq, 14.0);
  single.radiusSearch(Vec3(1, 2, 3), 0.0, out);
  EXPECT_TRUE(out.empty());  // strict: nothing is closer than 0
  single.radiusSearch(Vec3(1, 2, 3), -1.0, out);
  EXPECT_TRUE(out.empty());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  single.knnSearch(Vec3(nan, 0, 0), 1, out);
  EXPECT_TRUE(out.empty());
}

TEST(KdTreeIndex, NonFinitePointsAreNeverReturned) {
  std::vector<Vec3> points = testclouds::uniformCube(100, 8);
  points[10] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  points[20] = Vec3(0, std::numeric_limits<double>::infinity(), 0);
  const KdTreeIndex tree(points);
  EXPECT_EQ(tree.size(), 100u);  // indices still refer to the caller's vector
  std::vector<Neighbor> out;
  tree.knnSearch(Vec3(0.5, 0.5, 0.5), 1000, out);
  EXPECT_EQ(out.size(), 98u);
  for (const Neighbor& n : out) EXPECT_TRUE(n.index != 10u && n.index != 20u);
  // BruteForceIndex never returns them from radius queries either.
  compareWithBruteForce(points, {Vec3(0.5, 0.5, 0.5)}, {0.3, 10.0}, {});
}

TEST(KdTreeIndex, DefaultIndexIsKdTreeAndConcurrentQueriesAgree) {
  const auto points = testclouds::uniformCube(5000, 9);
  const auto index = makeSpatialIndex(points);
  EXPECT_NE(dynamic_cast<const KdTreeIndex*>(index.get()), nullptr);
  std::vector<std::vector<Neighbor>> sequential(points.size()), parallel(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) index->knnSearch(points[i], 12, sequential[i]);
  tbb::parallel_for(std::size_t(0), points.size(),
                    [&](std::size_t i) { index->knnSearch(points[i], 12, parallel[i]); });
  for (std::size_t i = 0; i < points.size(); ++i) expectSame(sequential[i], parallel[i], "threads");
}
