#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "scalespace/fit/FastExp.hpp"

using namespace scalespace;

TEST(FastExp, MatchesStdExpToRelativeOneInAHundredMillion) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> small(0, 2), large(0, 708);
  double worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = i % 2 ? small(rng) : large(rng);
    const double e = std::exp(-x);
    worst = std::max(worst, std::abs(expNegative(x) - e) / e);
  }
  EXPECT_LT(worst, 1e-8);
}

TEST(FastExp, EdgeCases) {
  EXPECT_EQ(expNegative(0.0), 1.0);
  EXPECT_EQ(expNegative(-3.0), 1.0);   // clamped: the argument is a sum of squares
  EXPECT_EQ(expNegative(708.5), 0.0);  // documented cut: a weight below 1e-307 is no weight
  EXPECT_EQ(expNegative(800.0), 0.0);
  EXPECT_EQ(expNegative(std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(expNegative(std::nan("")), 0.0);
  EXPECT_NEAR(expNegative(1.0), std::exp(-1.0), 1e-9);
  EXPECT_NEAR(expNegative(std::log(2.0) * 10), 1.0 / 1024, 1e-11);
}
