#pragma once
// Small synthetic clouds for the scales tests.
#include <cmath>
#include <random>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::test {

inline std::vector<Vec3> randomCube(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(u(rng), u(rng), u(rng));
  return p;
}

/// Gaussian clusters of very different spreads: dense and sparse regions.
inline std::vector<Vec3> clusteredCloud(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, 1);
  const Vec3 centres[3] = {Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 4, 1)};
  const double spread[3] = {0.02, 0.3, 1.0};
  std::vector<Vec3> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = i % 3;
    p[i] = centres[c] + spread[c] * Vec3(g(rng), g(rng), g(rng));
  }
  return p;
}

/// Fibonacci sphere of radius r with outward normals.
inline PointCloud sphereCloud(std::size_t n, double r) {
  std::vector<Vec3> p(n), nn(n);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1 - 2 * (double(i) + 0.5) / double(n);
    const double rad = std::sqrt(1 - z * z);
    const double phi = golden * double(i);
    nn[i] = Vec3(rad * std::cos(phi), rad * std::sin(phi), z);
    p[i] = r * nn[i];
  }
  PointCloud cloud;
  cloud.setAbsolutePositions(p);
  cloud.setNormals(nn);
  return cloud;
}

/// Jittered grid on z = 0 over [0, side]^2 with Gaussian height noise sigma, normals +z.
inline PointCloud noisyPlane(std::size_t perSide, double side, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, sigma);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  std::vector<Vec3> p, nn;
  const double h = side / double(perSide);
  for (std::size_t a = 0; a < perSide; ++a)
    for (std::size_t b = 0; b < perSide; ++b) {
      p.emplace_back((double(a) + 0.5 + u(rng)) * h, (double(b) + 0.5 + u(rng)) * h, g(rng));
      nn.emplace_back(0, 0, 1);
    }
  PointCloud cloud;
  cloud.setAbsolutePositions(p);
  cloud.setNormals(nn);
  return cloud;
}

}  // namespace scalespace::test
