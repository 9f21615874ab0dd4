#include "scalespace/fit/RobustReweighting.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "scalespace/fit/Avx512Sums.hpp"
#include "scalespace/fit/FastExp.hpp"
#include "scalespace/fit/SimdIntrinsics.hpp"

namespace scalespace {

namespace {

inline void addSample(SphereSums& out, const NeighborColumns& c, std::size_t k, double w) {
  out.s[0] += w;
  out.s[1] += w * c.qx[k], out.s[2] += w * c.qy[k], out.s[3] += w * c.qz[k];
  out.s[4] += w * c.nx[k], out.s[5] += w * c.ny[k], out.s[6] += w * c.nz[k];
  out.s[7] += w * (c.qx[k] * c.nx[k] + c.qy[k] * c.ny[k] + c.qz[k] * c.nz[k]);
  out.s[8] += w * c.d2[k];
  out.used += w > 0 ? 1 : 0;
}

void kernelWeightedSumsPortable(const NeighborColumns& c, SphereSums& out) {
  for (std::size_t k = 0; k < c.size(); ++k) addSample(out, c, k, c.weight[k]);
}

/// The factor of neighbour k (the portable pass).
inline double factorOf(const AlgebraicSphere& s, double invSr2, double invSn2,
                       const NeighborColumns& c, std::size_t k) {
  const Vec3 q(c.qx[k], c.qy[k], c.qz[k]);
  const Vec3 g = s.gradient(q);
  const double gn = g.norm();
  if (!(gn > 0)) return 0;
  const double r = s.value(q) / gn;
  const double dn = (Vec3(c.nx[k], c.ny[k], c.nz[k]) - g / gn).squaredNorm();
  return expNegative(r * r * invSr2 + dn * invSn2);
}

double reweightPortable(const AlgebraicSphere& s, double invSr2, double invSn2,
                        const NeighborColumns& c, const std::vector<double>& previous,
                        std::vector<double>& rho, SphereSums& next) {
  double change = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    rho[k] = factorOf(s, invSr2, invSn2, c, k);
    change = std::max(change, std::abs(rho[k] - (previous.empty() ? 1.0 : previous[k])));
    addSample(next, c, k, c.weight[k] * rho[k]);
  }
  return change;
}

#ifdef SCALESPACE_HAVE_AVX2_TARGET
SCALESPACE_TARGET_AVX2 inline __m256d splat(double v) { return _mm256_set1_pd(v); }

/// expNegative (fit/FastExp.hpp) on four lanes: the same reduction and polynomial; the scaling by
/// 2^-n goes through the exponent bits for every lane (FastExp uses ldexp for n > 1000, where
/// exp(-x) < 1e-301: a weight that small is 0 for any purpose). x >= 708 and NaN give 0.
SCALESPACE_TARGET_AVX2 inline __m256d expNegative4(__m256d x) {
  using namespace fastexp;
  const __m256d valid = _mm256_cmp_pd(x, splat(kMaxArgument), _CMP_LT_OQ);  // false for NaN
  x = _mm256_max_pd(_mm256_min_pd(x, splat(kMaxArgument)), _mm256_setzero_pd());
  const __m256d n = _mm256_floor_pd(_mm256_fmadd_pd(x, splat(kInvLn2), splat(0.5)));
  const __m256d y = _mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(n, splat(kLn2Hi)), x),
                                  _mm256_mul_pd(n, splat(kLn2Lo)));
  const __m256d y2 = _mm256_mul_pd(y, y);
  const __m256d a = _mm256_add_pd(_mm256_add_pd(splat(1.0), y),
                                  _mm256_mul_pd(y2, _mm256_fmadd_pd(y, splat(kC3), splat(kC2))));
  const __m256d b = _mm256_add_pd(_mm256_fmadd_pd(y, splat(kC5), splat(kC4)),
                                  _mm256_mul_pd(y2, _mm256_fmadd_pd(y, splat(kC7), splat(kC6))));
  const __m256d p = _mm256_fmadd_pd(_mm256_mul_pd(y2, y2), b, a);
  // 2^-n: the biased exponent 1023 - n (an integer-valued double in [1, 1023]) read as an
  // integer by adding 2^52, then shifted into the exponent field.
  const __m256d biased = _mm256_add_pd(_mm256_sub_pd(splat(1023.0), n), splat(4503599627370496.0));
  const __m256i e = _mm256_slli_epi64(
      _mm256_sub_epi64(_mm256_castpd_si256(biased), _mm256_set1_epi64x(0x4330000000000000LL)), 52);
  return _mm256_and_pd(_mm256_mul_pd(p, _mm256_castsi256_pd(e)), valid);
}

