// gatherWithin: the neighbours within t of y, as columns, equal a brute-force scan on every path,
// for every candidate count (whole and partial groups of eight).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scalespace/fit/NeighborColumns.hpp"

using namespace scalespace;

namespace {

SampleColumns randomSamples(std::size_t count, const Vec3& y, double t, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  SampleColumns s;
  for (std::size_t k = 0; k < count; ++k) {
    Vec3 p = y + t * Vec3(u(rng), u(rng), u(rng));  // about a third within t
    if (k == 3) p = y + Vec3(t, 0, 0);              // on the sphere: |p - y|^2 = t^2, left out
    if (k == 11) p = Vec3(NAN, 0, 0);               // never within
    if (k == 17) p = y;                             // the point itself: weight 1
    const Vec3 n = Vec3(u(rng), u(rng), 1).normalized();
    s.px.push_back(p.x()), s.py.push_back(p.y()), s.pz.push_back(p.z());
    s.nx.push_back(n.x()), s.ny.push_back(n.y()), s.nz.push_back(n.z());
  }
  return s;
}

void expectBruteForce(SimdKernel kernel) {
  const Vec3 y(0.3, -0.1, 2.0);
  const double t = 0.5;
  for (std::size_t count = 0; count <= 45; ++count) {
    const SampleColumns s = randomSamples(count, y, t, unsigned(count) + 1);
    NeighborColumns out;
    out.push(Vec3::Ones(), Vec3::UnitZ(), 1.0);  // replaced, not appended to
    gatherWithin(s, y, t, out, kernel);
    std::size_t j = 0;
    for (std::size_t k = 0; k < count; ++k) {
      const Vec3 q(s.px[k] - y.x(), s.py[k] - y.y(), s.pz[k] - y.z());
      if (!(q.squaredNorm() < t * t)) continue;
      ASSERT_LT(j, out.size()) << count;
      EXPECT_EQ(out.qx[j], q.x());
      EXPECT_EQ(out.qy[j], q.y());
      EXPECT_EQ(out.qz[j], q.z());
      EXPECT_EQ(out.nx[j], s.nx[k]);
      EXPECT_EQ(out.ny[j], s.ny[k]);
      EXPECT_EQ(out.nz[j], s.nz[k]);
      EXPECT_NEAR(out.d2[j], q.squaredNorm(), 1e-15);
      const double r = q.squaredNorm() / (t * t);
      EXPECT_NEAR(out.weight[j], (r - 1) * (r - 1), 1e-14);
      ++j;
    }
    EXPECT_EQ(out.size(), j) << count;
    for (const auto* column :
         {&out.qx, &out.qy, &out.qz, &out.nx, &out.ny, &out.nz, &out.d2, &out.weight})
      EXPECT_GE(column->size(), j);
  }
}

}  // namespace

TEST(NeighborColumns, PortableGatherEqualsBruteForce) { expectBruteForce(SimdKernel::Portable); }

TEST(NeighborColumns, Avx512GatherEqualsBruteForce) {
  expectBruteForce(SimdKernel::Avx512);
  if (!avx512Available()) GTEST_SKIP() << "no AVX-512 on this CPU: the portable gather ran";
}

TEST(NeighborColumns, DefaultGatherEqualsBruteForce) { expectBruteForce(SimdKernel::Auto); }
