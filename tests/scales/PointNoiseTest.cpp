#include <gtest/gtest.h>

#include <random>

#include "scalespace/scales/PointNoise.hpp"

using namespace scalespace;

// The noise read from every point's 10 neighbours is the sigma of Gaussian noise added to a
// plane (within 15%), and 0 on the clean plane; an empty graph reads 0.
TEST(PointNoise, IsTheSigmaOfANoisyPlaneAndZeroOnACleanOne) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> gauss(0, 0.002);
  std::vector<Vec3> clean, noisy;
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng);
    clean.emplace_back(x, y, 0.0);
    noisy.emplace_back(x, y, gauss(rng));
  }
  EXPECT_NEAR(pointNoiseRms(clean, buildKnnGraph(clean, 10)), 0.0, 1e-12);
  EXPECT_NEAR(pointNoiseRms(noisy, buildKnnGraph(noisy, 10)), 0.002, 0.0003);
  EXPECT_DOUBLE_EQ(pointNoiseRms({}, KnnGraph{}), 0.0);
}