SCALESPACE_TARGET_AVX2 double reweightAvx2(const AlgebraicSphere& s, double invSr2, double invSn2,
                                           const NeighborColumns& c,
                                           const std::vector<double>& previous,
                                           std::vector<double>& rho, SphereSums& next) {
  const __m256d uc = _mm256_set1_pd(s.uc), uq = _mm256_set1_pd(s.uq);
  const __m256d two_uq = _mm256_set1_pd(2 * s.uq);
  const __m256d ulx = _mm256_set1_pd(s.ul.x()), uly = _mm256_set1_pd(s.ul.y()),
                ulz = _mm256_set1_pd(s.ul.z());
  const __m256d sr = _mm256_set1_pd(invSr2), sn = _mm256_set1_pd(invSn2);
  const __m256d signMask = _mm256_set1_pd(-0.0);
  __m256d acc[9];
  SCALESPACE_UNROLLED_ZERO
  for (__m256d& v : acc) v = _mm256_setzero_pd();
  __m256d change = _mm256_setzero_pd();
  __m256i used = _mm256_setzero_si256();
  const std::size_t n = c.size();
  // The last group of 1-3 neighbours runs masked: lanes past n load zeros, get the factor 0 (so
  // a zero weight, counted nowhere) and store nothing. A scalar tail was a large share of the pass.
  const __m256i lanes = _mm256_set_epi64x(3, 2, 1, 0);
  for (std::size_t k = 0; k < n; k += 4) {
    const __m256i mask = _mm256_cmpgt_epi64(_mm256_set1_epi64x(std::int64_t(n - k)), lanes);
    const __m256d live = _mm256_castsi256_pd(mask);
    const __m256d qx = _mm256_maskload_pd(&c.qx[k], mask), qy = _mm256_maskload_pd(&c.qy[k], mask),
                  qz = _mm256_maskload_pd(&c.qz[k], mask);
    const __m256d nx = _mm256_maskload_pd(&c.nx[k], mask), ny = _mm256_maskload_pd(&c.ny[k], mask),
                  nz = _mm256_maskload_pd(&c.nz[k], mask);
    const __m256d d2 = _mm256_maskload_pd(&c.d2[k], mask);
    const __m256d gx = _mm256_fmadd_pd(two_uq, qx, ulx), gy = _mm256_fmadd_pd(two_uq, qy, uly),
                  gz = _mm256_fmadd_pd(two_uq, qz, ulz);
    const __m256d gn =
        _mm256_sqrt_pd(_mm256_fmadd_pd(gx, gx, _mm256_fmadd_pd(gy, gy, _mm256_mul_pd(gz, gz))));
    const __m256d inv = _mm256_div_pd(_mm256_set1_pd(1.0), gn);  // inf where gn = 0: rho 0
    const __m256d f = _mm256_fmadd_pd(
        uq, d2, _mm256_fmadd_pd(ulx, qx, _mm256_fmadd_pd(uly, qy, _mm256_fmadd_pd(ulz, qz, uc))));
    const __m256d r = _mm256_mul_pd(f, inv);
    const __m256d dx = _mm256_fnmadd_pd(gx, inv, nx), dy = _mm256_fnmadd_pd(gy, inv, ny),
                  dz = _mm256_fnmadd_pd(gz, inv, nz);
    const __m256d dn = _mm256_fmadd_pd(dx, dx, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dz, dz)));
    const __m256d rh = _mm256_and_pd(
        expNegative4(_mm256_fmadd_pd(_mm256_mul_pd(r, r), sr, _mm256_mul_pd(dn, sn))), live);
    _mm256_maskstore_pd(&rho[k], mask, rh);
    change = _mm256_max_pd(
        change, _mm256_andnot_pd(
                    signMask,
                    _mm256_sub_pd(rh, previous.empty() ? _mm256_and_pd(_mm256_set1_pd(1.0), live)
                                                       : _mm256_maskload_pd(&previous[k], mask))));
    const __m256d w = _mm256_mul_pd(_mm256_maskload_pd(&c.weight[k], mask), rh);
    used = _mm256_sub_epi64(used,
                            _mm256_castpd_si256(_mm256_cmp_pd(w, _mm256_setzero_pd(), _CMP_GT_OQ)));
    acc[0] = _mm256_add_pd(acc[0], w);
    acc[1] = _mm256_fmadd_pd(w, qx, acc[1]);
    acc[2] = _mm256_fmadd_pd(w, qy, acc[2]);
    acc[3] = _mm256_fmadd_pd(w, qz, acc[3]);
    acc[4] = _mm256_fmadd_pd(w, nx, acc[4]);
    acc[5] = _mm256_fmadd_pd(w, ny, acc[5]);
    acc[6] = _mm256_fmadd_pd(w, nz, acc[6]);
    acc[7] = _mm256_fmadd_pd(
        w, _mm256_fmadd_pd(qx, nx, _mm256_fmadd_pd(qy, ny, _mm256_mul_pd(qz, nz))), acc[7]);
    acc[8] = _mm256_fmadd_pd(w, d2, acc[8]);
  }
  alignas(32) double lane[4];
  for (int i = 0; i < 9; ++i) {
    _mm256_store_pd(lane, acc[i]);
    next.s[i] += (lane[0] + lane[1]) + (lane[2] + lane[3]);
  }
  _mm256_store_pd(lane, change);
  double maxChange = std::max(std::max(lane[0], lane[1]), std::max(lane[2], lane[3]));
  alignas(32) long long counts[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(counts), used);
  next.used += int(counts[0] + counts[1] + counts[2] + counts[3]);
  return maxChange;
}

