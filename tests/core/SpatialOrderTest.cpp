#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "core/CoreTestClouds.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialOrder.hpp"

using namespace scalespace;

namespace {
bool isPermutation(const std::vector<Index>& order) {
  std::vector<Index> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (sorted[i] != i) return false;
  return true;
}
}  // namespace

TEST(SpatialOrder, MortonCodeInterleavesBits) {
  EXPECT_EQ(mortonCode(0, 0, 0), 0u);
  EXPECT_EQ(mortonCode(1, 0, 0), 1u);
  EXPECT_EQ(mortonCode(0, 1, 0), 2u);
  EXPECT_EQ(mortonCode(0, 0, 1), 4u);
  EXPECT_EQ(mortonCode(2, 0, 0), 8u);
  EXPECT_EQ(mortonCode(3, 3, 3), 63u);
  const std::uint32_t all = (1u << 21) - 1;
  EXPECT_EQ(mortonCode(all, all, all), (std::uint64_t(1) << 63) - 1);
}

TEST(SpatialOrder, IsADeterministicPermutationForAnyThreadCount) {
  const auto points = testclouds::uniformCube(20000, 11);
  std::vector<Index> one, two;
  {
    ThreadLimit limit(1);
    one = spatialOrder(points);
  }
  {
    ThreadLimit limit(2);
    two = spatialOrder(points);
  }
  EXPECT_TRUE(isPermutation(one));
  EXPECT_EQ(one, two);
  EXPECT_EQ(spatialOrder(points), one);
}

TEST(SpatialOrder, FollowsTheZCurveAndImprovesLocality) {
  // The 2x2x2 corners of a cube come out in Morton order: x fastest, then y, then z.
  std::vector<Vec3> corners;
  for (int z = 1; z >= 0; --z)
    for (int y = 1; y >= 0; --y)
      for (int x = 1; x >= 0; --x) corners.emplace_back(x, y, z);
  const std::vector<Index> order = spatialOrder(corners);
  const std::vector<Index> expected{7, 6, 5, 4, 3, 2, 1, 0};
  EXPECT_EQ(order, expected);

  // Mean distance between consecutive points drops by far after ordering.
  const auto points = testclouds::sphere(20000, 1.0, 12);
  auto meanStep = [](const std::vector<Vec3>& p) {
    double s = 0;
    for (std::size_t i = 1; i < p.size(); ++i) s += (p[i] - p[i - 1]).norm();
    return s / double(p.size() - 1);
  };
  const double before = meanStep(points);
  const double after = meanStep(applyPermutation(points, spatialOrder(points)));
  EXPECT_LT(after, 0.1 * before);
}

TEST(SpatialOrder, DegenerateInputs) {
  EXPECT_TRUE(spatialOrder({}).empty());
  EXPECT_EQ(spatialOrder({Vec3(1, 2, 3)}), std::vector<Index>{0});
  // All identical: ties broken by index.
  const std::vector<Vec3> same(5, Vec3(1, 1, 1));
  EXPECT_EQ(spatialOrder(same), (std::vector<Index>{0, 1, 2, 3, 4}));
  // Non-finite points go last, in index order.
  std::vector<Vec3> p = testclouds::uniformCube(10, 13);
  p[2] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  p[5] = Vec3(0, 0, std::numeric_limits<double>::infinity());
  const auto order = spatialOrder(p);
  EXPECT_TRUE(isPermutation(order));
  EXPECT_EQ(order[8], 2u);
  EXPECT_EQ(order[9], 5u);
}

TEST(SpatialOrder, PermutationHelpers) {
  const std::vector<double> values{10, 11, 12, 13, 14};
  const std::vector<Index> order{3, 0, 4, 1, 2};
  const auto permuted = applyPermutation(values, order);
  EXPECT_EQ(permuted, (std::vector<double>{13, 10, 14, 11, 12}));
  const auto inverse = invertPermutation(order);
  EXPECT_EQ(applyPermutation(permuted, inverse), values);
  EXPECT_THROW(applyPermutation(values, std::vector<Index>{0, 1}), OptionError);
  EXPECT_THROW(invertPermutation({0, 0, 1}), OptionError);
  EXPECT_THROW(invertPermutation({0, 3, 1}), OptionError);
  EXPECT_TRUE(invertPermutation({}).empty());
}

