#pragma once
// Small deterministic point clouds for the core tests (sampled here so that these tests do not
// depend on the analytic-surface module they are used to validate).
#include <cmath>
#include <random>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace::testclouds {

inline std::vector<Vec3> uniformCube(std::size_t n, std::uint64_t seed, double size = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, size);
  std::vector<Vec3> p(n);
  for (Vec3& x : p) x = Vec3(u(rng), u(rng), u(rng));
  return p;
}

/// Uniform on the sphere of radius r centred at c (normalised Gaussian vectors).
inline std::vector<Vec3> sphere(std::size_t n, double r, std::uint64_t seed,
                                const Vec3& c = Vec3::Zero()) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> p(n);
  for (Vec3& x : p) {
    Vec3 d;
    do d = Vec3(g(rng), g(rng), g(rng));
    while (d.norm() < 1e-9);
    x = c + r * d.normalized();
  }
  return p;
}

/// Quasi-uniform (Fibonacci lattice) on the unit sphere: evenly spaced, no clumps.
inline std::vector<Vec3> fibonacciSphere(std::size_t n) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Vec3> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * double(i) + 1.0) / double(n);
    const double r = std::sqrt(1.0 - z * z);
    p[i] = Vec3(r * std::cos(golden * double(i)), r * std::sin(golden * double(i)), z);
  }
  return p;
}

/// Uniform on the plane z = 0 over [0, size]^2.
inline std::vector<Vec3> plane(std::size_t n, double size, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, size);
  std::vector<Vec3> p(n);
  for (Vec3& x : p) x = Vec3(u(rng), u(rng), 0.0);
  return p;
}

/// Uniform on the lateral surface of the cylinder x^2 + y^2 = r^2, z in [0, h].
inline std::vector<Vec3> cylinder(std::size_t n, double r, double h, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), z(0.0, h);
  std::vector<Vec3> p(n);
  for (Vec3& x : p) {
    const double a = angle(rng);
    x = Vec3(r * std::cos(a), r * std::sin(a), z(rng));
  }
  return p;
}

inline double angleDegrees(const Vec3& a, const Vec3& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::min(1.0, c)) * 180.0 / M_PI;  // up to sign
}

}  // namespace scalespace::testclouds
