#pragma once
// The AVX-512 pieces that the single-fit re-weighting pass (fit/RobustReweighting.cpp) and the
// eight-fits-in-lanes pass (fit/RobustLanes.cpp) share: the exponential and inverse square root on
// eight lanes, the accumulation of a sphere fit's 9 sums and the RIMLS factor of eight
// neighbours. Included only by the .cpp files that define AVX-512 kernels (it includes
// fit/SimdIntrinsics.hpp, which silences warnings for the rest of the including file).
#include "scalespace/fit/FastExp.hpp"
#include "scalespace/fit/SimdIntrinsics.hpp"

#ifdef SCALESPACE_HAVE_AVX2_TARGET
namespace scalespace {

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

}  // namespace scalespace
#endif