/// The pass of reweightAvx2 on eight lanes (AVX-512), much faster than reweightAvx2, whose body
/// (~120 instructions for 4 neighbours, accumulators spilled: 16 registers) is latency-bound;
/// here 32 registers hold everything and the last group's mask is a mask register.
/// kSums: accumulate the next fit's sums; kTrack: count the samples of positive weight and
/// measure the largest change (ReweightOutput; each is a few instructions of ~70 per group).
template <bool kSums, bool kTrack>
SCALESPACE_TARGET_AVX512 double reweightAvx512(const AlgebraicSphere& s, double invSr2,
                                               double invSn2, const NeighborColumns& c,
                                               const std::vector<double>& previous,
                                               std::vector<double>& rho, SphereSums& next) {
  const Spheres8 sphere{splat8(s.uc), splat8(s.uq), splat8(s.ul.x()), splat8(s.ul.y()),
                        splat8(s.ul.z())};
  const __m512d twoUq = splat8(2 * s.uq);
  const __m512d sr = splat8(invSr2), sn = splat8(invSn2);
  __m512d acc[9];
  SCALESPACE_UNROLLED_ZERO
  for (__m512d& v : acc) v = _mm512_setzero_pd();
  __m512d change = _mm512_setzero_pd();
  int used = 0;
  const std::size_t n = c.size();
  // Raw pointers: the stores to rho could alias the columns' vectors, whose data pointers the
  // compiler would otherwise reload at every group.
  const double *qxs = c.qx.data(), *qys = c.qy.data(), *qzs = c.qz.data();
  const double *nxs = c.nx.data(), *nys = c.ny.data(), *nzs = c.nz.data();
  const double *d2s = c.d2.data(), *ws = c.weight.data(), *prev = previous.data();
  // No previous factors: all 1 (the lanes that exist), the others 0 as the factors there.
  const bool ones = previous.empty();
  double* out = rho.data();
  for (std::size_t k = 0; k < n; k += 8) {
    const __mmask8 m = n - k >= 8 ? __mmask8(0xff) : __mmask8((1u << (n - k)) - 1);
    const __m512d qx = _mm512_maskz_loadu_pd(m, qxs + k), qy = _mm512_maskz_loadu_pd(m, qys + k),
                  qz = _mm512_maskz_loadu_pd(m, qzs + k);
    const __m512d nx = _mm512_maskz_loadu_pd(m, nxs + k), ny = _mm512_maskz_loadu_pd(m, nys + k),
                  nz = _mm512_maskz_loadu_pd(m, nzs + k);
    const __m512d d2 = _mm512_maskz_loadu_pd(m, d2s + k);
    const __m512d rh =
        _mm512_maskz_mov_pd(m, factors8(sphere, twoUq, qx, qy, qz, nx, ny, nz, d2, sr, sn));
    _mm512_mask_storeu_pd(out + k, m, rh);
    if (kTrack)
      change = _mm512_max_pd(
          change, _mm512_abs_pd(_mm512_sub_pd(
                      rh, _mm512_mask_loadu_pd(_mm512_maskz_mov_pd(ones ? m : 0, splat8(1.0)),
                                               ones ? 0 : m, prev + k))));
    if (kSums) {
      const __m512d w = _mm512_mul_pd(_mm512_maskz_loadu_pd(m, ws + k), rh);
      const int positive = accumulate8(acc, w, qx, qy, qz, nx, ny, nz, d2);
      if (kTrack) used += positive;  // (the count is dropped by the compiler otherwise)
    }
  }
  if (kSums) {
    addReduced8(acc, next.s);
    next.s[8] += _mm512_reduce_add_pd(acc[8]);
  }
  next.used += used;
  return kTrack ? _mm512_reduce_max_pd(change) : std::numeric_limits<double>::infinity();
}

