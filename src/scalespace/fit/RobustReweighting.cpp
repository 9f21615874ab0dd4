#include "scalespace/fit/RobustReweighting.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "scalespace/fit/FastExp.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
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

SCALESPACE_TARGET_AVX512 inline __m512d splat8(double v) { return _mm512_set1_pd(v); }

/// expNegative (fit/FastExp.hpp) on eight lanes: the same reduction and polynomial as
/// expNegative4; vscalefpd multiplies by 2^-n. x >= 708 and NaN give 0.
SCALESPACE_TARGET_AVX512 inline __m512d expNegative8(__m512d x) {
  using namespace fastexp;
  const __mmask8 valid = _mm512_cmp_pd_mask(x, splat8(kMaxArgument), _CMP_LT_OQ);
  x = _mm512_max_pd(_mm512_min_pd(x, splat8(kMaxArgument)), _mm512_setzero_pd());
  const __m512d n = _mm512_roundscale_pd(_mm512_fmadd_pd(x, splat8(kInvLn2), splat8(0.5)),
                                         _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m512d y = _mm512_add_pd(_mm512_sub_pd(_mm512_mul_pd(n, splat8(kLn2Hi)), x),
                                  _mm512_mul_pd(n, splat8(kLn2Lo)));
  const __m512d y2 = _mm512_mul_pd(y, y);
  const __m512d a = _mm512_add_pd(_mm512_add_pd(splat8(1.0), y),
                                  _mm512_mul_pd(y2, _mm512_fmadd_pd(y, splat8(kC3), splat8(kC2))));
  const __m512d b = _mm512_add_pd(_mm512_fmadd_pd(y, splat8(kC5), splat8(kC4)),
                                  _mm512_mul_pd(y2, _mm512_fmadd_pd(y, splat8(kC7), splat8(kC6))));
  const __m512d p = _mm512_fmadd_pd(_mm512_mul_pd(y2, y2), b, a);
  return _mm512_maskz_mov_pd(valid, _mm512_scalef_pd(p, _mm512_sub_pd(_mm512_setzero_pd(), n)));
}

/// 1 / sqrt(x) on eight lanes: the 14-bit estimate and two Newton steps y (3 - x y^2) / 2, each
/// squaring the relative error (2^-14 -> 2^-28 -> ~1 ulp). A square root and a division per group
/// were the dearest instructions of the pass on this machine's Zen 5. x = 0 gives NaN (inf
/// times 0), and NaN lanes get the factor 0, as a vanishing gradient must.
SCALESPACE_TARGET_AVX512 inline __m512d inverseSqrt8(__m512d x) {
  const __m512d half = _mm512_mul_pd(x, splat8(0.5)), threeHalves = splat8(1.5);
  __m512d y = _mm512_rsqrt14_pd(x);
  y = _mm512_mul_pd(y, _mm512_fnmadd_pd(half, _mm512_mul_pd(y, y), threeHalves));
  return _mm512_mul_pd(y, _mm512_fnmadd_pd(half, _mm512_mul_pd(y, y), threeHalves));
}

/// out[i] += the sum of the lanes of acc[i], i < 8: _mm512_reduce_add_pd's pairing exactly
/// (halves, then quarters, then the last two lanes), so the sums are the same to the bit, but
/// the eight reductions share their shuffles: 21 instructions instead of 48 per pass.
SCALESPACE_TARGET_AVX512 inline void addReduced8(const __m512d* acc, double* out) {
  // Lanes k + 4 onto k: two accumulators per vector, four lanes each.
  __m512d half[4];
  for (int p = 0; p < 4; ++p)
    half[p] = _mm512_add_pd(_mm512_shuffle_f64x2(acc[2 * p], acc[2 * p + 1], 0x44),
                            _mm512_shuffle_f64x2(acc[2 * p], acc[2 * p + 1], 0xEE));
  // Lanes k + 2 onto k: four accumulators per vector, two lanes each.
  __m512d quarter[2];
  for (int p = 0; p < 2; ++p)
    quarter[p] = _mm512_add_pd(_mm512_shuffle_f64x2(half[2 * p], half[2 * p + 1], 0x88),
                               _mm512_shuffle_f64x2(half[2 * p], half[2 * p + 1], 0xDD));
  // The last two lanes: lane order 0, 4, 1, 5, 2, 6, 3, 7.
  alignas(64) double sums[8];
  _mm512_store_pd(sums, _mm512_add_pd(_mm512_unpacklo_pd(quarter[0], quarter[1]),
                                      _mm512_unpackhi_pd(quarter[0], quarter[1])));
  const int accOf[8] = {0, 4, 1, 5, 2, 6, 3, 7};
  for (int l = 0; l < 8; ++l) out[accOf[l]] += sums[l];
}

/// Adds eight neighbours with weights w to the 9 sums of SphereSums (lanes with w = 0 add
/// nothing) and returns how many have a positive weight.
SCALESPACE_TARGET_AVX512 inline int accumulate8(__m512d* acc, __m512d w, __m512d qx, __m512d qy,
                                                __m512d qz, __m512d nx, __m512d ny, __m512d nz,
                                                __m512d d2) {
  acc[0] = _mm512_add_pd(acc[0], w);
  acc[1] = _mm512_fmadd_pd(w, qx, acc[1]);
  acc[2] = _mm512_fmadd_pd(w, qy, acc[2]);
  acc[3] = _mm512_fmadd_pd(w, qz, acc[3]);
  acc[4] = _mm512_fmadd_pd(w, nx, acc[4]);
  acc[5] = _mm512_fmadd_pd(w, ny, acc[5]);
  acc[6] = _mm512_fmadd_pd(w, nz, acc[6]);
  acc[7] = _mm512_fmadd_pd(
      w, _mm512_fmadd_pd(qx, nx, _mm512_fmadd_pd(qy, ny, _mm512_mul_pd(qz, nz))), acc[7]);
  acc[8] = _mm512_fmadd_pd(w, d2, acc[8]);
  return __builtin_popcount(_mm512_cmp_pd_mask(w, _mm512_setzero_pd(), _CMP_GT_OQ));
}

/// An algebraic sphere per lane (the same one in every lane for a single fit's pass).
struct Spheres8 {
  __m512d uc, uq, ulx, uly, ulz;
};

/// The re-weighting factor (factorOf) of eight neighbours against the lanes' spheres, before any
/// lane mask; twoUq = 2 u_q.
SCALESPACE_TARGET_AVX512 inline __m512d factors8(const Spheres8& s, __m512d twoUq, __m512d qx,
                                                 __m512d qy, __m512d qz, __m512d nx, __m512d ny,
                                                 __m512d nz, __m512d d2, __m512d sr, __m512d sn) {
  const __m512d gx = _mm512_fmadd_pd(twoUq, qx, s.ulx), gy = _mm512_fmadd_pd(twoUq, qy, s.uly),
                gz = _mm512_fmadd_pd(twoUq, qz, s.ulz);
  const __m512d inv =
      inverseSqrt8(_mm512_fmadd_pd(gx, gx, _mm512_fmadd_pd(gy, gy, _mm512_mul_pd(gz, gz))));
  const __m512d f = _mm512_fmadd_pd(
      s.uq, d2,
      _mm512_fmadd_pd(s.ulx, qx, _mm512_fmadd_pd(s.uly, qy, _mm512_fmadd_pd(s.ulz, qz, s.uc))));
  const __m512d r = _mm512_mul_pd(f, inv);
  const __m512d dx = _mm512_fnmadd_pd(gx, inv, nx), dy = _mm512_fnmadd_pd(gy, inv, ny),
                dz = _mm512_fnmadd_pd(gz, inv, nz);
  const __m512d dn = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
  return expNegative8(_mm512_fmadd_pd(_mm512_mul_pd(r, r), sr, _mm512_mul_pd(dn, sn)));
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

/// sphereFromSums on eight lanes (solveSphere<double>'s operations in its order, no fused
/// multiply-adds, so that a lane solves its sums as the scalar code does): the lanes where it
/// would return true. `count`: the lanes' sample counts (as doubles).
SCALESPACE_TARGET_AVX512 inline __mmask8 solve8(const __m512d* s, __m512d count, double t,
                                                int minNeighbors, Spheres8& out) {
  const __m512d zero = _mm512_setzero_pd();
  __mmask8 ok = _mm512_cmp_pd_mask(count, splat8(std::max(minNeighbors, 1)), _CMP_GE_OQ) &
                _mm512_cmp_pd_mask(s[0], zero, _CMP_GT_OQ);
  const __m512d pn =
      _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(s[1], s[4]), _mm512_mul_pd(s[2], s[5])),
                    _mm512_mul_pd(s[3], s[6]));
  const __m512d pp =
      _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(s[1], s[1]), _mm512_mul_pd(s[2], s[2])),
                    _mm512_mul_pd(s[3], s[3]));
  const __m512d num = _mm512_sub_pd(_mm512_mul_pd(s[0], s[7]), pn);
  const __m512d den = _mm512_sub_pd(_mm512_mul_pd(s[0], s[8]), pp);
  const __m512d degenerate =
      _mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(splat8(1e-14), s[0]), s[0]), splat8(t * t));
  ok &= _mm512_cmp_pd_mask(den, degenerate, _CMP_GT_OQ);
  out.uq = _mm512_mul_pd(splat8(0.5), _mm512_div_pd(num, den));
  const __m512d inv = _mm512_div_pd(splat8(1.0), s[0]);
  out.uc = _mm512_mul_pd(
      splat8(-1.0), _mm512_mul_pd(_mm512_add_pd(pn, _mm512_mul_pd(out.uq, _mm512_sub_pd(den, pp))),
                                  _mm512_mul_pd(inv, inv)));
  const __m512d twoUq = splat8(2.0);
  out.ulx =
      _mm512_mul_pd(_mm512_sub_pd(s[4], _mm512_mul_pd(twoUq, _mm512_mul_pd(out.uq, s[1]))), inv);
  out.uly =
      _mm512_mul_pd(_mm512_sub_pd(s[5], _mm512_mul_pd(twoUq, _mm512_mul_pd(out.uq, s[2]))), inv);
  out.ulz =
      _mm512_mul_pd(_mm512_sub_pd(s[6], _mm512_mul_pd(twoUq, _mm512_mul_pd(out.uq, s[3]))), inv);
  // AlgebraicSphere::isValid and a non-zero u_l (sphereFromSums).
  const __m512d ul2 =
      _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(out.ulx, out.ulx), _mm512_mul_pd(out.uly, out.uly)),
                    _mm512_mul_pd(out.ulz, out.ulz));
  const __m512d delta =
      _mm512_sub_pd(ul2, _mm512_mul_pd(_mm512_mul_pd(splat8(4.0), out.uq), out.uc));
  const int nonFinite = 0x01 | 0x08 | 0x10 | 0x80;  // QNaN, +inf, -inf, SNaN
  for (const __m512d v : {out.uc, out.uq, out.ulx, out.uly, out.ulz, delta})
    ok &= __mmask8(~_mm512_fpclass_pd_mask(v, nonFinite));
  ok &= _mm512_cmp_pd_mask(delta, zero, _CMP_GT_OQ) & _mm512_cmp_pd_mask(ul2, zero, _CMP_GT_OQ);
  return ok;
}