TEST(Parallel, ParallelForVisitsEveryIndexOnceAndThreadLimitApplies) {
  std::vector<int> hits(10007, 0);
  parallelFor(
      hits.size(), [&](std::size_t i) { hits[i] += 1; }, 64);
  EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; }));
  parallelFor(
      0, [&](std::size_t) { FAIL(); }, 0);
  {
    ThreadLimit limit(1);
    EXPECT_EQ(ThreadLimit::active(), 1u);
  }
  { ThreadLimit all(0); }
  EXPECT_THROW(ThreadLimit(-1), OptionError);
}

namespace {
// The octree cell (cells `side` wide, a 16-wide lattice) of a lattice point.
int cellOf(const Vec3& p, int side) {
  const int n = 16 / side;
  return (int(p.x()) / side) + n * ((int(p.y()) / side) + n * (int(p.z()) / side));
}
}  // namespace

TEST(CoarseToFineOrder, EveryLevelsPrefixHoldsOnePointPerCell) {
  // A 16^3 lattice, shuffled: the first 8 points are one per octant, the first 64 one per cell of
  // the 4x4x4 grid, the first 512 one per cell of the 8x8x8 grid.
  std::vector<Vec3> lattice;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) lattice.emplace_back(x, y, z);
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < lattice.size(); ++i) points.push_back(lattice[(i * 1999) % 4096]);
  const std::vector<Index> order = coarseToFineOrder(points);
  EXPECT_TRUE(isPermutation(order));
  for (int side : {8, 4, 2}) {
    const std::size_t cells = std::size_t(16 / side) * (16 / side) * (16 / side);
    std::vector<int> hits(cells, 0);
    for (std::size_t k = 0; k < cells; ++k) ++hits[std::size_t(cellOf(points[order[k]], side))];
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), std::ptrdiff_t(cells)) << side;
  }
}

TEST(CoarseToFineOrder, APrefixIsEvenWhereEveryKthPointIsNot) {
  // 90% of the points in a corner 1/1000 of the volume (a scan's points near the scanner): the
  // first 1000 points of the order hold few of them, every k-th point nine in ten.
  std::vector<Vec3> points = testclouds::uniformCube(20000, 21);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (i % 10 != 0) points[i] *= 0.1;
  const auto inCorner = [](const Vec3& p) { return (p.array() <= 0.1).all(); };
  const std::vector<Index> order = coarseToFineOrder(points);
  std::size_t corner = 0, everyKth = 0;
  for (std::size_t k = 0; k < 1000; ++k) {
    corner += inCorner(points[order[k]]);
    everyKth += inCorner(points[19 * k]);
  }
  EXPECT_GE(everyKth, 850u);
  EXPECT_LE(corner, 250u);
}

TEST(CoarseToFineOrder, IsDeterministicForAnyThreadCountWithNonFinitePointsLast) {
  std::vector<Vec3> points = testclouds::uniformCube(30000, 22);
  points[5] = Vec3(std::numeric_limits<double>::infinity(), 0, 0);
  points.push_back(points[7]);  // a repeated point
  std::vector<Index> one, two;
  {
    ThreadLimit limit(1);
    one = coarseToFineOrder(points);
  }
  {
    ThreadLimit limit(2);
    two = coarseToFineOrder(points);
  }
  EXPECT_TRUE(isPermutation(one));
  EXPECT_EQ(one, two);
  EXPECT_EQ(one.back(), 5u);
  EXPECT_TRUE(coarseToFineOrder({}).empty());
  EXPECT_EQ(coarseToFineOrder({Vec3(1, 2, 3)}), std::vector<Index>{0});
  EXPECT_EQ(coarseToFineOrder(std::vector<Vec3>(3, Vec3(1, 1, 1))).size(), 3u);
}
