#pragma once
// The inner kernel of OrientedSphereFit's derivative pass (W2, W3 and the scale derivatives):
// with, per sample k, its item I_k = (1, q, n, q.n, |q|^2) and its weight factors
// F_k = (w, grad_x w, a, b qq^T, dw/dt) (fit/OrientedSphereFit.hpp), every sum the fit needs is
// an entry of the 9 x 12 block sum_k I_k F_k^T. It is the hottest loop of the scale stack.

namespace scalespace {

/// Rows of up to kSize samples, row-major.
struct alignas(32) DerivativeChunk {
  static constexpr int kSize = 32;
  double factors[kSize][12];  // first, so that the 96-byte rows stay 32-byte aligned
  double items[kSize][9];
};
using DerivativeSums = double[9][12];

enum class SumsKernel {
  Auto,      // the fastest one this CPU runs (what the fits use)
  Portable,  // plain C++ (any CPU)
  Avx2Fma    // 4-wide fused multiply-adds (x86-64 with AVX2 and FMA)
};

/// True when the CPU (and the compiler) can run SumsKernel::Avx2Fma.
bool avx2FmaKernelAvailable();

/// sums[i][j] += sum_{k < m} chunk.items[k][i] * chunk.factors[k][j]. Avx2Fma rounds each
/// product-sum once (fused), so it differs from Portable in the last bits; Auto always takes the
/// same path on a given machine, so results do not depend on the thread count. Asking for
/// Avx2Fma where it is not available runs Portable.
void accumulateDerivativeSums(const DerivativeChunk& chunk, int m, DerivativeSums& sums,
                              SumsKernel kernel = SumsKernel::Auto);

}  // namespace scalespace