/// Lane l's entries of an interleaved buffer, its first n of them, into out (resized).
inline void deinterleave(const double* lanes, int l, std::size_t n, std::vector<double>& out) {
  out.resize(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = lanes[InterleavedColumns::kLanes * k + l];
}

SCALESPACE_TARGET_AVX512 void robustSpheresAvx512(const InterleavedColumns& c, double t, int passes,
                                                  int minNeighbors, double invSr2, double invSn2,
                                                  LaneSphere* out, std::vector<double>* factors,
                                                  std::vector<double>& current,
                                                  std::vector<double>& trial) {
  const std::size_t n = c.length;
  const double *qxs = c.qx.data(), *qys = c.qy.data(), *qzs = c.qz.data();
  const double *nxs = c.nx.data(), *nys = c.ny.data(), *nzs = c.nz.data();
  const double *d2s = c.d2.data(), *ws = c.weight.data();
  const __mmask8 lanes = __mmask8((1u << c.fits) - 1);
  // The kernel-weighted fit.
  __m512d acc[9];
  SCALESPACE_UNROLLED_ZERO
  for (__m512d& v : acc) v = _mm512_setzero_pd();
  __m512d count = _mm512_setzero_pd();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t o = 8 * k;
    const __m512d w = _mm512_loadu_pd(ws + o);
    count = _mm512_add_pd(
        count,
        _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(w, _mm512_setzero_pd(), _CMP_GT_OQ), splat8(1.0)));
    const __m512d qx = _mm512_loadu_pd(qxs + o), qy = _mm512_loadu_pd(qys + o),
                  qz = _mm512_loadu_pd(qzs + o);
    const __m512d nx = _mm512_loadu_pd(nxs + o), ny = _mm512_loadu_pd(nys + o),
                  nz = _mm512_loadu_pd(nzs + o);
    accumulate8(acc, w, qx, qy, qz, nx, ny, nz, _mm512_loadu_pd(d2s + o));
  }
  Spheres8 s;
  __mmask8 active = solve8(acc, count, t, minNeighbors, s) & lanes;
  alignas(64) double counted[8];
  _mm512_store_pd(counted, count);
  for (int l = 0; l < c.fits; ++l) {
    out[l].valid = (active >> l) & 1;
    out[l].neighbors = int(counted[l]);
    factors[l].clear();
  }
  current.resize(8 * n);
  trial.resize(8 * n);
  const __m512d sr = splat8(invSr2), sn = splat8(invSn2);
  const __m512i counts =
      _mm512_cvtepi32_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c.count)));
  // The spheres as kept per lane: a lane whose solve fails keeps its previous one.
  Spheres8 kept = s;
  for (int it = 0; it < passes && active; ++it) {
    const __m512d twoUq = _mm512_add_pd(kept.uq, kept.uq);
    SCALESPACE_UNROLLED_ZERO
    for (__m512d& v : acc) v = _mm512_setzero_pd();
    double* rhoOut = trial.data();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t o = 8 * k;
      const __m512d qx = _mm512_loadu_pd(qxs + o), qy = _mm512_loadu_pd(qys + o),
                    qz = _mm512_loadu_pd(qzs + o);
      const __m512d nx = _mm512_loadu_pd(nxs + o), ny = _mm512_loadu_pd(nys + o),
                    nz = _mm512_loadu_pd(nzs + o);
      const __m512d d2 = _mm512_loadu_pd(d2s + o);
      const __m512d kw = _mm512_loadu_pd(ws + o);
      // Past a fit's count the factor is 0, as in reweight's masked lanes.
      const __mmask8 live = _mm512_cmpgt_epi64_mask(counts, _mm512_set1_epi64(std::int64_t(k)));
      const __m512d rh =
          _mm512_maskz_mov_pd(live, factors8(kept, twoUq, qx, qy, qz, nx, ny, nz, d2, sr, sn));
      _mm512_storeu_pd(rhoOut + o, rh);
      accumulate8(acc, _mm512_mul_pd(kw, rh), qx, qy, qz, nx, ny, nz, d2);
    }
    Spheres8 next;
    // Without the count (no tolerance), s0 > 0 exactly when a sample has weight (robustSphere).
    const __mmask8 solved = solve8(acc, splat8(1.0), t, 1, next) & active;
    // A lane whose solve failed stops with its previous sphere and factors (none before the
    // first re-weighting: every factor 1).
    for (int l = 0; l < c.fits; ++l)
      if (((active & ~solved) >> l) & 1 && it > 0)
        deinterleave(current.data(), l, std::size_t(c.count[l]), factors[l]);
    active = solved;
    kept.uc = _mm512_mask_mov_pd(kept.uc, solved, next.uc);
    kept.uq = _mm512_mask_mov_pd(kept.uq, solved, next.uq);
    kept.ulx = _mm512_mask_mov_pd(kept.ulx, solved, next.ulx);
    kept.uly = _mm512_mask_mov_pd(kept.uly, solved, next.uly);
    kept.ulz = _mm512_mask_mov_pd(kept.ulz, solved, next.ulz);
    std::swap(current, trial);
  }
  // A lane still active has solved every pass: its factors are the last pass's.
  for (int l = 0; l < c.fits; ++l)
    if ((active >> l) & 1 && passes > 0)
      deinterleave(current.data(), l, std::size_t(c.count[l]), factors[l]);
  alignas(64) double uc[8], uq[8], ulx[8], uly[8], ulz[8];
  _mm512_store_pd(uc, kept.uc);
  _mm512_store_pd(uq, kept.uq);
  _mm512_store_pd(ulx, kept.ulx);
  _mm512_store_pd(uly, kept.uly);
  _mm512_store_pd(ulz, kept.ulz);
  for (int l = 0; l < c.fits; ++l) {
    out[l].sphere.uc = uc[l];
    out[l].sphere.uq = uq[l];
    out[l].sphere.ul = Vec3(ulx[l], uly[l], ulz[l]);
  }
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

