#pragma once
// The inner kernel of OrientedSphereFit's derivative pass (W2, W3 and the scale derivatives):
// with, per sample k, its item I_k = (1, q, n, q.n, |q|^2) and its weight factors
// F_k = (w, grad_x w, a, b qq^T, dw/dt) (fit/OrientedSphereFit.hpp), every sum the fit needs is
// an entry of the 9 x 12 block sum_k I_k F_k^T. It is the hottest loop of the scale stack.
#include "scalespace/fit/SimdKernel.hpp"

namespace scalespace {

/// Rows of up to kSize samples, row-major.
struct alignas(32) DerivativeChunk {
  static constexpr int kSize = 32;
  double factors[kSize][12];  // first, so that the 96-byte rows stay 32-byte aligned
  double items[kSize][9];
};
using DerivativeSums = double[9][12];

/// sums[i][j] += sum_{k < m} chunk.items[k][i] * chunk.factors[k][j] (fit/SimdKernel.hpp for
/// `kernel`).
void accumulateDerivativeSums(const DerivativeChunk& chunk, int m, DerivativeSums& sums,
                              SimdKernel kernel = SimdKernel::Auto);

}  // namespace scalespace
