#include "scalespace/fit/RobustLanes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "scalespace/fit/Avx512Sums.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/fit/SimdIntrinsics.hpp"

namespace scalespace {

#ifdef SCALESPACE_HAVE_AVX2_TARGET
namespace {

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

}  // namespace
#endif

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