#ifdef SCALESPACE_HAVE_AVX2_TARGET
namespace {
/// Transposes the 8 x 8 block rows[0..8) (row l: eight values of fit l) into columns: out[j] gets
/// entry j of every row, lane l from row l (three rounds of interleaves).
SCALESPACE_TARGET_AVX512 inline void transpose8(const __m512d* rows, __m512d* out) {
  __m512d a[8], b[8];
  for (int p = 0; p < 4; ++p) {
    a[2 * p] = _mm512_unpacklo_pd(rows[2 * p], rows[2 * p + 1]);
    a[2 * p + 1] = _mm512_unpackhi_pd(rows[2 * p], rows[2 * p + 1]);
  }
  // 128-bit blocks: rows 0-3 with their partners in rows 4-7 below.
  for (int p = 0; p < 2; ++p)
    for (int h = 0; h < 2; ++h) {
      b[4 * p + h] = _mm512_permutex2var_pd(
          a[4 * p + h], _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13), a[4 * p + 2 + h]);
      b[4 * p + 2 + h] = _mm512_permutex2var_pd(
          a[4 * p + h], _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15), a[4 * p + 2 + h]);
    }
  // 256-bit halves: rows 0-3 (b[0..3]) with rows 4-7 (b[4..7]).
  for (int q = 0; q < 4; ++q) {
    out[q] = _mm512_shuffle_f64x2(b[q], b[q + 4], 0x44);
    out[q + 4] = _mm512_shuffle_f64x2(b[q], b[q + 4], 0xEE);
  }
}