SCALESPACE_TARGET_AVX512 void kernelWeightedSumsAvx512(const NeighborColumns& c, SphereSums& out) {
  __m512d acc[9];
  SCALESPACE_UNROLLED_ZERO
  for (__m512d& v : acc) v = _mm512_setzero_pd();
  int used = 0;
  const std::size_t n = c.size();
  const double *qxs = c.qx.data(), *qys = c.qy.data(), *qzs = c.qz.data();
  const double *nxs = c.nx.data(), *nys = c.ny.data(), *nzs = c.nz.data();
  const double *d2s = c.d2.data(), *ws = c.weight.data();
  for (std::size_t k = 0; k < n; k += 8) {
    const __mmask8 m = n - k >= 8 ? __mmask8(0xff) : __mmask8((1u << (n - k)) - 1);
    const __m512d qx = _mm512_maskz_loadu_pd(m, qxs + k), qy = _mm512_maskz_loadu_pd(m, qys + k),
                  qz = _mm512_maskz_loadu_pd(m, qzs + k);
    const __m512d nx = _mm512_maskz_loadu_pd(m, nxs + k), ny = _mm512_maskz_loadu_pd(m, nys + k),
                  nz = _mm512_maskz_loadu_pd(m, nzs + k);
    const __m512d w = _mm512_maskz_loadu_pd(m, ws + k);
    used += accumulate8(acc, w, qx, qy, qz, nx, ny, nz, _mm512_maskz_loadu_pd(m, d2s + k));
  }
  addReduced8(acc, out.s);
  out.s[8] += _mm512_reduce_add_pd(acc[8]);
  out.used += used;
}
#endif

}  // namespace

void kernelWeightedSums(const NeighborColumns& c, SphereSums& out, SimdKernel kernel) {
  out = SphereSums{};
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel)) return kernelWeightedSumsAvx512(c, out);
#endif
  (void)kernel;
  kernelWeightedSumsPortable(c, out);
}

double reweight(const AlgebraicSphere& sphere, double invSr2, double invSn2,
                const NeighborColumns& c, const std::vector<double>& previous,
                std::vector<double>& rho, SphereSums& next, SimdKernel kernel,
                ReweightOutput output) {
  rho.resize(c.size());
  next = SphereSums{};
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel)) {
    switch (output) {
      case ReweightOutput::All:
        return reweightAvx512<true, true>(sphere, invSr2, invSn2, c, previous, rho, next);
      case ReweightOutput::Sums:
        return reweightAvx512<true, false>(sphere, invSr2, invSn2, c, previous, rho, next);
      case ReweightOutput::FactorsOnly:
        return reweightAvx512<false, false>(sphere, invSr2, invSn2, c, previous, rho, next);
    }
  }
#endif
  // The other paths compute everything and drop what was not asked for.
  double change = 0;
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx2Fma(kernel))
    change = reweightAvx2(sphere, invSr2, invSn2, c, previous, rho, next);
  else
#endif
    change = reweightPortable(sphere, invSr2, invSn2, c, previous, rho, next);
  (void)kernel;
  if (output == ReweightOutput::All) return change;
  next.used = 0;
  if (output == ReweightOutput::FactorsOnly) next = SphereSums{};
  return std::numeric_limits<double>::infinity();
}

}  // namespace scalespace
