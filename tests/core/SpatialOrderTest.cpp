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