/// assign() eight neighbours at a time: each fit's next eight entries (zeros past its count) as
/// the rows of a block, transposed into eight interleaved entries. The scalar strided copy and
/// the zeroing showed in a robust stack's profile.
SCALESPACE_TARGET_AVX512 void interleaveAvx512(const NeighborColumns* const* fits, int count,
                                               std::size_t length, Column* const* out) {
  const std::size_t kLanes = InterleavedColumns::kLanes;
  const double* in[8][kLanes] = {};  // column a of fit l
  std::size_t size[kLanes] = {};
  for (int l = 0; l < count; ++l) {
    const NeighborColumns& c = *fits[l];
    const Column* columns[8] = {&c.qx, &c.qy, &c.qz, &c.nx, &c.ny, &c.nz, &c.d2, &c.weight};
    for (int a = 0; a < 8; ++a) in[a][l] = columns[a]->data();
    size[l] = c.size();
  }
  for (std::size_t k = 0; k < length; k += 8) {
    __mmask8 m[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l) {
      const std::size_t rest = size[l] > k ? size[l] - k : 0;
      m[l] = rest >= 8 ? __mmask8(0xff) : __mmask8((1u << rest) - 1);
    }
    for (int a = 0; a < 8; ++a) {
      __m512d rows[8], columns[8];
      for (std::size_t l = 0; l < kLanes; ++l)
        rows[l] = m[l] ? _mm512_maskz_loadu_pd(m[l], in[a][l] + k) : _mm512_setzero_pd();
      transpose8(rows, columns);
      double* to = out[a]->data() + kLanes * k;
      for (std::size_t j = 0; j < 8; ++j) _mm512_storeu_pd(to + kLanes * j, columns[j]);
    }
  }
}
}  // namespace
#endif

