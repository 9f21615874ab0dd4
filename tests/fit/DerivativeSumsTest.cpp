// The derivative-pass kernel: both implementations equal a long-double reference for every
// chunk length.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scalespace/fit/DerivativeSums.hpp"

using namespace scalespace;

namespace {

void fillRandom(DerivativeChunk& c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < DerivativeChunk::kSize; ++k) {
    for (double& v : c.items[k]) v = u(rng);
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
          ref += (long double)c.items[k][i] * c.factors[k][j];
          mag += std::abs((long double)c.items[k][i] * c.factors[k][j]);
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
