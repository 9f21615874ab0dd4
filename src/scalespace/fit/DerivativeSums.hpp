#pragma once
// The inner kernel of OrientedSphereFit's derivative pass (W2, W3 and the scale derivatives):
// with, per sample k, its item I_k = (1, q, n, q.n, |q|^2) and its weight factors
// F_k = (w, grad_x w, a, b qq^T, dw/dt) (fit/OrientedSphereFit.hpp), every sum the fit needs is
// an entry of the 9 x 12 block sum_k I_k F_k^T. It is the hottest loop of the scale stack.
#include <cstddef>

#include "scalespace/core/Types.hpp"
#include "scalespace/fit/NeighborColumns.hpp"
#include "scalespace/fit/SimdKernel.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

/// Up to kSize samples: a row of factors per sample (the kernels load a row at a time) and a
/// column per item (they broadcast one item of one sample at a time).
struct alignas(64) DerivativeChunk {
  static constexpr int kSize = 32;
  double factors[kSize][12];  // first, so that the 96-byte rows stay 32-byte aligned
  double items[9][kSize];
};
using DerivativeSums = double[9][12];

/// sums[i][j] += sum_{k < m} chunk.items[i][k] * chunk.factors[k][j] (fit/SimdKernel.hpp for
/// `kernel`).
void accumulateDerivativeSums(const DerivativeChunk& chunk, int m, DerivativeSums& sums,
                              SimdKernel kernel = SimdKernel::Auto);

/// The whole derivative pass over the samples of `c` with extra weights e[k] (robust factors)
/// around the evaluation point x: sample k is p = (qx, qy, qz)[k] with normal (nx, ny, nz)[k]
/// (the columns' d2 and weight are not read). Forms each sample's item and factors (q = p - x,
/// w = (r - 1)^2 e with r = |q|^2 / t^2, Eq. 1.6, and its derivatives, OrientedSphereFit::add)
/// and adds I F^T to `sums`. Samples with r >= 1 or no positive weight add nothing. Returns how
/// many samples have a positive weight. The AVX-512 version forms eight samples at a time and
/// transposes their factors into rows; the others form one at a time.
int addDerivativeColumns(const NeighborColumns& c, const double* e, const Vec3& x,
                         const WeightKernel& weight, DerivativeSums& sums,
                         SimdKernel kernel = SimdKernel::Auto);

}  // namespace scalespace