void InterleavedColumns::assign(const NeighborColumns* const* columns, int count) {
  fits = count;
  length = 0;
  for (int l = 0; l < count; ++l) {
    this->count[l] = int(columns[l]->size());
    length = std::max(length, columns[l]->size());
  }
  for (int l = count; l < kLanes; ++l) this->count[l] = 0;
  // Whole blocks of eight neighbours: the last one may pass `length`.
  const std::size_t entries = std::size_t(kLanes) * ((length + 7) / 8 * 8);
  Column* out[8] = {&qx, &qy, &qz, &nx, &ny, &nz, &d2, &weight};
  for (Column* v : out)
    if (v->size() < entries) v->resize(entries);
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (avx512Available()) return interleaveAvx512(columns, count, length, out);
#endif
  for (int a = 0; a < 8; ++a)
    std::fill(out[a]->begin(), out[a]->begin() + std::ptrdiff_t(entries), 0.0);
  for (int l = 0; l < count; ++l) {
    const NeighborColumns& c = *columns[l];
    const Column* in[8] = {&c.qx, &c.qy, &c.qz, &c.nx, &c.ny, &c.nz, &c.d2, &c.weight};
    for (int a = 0; a < 8; ++a) {
      const double* from = in[a]->data();
      double* to = out[a]->data() + l;
      for (std::size_t k = 0; k < c.size(); ++k) to[std::size_t(kLanes) * k] = from[k];
    }
  }
}

