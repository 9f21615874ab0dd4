#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scales/ScalesTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {
namespace {

TEST(ScaleSeries, LogIsGeometricWithCorrectedEq140) {
  const double tMin = 0.01, tMax = 10;
  const int M = 7;
  const auto t = scaleSeries(tMin, tMax, M, ScaleSpacing::Log);
  ASSERT_EQ(t.size(), 7u);
  EXPECT_EQ(t.front(), tMin);
  EXPECT_EQ(t.back(), tMax);
  const double ratio = std::pow(tMax / tMin, 1.0 / (M - 1));
  for (int j = 1; j <= M; ++j) {
    // Corrected Eq. 1.40 with 1-based j.
    EXPECT_NEAR(t[j - 1], tMin * std::pow(tMax / tMin, double(j - 1) / (M - 1)), 1e-12 * tMax);
    if (j > 1) {
      EXPECT_NEAR(t[j - 1] / t[j - 2], ratio, 1e-12);
    }
  }
  // Not the misprinted exponent (j-1)/M, which would never reach tMax.
  EXPECT_GT(t.back(), tMin * std::pow(tMax / tMin, double(M - 1) / M) * 1.5);
}

TEST(ScaleSeries, LinearHasConstantDifference) {
  const auto t = scaleSeries(1, 5, 5, ScaleSpacing::Linear);
  ASSERT_EQ(t.size(), 5u);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(t[j], 1.0 + j, 1e-12);
}

TEST(ScaleSeries, MonotoneForManyScales) {
  for (auto spacing : {ScaleSpacing::Log, ScaleSpacing::Linear}) {
    const auto t = scaleSeries(0.003, 42, 50, spacing);
    EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
    EXPECT_EQ(std::adjacent_find(t.begin(), t.end()), t.end());
  }
  EXPECT_EQ(scaleSeries(2, 2, 1, ScaleSpacing::Log), std::vector<double>{2});
}

TEST(ScaleSeries, RejectsInvalidOptions) {
  EXPECT_THROW(scaleSeries(1, 2, 0, ScaleSpacing::Log), OptionError);
  EXPECT_THROW(scaleSeries(1, 2, kMaxScaleCount + 1, ScaleSpacing::Log), OptionError);
  EXPECT_EQ(scaleSeries(1, 2, kMaxScaleCount, ScaleSpacing::Log).size(),
            std::size_t(kMaxScaleCount));
  EXPECT_THROW(scaleSeries(0, 2, 5, ScaleSpacing::Log), OptionError);
  EXPECT_THROW(scaleSeries(-1, 2, 5, ScaleSpacing::Linear), OptionError);
  EXPECT_THROW(scaleSeries(3, 2, 5, ScaleSpacing::Log), OptionError);
  EXPECT_THROW(scaleSeries(2, 2, 5, ScaleSpacing::Log), OptionError);
  EXPECT_THROW(scaleSeries(1, std::nan(""), 5, ScaleSpacing::Log), OptionError);
  EXPECT_THROW(parseScaleSpacing("geometric"), OptionError);
  EXPECT_EQ(parseScaleSpacing("linear"), ScaleSpacing::Linear);
}

TEST(ScaleSeries, AutomaticEndpointsMatchBruteForce) {
  const auto p = test::randomCube(500, 3);
  BruteForceIndex brute(p);
  ScaleSeriesOptions o;
  o.count = 10;
  const auto r = makeScaleSeries(p, o, &brute);
  // t_min: median over points of the distance to the 10-th neighbour (self excluded).
  std::vector<double> d;
  for (const Vec3& q : p) {
    std::vector<double> all;
    for (const Vec3& x : p) all.push_back((x - q).norm());
    std::sort(all.begin(), all.end());
    d.push_back(all[10]);
  }
  std::sort(d.begin(), d.end());
  EXPECT_DOUBLE_EQ(r.tMin, d[(d.size() - 1) / 2]);
  Vec3 lo = p[0], hi = p[0];
  for (const Vec3& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  EXPECT_DOUBLE_EQ(r.tMax, (hi - lo).norm());
  EXPECT_TRUE(r.tMinAuto && r.tMaxAuto);
  EXPECT_EQ(r.scales.size(), 10u);
  // Per-point (adaptive) radii agree with the brute force too, and the default kd-tree path.
  const auto radii = knnRadii(p, brute, 10);
  EXPECT_EQ(makeScaleSeries(p, o).tMin, r.tMin);
  EXPECT_EQ(*std::max_element(radii.begin(), radii.end()), d.back());
}

TEST(ScaleSeries, TooFewPointsForAutomaticTMin) {
  const auto p = test::randomCube(5, 1);
  EXPECT_THROW(makeScaleSeries(p, {}), OptionError);
  ScaleSeriesOptions o;
  o.tMin = 0.01;
  EXPECT_NO_THROW(makeScaleSeries(p, o));
}

}  // namespace
}  // namespace scalespace
