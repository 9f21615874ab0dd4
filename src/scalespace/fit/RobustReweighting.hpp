#pragma once
// One RIMLS re-weighting pass of the robust APSS (Oztireli, Guennebaud, Gross 2009; constants in
// fit/LocalFit.cpp): for every neighbour k, its factor against the current sphere s,
//   rho_k = exp(-(r_k / sigma_r)^2 - (|n_k - grad s(q_k)/|grad s(q_k)|| / sigma_n)^2),
//   r_k = s(q_k) / |grad s(q_k)|,
// fused with the accumulation of the next fit's sums (Eq. 1.7-1.9 inputs) with weights
// w_k rho_k, w_k the kernel weight of Eq. 1.6. The robust stack spends most of its time here
// (5 passes per fit), so the neighbours are read as columns and, on CPUs with AVX-512 (AVX2 +
// FMA), eight (four) at a time.
#include <cstddef>
#include <vector>

#include "scalespace/fit/AlgebraicSphere.hpp"
#include "scalespace/fit/NeighborColumns.hpp"
#include "scalespace/fit/SimdKernel.hpp"

namespace scalespace {

/// The 9 sums of a sphere fit: sum w, sum w q, sum w n, sum w q.n, sum w |q|^2, and how many
/// samples had a positive weight.
struct SphereSums {
  double s[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  int used = 0;
};

/// The sums with the kernel weights alone (the first, not yet re-weighted fit), into `out` (from
/// zero). `kernel`: fit/SimdKernel.hpp.
void kernelWeightedSums(const NeighborColumns& c, SphereSums& out,
                        SimdKernel kernel = SimdKernel::Auto);

/// What reweight() computes besides the factors (always all of them).
enum class ReweightOutput {
  All,         // the next fit's sums with their count, and the largest change of a factor
  Sums,        // the sums alone (next.used 0, returns +infinity): a pass with no tolerance
  FactorsOnly  // nothing else (next zero, returns +infinity): the pass redone with derivatives
};

/// Re-weights against `sphere`: writes rho_k to rho (resized), accumulates the sums with weights
/// w_k rho_k into `next` (from zero) and returns max_k |rho_k - previous[k]| (`previous` empty:
/// every previous factor is 1, as for the kernel-only fit), or less as `output` says.
/// invSr2 = 1 / sigma_r^2, invSn2 = 1 / sigma_n^2. A neighbour where the gradient vanishes gets
/// rho = 0. `kernel`: fit/SimdKernel.hpp.
double reweight(const AlgebraicSphere& sphere, double invSr2, double invSn2,
                const NeighborColumns& c, const std::vector<double>& previous,
                std::vector<double>& rho, SphereSums& next, SimdKernel kernel = SimdKernel::Auto,
                ReweightOutput output = ReweightOutput::All);

}  // namespace scalespace
