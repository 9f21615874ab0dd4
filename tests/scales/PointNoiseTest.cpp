#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
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

namespace {

// n points drawn uniformly on a sphere of radius 1 (as a mesh's area samples; mean spacing
// about sqrt(4 pi / n)), moved along the normal by Gaussian noise of the given sigma.
std::vector<Vec3> noisySphere(int n, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    points.push_back(p * (1 + sigma * gauss(rng)));
  }
  return points;
}

double sphereNoise(const std::vector<Vec3>& points, const SurfaceNoiseOptions& options = {}) {
  return surfaceNoiseRms(points, *makeSpatialIndex(points), options);
}

}  // namespace

// The quadric reads a curved surface's noise where the plane reads its curvature: on a clean
// sphere of 20,000 points (spacing e = 0.025) it reads under a tenth of the plane's 10
// neighbours, and it reads sigma within 10% from 0.1 e to 0.4 e, where the plane of 10 neighbours
// reads 0.4 e low by a quarter.
TEST(SurfaceNoise, ReadsASpheresNoiseWithoutItsCurvature) {
  const int n = 20000;
  const double e = std::sqrt(4 * M_PI / n);
  const std::vector<Vec3> clean = noisySphere(n, 0, 1);
  const double planeClean = pointNoiseRms(clean, buildKnnGraph(clean, 10));
  EXPECT_GT(planeClean, 1e-5);
  EXPECT_LT(sphereNoise(clean), 0.1 * planeClean);
  for (const double sigma : {0.1, 0.2, 0.4}) {
    const std::vector<Vec3> noisy = noisySphere(n, sigma * e, 2);
    EXPECT_NEAR(sphereNoise(noisy) / e, sigma, 0.1 * sigma) << sigma;
  }
}

// Reading a sample of the points gives the median of all within 2%; the result does not depend
// on the thread count (the sample is fixed by the input order).
TEST(SurfaceNoise, ASampleReadsTheSameAsAll) {
  const std::vector<Vec3> noisy = noisySphere(20000, 0.004, 4);
  SurfaceNoiseOptions all;
  all.maxSamples = noisy.size();
  SurfaceNoiseOptions few;
  few.maxSamples = 2000;
  EXPECT_NEAR(sphereNoise(noisy, few), sphereNoise(noisy, all), 0.02 * sphereNoise(noisy, all));
  double oneThread = 0;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    oneThread = sphereNoise(noisy, few);
  }
  EXPECT_EQ(sphereNoise(noisy, few), oneThread);
}

// Too few points, a line and a single repeated position have no quadric: they read 0, no NaN.
TEST(SurfaceNoise, DegenerateCloudsReadZero) {
  EXPECT_EQ(sphereNoise({}), 0.0);
  EXPECT_EQ(sphereNoise(std::vector<Vec3>(5, Vec3(1, 2, 3))), 0.0);
  EXPECT_EQ(sphereNoise(std::vector<Vec3>(100, Vec3(1, 2, 3))), 0.0);
  std::vector<Vec3> line;
  for (int i = 0; i < 100; ++i) line.emplace_back(0.01 * i, 0, 0);
  EXPECT_EQ(sphereNoise(line), 0.0);
}
