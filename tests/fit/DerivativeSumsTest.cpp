// The derivative-pass kernels: every implementation equals a long-double reference for every
// chunk length, and the whole pass over samples held as columns (items and factors formed one by
// one or eight at a time) equals the formula of OrientedSphereFit::add for every sample count.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scalespace/fit/DerivativeSums.hpp"

using namespace scalespace;

namespace {

void fillRandom(DerivativeChunk& c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < DerivativeChunk::kSize; ++k) {
    for (int i = 0; i < 9; ++i) c.items[i][k] = u(rng);
    for (double& v : c.factors[k]) v = u(rng);
  }
}

void expectMatchesReference(SimdKernel kernel) {
  DerivativeChunk c;
  fillRandom(c, 11);
  for (int m = 0; m <= DerivativeChunk::kSize; ++m) {
    DerivativeSums sums;
    for (auto& row : sums)
      for (double& v : row) v = 0.5;  // accumulates onto what is there
    accumulateDerivativeSums(c, m, sums, kernel);
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 12; ++j) {
        long double ref = 0.5L, mag = 0.5L;
        for (int k = 0; k < m; ++k) {
          ref += (long double)c.items[i][k] * c.factors[k][j];
          mag += std::abs((long double)c.items[i][k] * c.factors[k][j]);
        }
        EXPECT_NEAR(sums[i][j], (double)ref, 1e-15 * (double)mag * (m + 1))
            << "m " << m << " i " << i << " j " << j;
      }
  }
}

}  // namespace

TEST(DerivativeSums, PortableKernelMatchesReference) {
  expectMatchesReference(SimdKernel::Portable);
}

TEST(DerivativeSums, Avx2KernelMatchesReference) {
  // Where the CPU has no AVX2, asking for it runs the portable kernel (still checked).
  expectMatchesReference(SimdKernel::Avx2Fma);
  if (!avx2FmaAvailable()) GTEST_SKIP() << "no AVX2 + FMA on this CPU: portable kernel ran";
}

TEST(DerivativeSums, Avx512KernelMatchesReference) {
  expectMatchesReference(SimdKernel::Avx512);
  if (!avx512Available()) GTEST_SKIP() << "no AVX-512 on this CPU: another kernel ran";
}

TEST(DerivativeSums, AutoIsTheWidestAvailableBitForBit) {
  DerivativeChunk c;
  fillRandom(c, 5);
  DerivativeSums a = {}, b = {};
  accumulateDerivativeSums(c, 29, a, SimdKernel::Auto);
  accumulateDerivativeSums(c, 29, b,
                           avx512Available()    ? SimdKernel::Avx512
                           : avx2FmaAvailable() ? SimdKernel::Avx2Fma
                                                : SimdKernel::Portable);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 12; ++j) EXPECT_EQ(a[i][j], b[i][j]);
}

namespace {

/// The formula of OrientedSphereFit::add, in long double: sums[i][j] of item i times factor j.
void referenceSamples(const std::vector<Vec3>& p, const std::vector<Vec3>& n,
                      const std::vector<double>& e, std::size_t count, const Vec3& x,
                      const WeightKernel& kernel, long double (&ref)[9][12],
                      long double (&mag)[9][12], int& used) {
  for (auto& row : ref)
    for (auto& v : row) v = 0;
  for (auto& row : mag)
    for (auto& v : row) v = 0;
  used = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const Vec3 q = p[k] - x;
    const long double d2 =
        (long double)q.x() * q.x() + (long double)q.y() * q.y() + (long double)q.z() * q.z();
    const long double r = d2 * kernel.invT2, rm1 = r - 1, w = rm1 * rm1 * e[k];
    if (!(r < 1) || !(w > 0)) continue;
    ++used;
    const long double b = 8.0L * kernel.invT2 * kernel.invT2 * e[k];
    const long double g = -4.0L * rm1 * kernel.invT2 * e[k];
    const long double item[9] = {
        1, q.x(), q.y(), q.z(), n[k].x(), n[k].y(), n[k].z(), (long double)q.dot(n[k]), d2};
    const long double f[12] = {w,
                               g * q.x(),
                               g * q.y(),
                               g * q.z(),
                               -g,
                               b * q.x() * q.x(),
                               b * q.y() * q.y(),
                               b * q.z() * q.z(),
                               b * q.x() * q.y(),
                               b * q.x() * q.z(),
                               b * q.y() * q.z(),
                               -4.0L * rm1 * r / kernel.t * e[k]};
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 12; ++j) {
        ref[i][j] += item[i] * f[j];
        mag[i][j] += std::abs(item[i] * f[j]);
      }
  }
}

/// The pass over samples held as columns (addDerivativeColumns) against the reference, for every
/// sample count (whole and partial groups of eight, chunks of 32 and a tail).
void expectColumnsMatchReference(SimdKernel kernel) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1, 1);
  const WeightKernel weight(0.7);
  const Vec3 x(0.1, -0.2, 0.05);
  std::vector<Vec3> p, n;
  std::vector<double> e;
  for (int k = 0; k < 75; ++k) {
    p.push_back(x + Vec3(u(rng), u(rng), 0.3 * u(rng)));  // some beyond the support t = 0.7
    n.push_back(Vec3(0.2 * u(rng), 0.2 * u(rng), 1).normalized());
    e.push_back(k % 9 == 4 ? 0.0 : 0.5 + 0.5 * u(rng));  // some robust factors 0
  }
  p[20] = Vec3(NAN, 0, 0);  // skipped, as by add()
  for (std::size_t count = 0; count <= p.size(); ++count) {
    DerivativeSums sums = {};
    NeighborColumns c;
    for (std::size_t k = 0; k < count; ++k) c.push(p[k], n[k], -1.0);  // d2, weight unread
    const int used = addDerivativeColumns(c, e.data(), x, weight, sums, kernel);
    long double ref[9][12], mag[9][12];
    int refUsed = 0;
    referenceSamples(p, n, e, count, x, weight, ref, mag, refUsed);
    EXPECT_EQ(used, refUsed) << count;
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 12; ++j)
        ASSERT_NEAR(sums[i][j], (double)ref[i][j], 1e-14 * (double)mag[i][j] + 1e-300)
            << "count " << count << " i " << i << " j " << j;
  }
}

}  // namespace

TEST(DerivativeSums, PortableColumnPassMatchesTheFormula) {
  expectColumnsMatchReference(SimdKernel::Portable);
}

TEST(DerivativeSums, Avx512ColumnPassMatchesTheFormula) {
  expectColumnsMatchReference(SimdKernel::Avx512);
  if (!avx512Available()) GTEST_SKIP() << "no AVX-512 on this CPU: another kernel ran";
}

TEST(DerivativeSums, DefaultColumnPassMatchesTheFormula) {
  expectColumnsMatchReference(SimdKernel::Auto);
}