namespace {

/// robustSpheresInLanes one fit at a time with the single-fit passes (CPUs without AVX-512).
void robustSpheresOneByOne(const InterleavedColumns& c, double t, int passes, int minNeighbors,
                           double invSr2, double invSn2, LaneSphere* out,
                           std::vector<double>* factors) {
  NeighborColumns fit;
  std::vector<double> trial;
  for (int l = 0; l < c.fits; ++l) {
    const std::size_t n = std::size_t(c.count[l]);
    fit.clear();
    fit.reserve(n);
    fit.setSize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t o = std::size_t(InterleavedColumns::kLanes) * k + std::size_t(l);
      fit.qx[k] = c.qx[o], fit.qy[k] = c.qy[o], fit.qz[k] = c.qz[o];
      fit.nx[k] = c.nx[o], fit.ny[k] = c.ny[o], fit.nz[k] = c.nz[o];
      fit.d2[k] = c.d2[o], fit.weight[k] = c.weight[o];
    }
    SphereSums sums;
    kernelWeightedSums(fit, sums);
    factors[l].clear();
    out[l].neighbors = sums.used;
    out[l].valid = sphereFromSums(sums.s, sums.used, t, minNeighbors, out[l].sphere);
    for (int it = 0; it < passes && out[l].valid; ++it) {
      reweight(out[l].sphere, invSr2, invSn2, fit, factors[l], trial, sums, SimdKernel::Auto,
               ReweightOutput::Sums);
      AlgebraicSphere next;
      if (!sphereFromSums(sums.s, sums.s[0] > 0 ? 1 : 0, t, 1, next)) break;
      out[l].sphere = next;
      std::swap(factors[l], trial);
    }
  }
}

}  // namespace

void robustSpheresInLanes(const InterleavedColumns& columns, double t, int passes, int minNeighbors,
                          double invSr2, double invSn2, LaneSphere* out,
                          std::vector<double>* factors, SimdKernel kernel) {
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel)) {
    // Per-thread scratch: the interleaved factors of the current and the trial pass.
    thread_local std::vector<double> current, trial;
    return robustSpheresAvx512(columns, t, passes, minNeighbors, invSr2, invSn2, out, factors,
                               current, trial);
  }
#endif
  (void)kernel;
  robustSpheresOneByOne(columns, t, passes, minNeighbors, invSr2, invSn2, out, factors);
}

}  // namespace scalespace
