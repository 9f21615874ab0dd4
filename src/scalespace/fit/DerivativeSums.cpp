#include "scalespace/fit/DerivativeSums.hpp"

#include <algorithm>

#include "scalespace/fit/SimdIntrinsics.hpp"

namespace scalespace {
namespace {

void accumulatePortable(const DerivativeChunk& c, int m, DerivativeSums& sums) {
  for (int k = 0; k < m; ++k)
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 12; ++j) sums[i][j] += c.items[i][k] * c.factors[k][j];
}

/// One sample's item and factors into row m of the chunk; false (nothing written) when it has
/// no positive weight.
inline bool formSample(const Vec3& q, const Vec3& n, double e, const WeightKernel& kernel,
                       DerivativeChunk& chunk, int m) {
  const double d2 = q.squaredNorm();
  const double r = kernel.ratio(d2);
  if (r >= 1) return false;
  const double rm1 = r - 1;
  const double w = rm1 * rm1 * e;
  if (!(w > 0)) return false;
  const double item[9] = {1.0, q.x(), q.y(), q.z(), n.x(), n.y(), n.z(), q.dot(n), d2};
  for (int i = 0; i < 9; ++i) chunk.items[i][m] = item[i];
  const double g = -4 * rm1 * kernel.invT2 * e;  // grad_x w = g q
  const double b = 8 * kernel.invT2 * kernel.invT2 * e;
  double* f = chunk.factors[m];
  f[0] = w;
  f[1] = g * q.x(), f[2] = g * q.y(), f[3] = g * q.z();
  f[4] = 4 * rm1 * kernel.invT2 * e;
  f[5] = b * q.x() * q.x(), f[6] = b * q.y() * q.y(), f[7] = b * q.z() * q.z();
  f[8] = b * q.x() * q.y(), f[9] = b * q.x() * q.z(), f[10] = b * q.y() * q.z();
  f[11] = kernel.scaleDerivative(r) * e;
  return true;
}

int addColumnsOneByOne(const NeighborColumns& c, const double* e, const Vec3& x,
                       const WeightKernel& kernel, DerivativeSums& sums, SimdKernel simd) {
  DerivativeChunk chunk;
  int used = 0;
  std::size_t k = 0;
  const std::size_t count = c.size();
  while (k < count) {
    int m = 0;
    for (; k < count && m < DerivativeChunk::kSize; ++k) {
      const Vec3 q = Vec3(c.qx[k], c.qy[k], c.qz[k]) - x;
      if (formSample(q, Vec3(c.nx[k], c.ny[k], c.nz[k]), e[k], kernel, chunk, m)) ++m;
    }
    used += m;
    accumulateDerivativeSums(chunk, m, sums, simd);
  }
  return used;
}

#ifdef SCALESPACE_HAVE_AVX2_TARGET
// 9 accumulators hold a 9 x 4 block of the sums in registers while the samples stream by, so the
// sums are not loaded and stored for every sample (bench/fig_1_10 --mode timing --threads 1).
SCALESPACE_TARGET_AVX2 void accumulateAvx2(const DerivativeChunk& c, int m, DerivativeSums& sums) {
  for (int jb = 0; jb < 12; jb += 4) {
    __m256d acc[9];
    for (__m256d& a : acc) a = _mm256_setzero_pd();
    for (int k = 0; k < m; ++k) {
      const __m256d f = _mm256_load_pd(&c.factors[k][jb]);
      for (int i = 0; i < 9; ++i)
        acc[i] = _mm256_fmadd_pd(_mm256_broadcast_sd(&c.items[i][k]), f, acc[i]);
    }
    for (int i = 0; i < 9; ++i) {
      alignas(32) double lane[4];
      _mm256_store_pd(lane, acc[i]);
      for (int l = 0; l < 4; ++l) sums[i][jb + l] += lane[l];
    }
  }
}

// The same block with 8 + 4 columns per pass over the samples instead of 4 + 4 + 4: 18
// fused multiply-adds per sample instead of 27, all accumulators in the 32 registers.
SCALESPACE_TARGET_AVX512 void accumulateAvx512(const DerivativeChunk& c, int m,
                                               DerivativeSums& sums) {
  __m512d lo[9];
  __m256d hi[9];
  SCALESPACE_UNROLLED_ZERO
  for (int i = 0; i < 9; ++i) lo[i] = _mm512_setzero_pd(), hi[i] = _mm256_setzero_pd();
  for (int k = 0; k < m; ++k) {
    const __m512d f0 = _mm512_loadu_pd(&c.factors[k][0]);
    const __m256d f1 = _mm256_load_pd(&c.factors[k][8]);
    for (int i = 0; i < 9; ++i) {
      const double item = c.items[i][k];
      lo[i] = _mm512_fmadd_pd(_mm512_set1_pd(item), f0, lo[i]);
      hi[i] = _mm256_fmadd_pd(_mm256_set1_pd(item), f1, hi[i]);
    }
  }
  for (int i = 0; i < 9; ++i) {
    alignas(64) double lane[12];
    _mm512_store_pd(lane, lo[i]);
    _mm256_store_pd(lane + 8, hi[i]);
    for (int j = 0; j < 12; ++j) sums[i][j] += lane[j];
  }
}

/// Rows k of eight factor vectors (lane k = sample k): an 8 x 8 transpose in three rounds of
/// two-element, 128-bit and 256-bit interleaves; row k goes to out[k][0..7].
SCALESPACE_TARGET_AVX512 inline void storeRows8(const __m512d* f, double (*out)[12]) {
  __m512d t[8], u[8];
  for (int p = 0; p < 4; ++p) {
    t[2 * p] = _mm512_unpacklo_pd(f[2 * p], f[2 * p + 1]);      // f_{2p}, f_{2p+1} at even k
    t[2 * p + 1] = _mm512_unpackhi_pd(f[2 * p], f[2 * p + 1]);  // and at odd k
  }
  // u[0]: k = 0, 4 of f0..f3; u[1]: k = 2, 6; u[2]: k = 1, 5; u[3]: k = 3, 7 (u[4..7]: f4..f7).
  for (int h = 0; h < 2; ++h) {
    u[4 * h + 0] = _mm512_shuffle_f64x2(t[4 * h + 0], t[4 * h + 2], 0x88);
    u[4 * h + 1] = _mm512_shuffle_f64x2(t[4 * h + 0], t[4 * h + 2], 0xDD);
    u[4 * h + 2] = _mm512_shuffle_f64x2(t[4 * h + 1], t[4 * h + 3], 0x88);
    u[4 * h + 3] = _mm512_shuffle_f64x2(t[4 * h + 1], t[4 * h + 3], 0xDD);
  }
  const int rowOf[4][2] = {{0, 4}, {2, 6}, {1, 5}, {3, 7}};
  for (int v = 0; v < 4; ++v) {
    _mm512_storeu_pd(out[rowOf[v][0]], _mm512_shuffle_f64x2(u[v], u[v + 4], 0x88));
    _mm512_storeu_pd(out[rowOf[v][1]], _mm512_shuffle_f64x2(u[v], u[v + 4], 0xDD));
  }
}

/// Rows k of four factor vectors into out[k][8..11].
SCALESPACE_TARGET_AVX512 inline void storeRows4(const __m512d* f, double (*out)[12]) {
  const __m512d lo01 = _mm512_unpacklo_pd(f[0], f[1]), hi01 = _mm512_unpackhi_pd(f[0], f[1]);
  const __m512d lo23 = _mm512_unpacklo_pd(f[2], f[3]), hi23 = _mm512_unpackhi_pd(f[2], f[3]);
  // Rows 0 and 2 from the even samples' pairs, rows 4 and 6 from the next ones.
  const __m512i first = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
  const __m512i second = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
  const __m512d r02 = _mm512_permutex2var_pd(lo01, first, lo23);
  const __m512d r46 = _mm512_permutex2var_pd(lo01, second, lo23);
  const __m512d r13 = _mm512_permutex2var_pd(hi01, first, hi23);
  const __m512d r57 = _mm512_permutex2var_pd(hi01, second, hi23);
  const __m512d pairs[4] = {r02, r13, r46, r57};  // rows (0, 2), (1, 3), (4, 6), (5, 7)
  const int rowOf[4] = {0, 1, 4, 5};
  for (int v = 0; v < 4; ++v) {
    _mm256_store_pd(out[rowOf[v]] + 8, _mm512_castpd512_pd256(pairs[v]));
    _mm256_store_pd(out[rowOf[v] + 2] + 8, _mm512_extractf64x4_pd(pairs[v], 1));
  }
}

/// The constants of formSample's arithmetic for one kernel, splatted.
struct FormConstants {
  __m512d invT2, one, minus4InvT2, b0, minus4InvT, zero;
  SCALESPACE_TARGET_AVX512 explicit FormConstants(const WeightKernel& kernel)
      : invT2(_mm512_set1_pd(kernel.invT2)),
        one(_mm512_set1_pd(1.0)),
        minus4InvT2(_mm512_set1_pd(-4 * kernel.invT2)),
        b0(_mm512_set1_pd(8 * kernel.invT2 * kernel.invT2)),
        minus4InvT(_mm512_set1_pd(-4 / kernel.t)),
        zero(_mm512_setzero_pd()) {}
};

/// formSample on eight samples (lanes without a positive weight zeroed instead of skipped) into
/// rows m..m+7 of the chunk; `lanes` marks the samples that exist. Returns how many have a
/// positive weight.
SCALESPACE_TARGET_AVX512 inline int formSamples8(__m512d qx, __m512d qy, __m512d qz, __m512d nx,
                                                 __m512d ny, __m512d nz, __m512d ew, __mmask8 lanes,
                                                 const FormConstants& c, DerivativeChunk& chunk,
                                                 int m) {
  const __m512d d2 = _mm512_fmadd_pd(qx, qx, _mm512_fmadd_pd(qy, qy, _mm512_mul_pd(qz, qz)));
  const __m512d r = _mm512_mul_pd(d2, c.invT2);
  const __m512d rm1 = _mm512_sub_pd(r, c.one);
  const __m512d w = _mm512_mul_pd(_mm512_mul_pd(rm1, rm1), ew);
  // formSample's tests: r < 1 and w > 0 (both false for NaN).
  const __mmask8 live = _mm512_mask_cmp_pd_mask(
      _mm512_mask_cmp_pd_mask(lanes, r, c.one, _CMP_LT_OQ), w, c.zero, _CMP_GT_OQ);
  const __m512d g = _mm512_mul_pd(_mm512_mul_pd(c.minus4InvT2, rm1), ew);
  const __m512d b = _mm512_mul_pd(c.b0, ew);
  const __m512d bx = _mm512_mul_pd(b, qx), by = _mm512_mul_pd(b, qy);
  __m512d f[12];
  f[0] = w;
  f[1] = _mm512_mul_pd(g, qx), f[2] = _mm512_mul_pd(g, qy), f[3] = _mm512_mul_pd(g, qz);
  f[4] = _mm512_sub_pd(c.zero, g);  // 4 (r - 1) e / t^2
  f[5] = _mm512_mul_pd(bx, qx), f[6] = _mm512_mul_pd(by, qy);
  f[7] = _mm512_mul_pd(_mm512_mul_pd(b, qz), qz);
  f[8] = _mm512_mul_pd(bx, qy), f[9] = _mm512_mul_pd(bx, qz), f[10] = _mm512_mul_pd(by, qz);
  f[11] = _mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(c.minus4InvT, rm1), r), ew);  // dw/dt e
  for (__m512d& v : f) v = _mm512_maskz_mov_pd(live, v);
  const __m512d item[9] = {
      c.one, qx, qy, qz,
      nx,    ny, nz, _mm512_fmadd_pd(qx, nx, _mm512_fmadd_pd(qy, ny, _mm512_mul_pd(qz, nz))),
      d2};
  for (int i = 0; i < 9; ++i)
    _mm512_store_pd(&chunk.items[i][m], _mm512_maskz_mov_pd(live, item[i]));
  storeRows8(f, chunk.factors + m);
  storeRows4(f + 8, chunk.factors + m);
  return __builtin_popcount(live);
}

/// addDerivativeColumns with eight samples formed at a time, read straight from the columns:
/// forming the samples, more than accumulating them, is what this pass spends its time on, and
/// eight at a time beats one at a time (robust stack: bench/bench_planes --scene stairs).
SCALESPACE_TARGET_AVX512 int addColumnsAvx512(const NeighborColumns& c, const double* e,
                                              const Vec3& x, const WeightKernel& kernel,
                                              DerivativeSums& sums) {
  DerivativeChunk chunk;
  const FormConstants constants(kernel);
  const __m512d cx = _mm512_set1_pd(x.x()), cy = _mm512_set1_pd(x.y()), cz = _mm512_set1_pd(x.z());
  const double *qx = c.qx.data(), *qy = c.qy.data(), *qz = c.qz.data();
  const double *nx = c.nx.data(), *ny = c.ny.data(), *nz = c.nz.data();
  const std::size_t count = c.size();
  int used = 0;
  std::size_t k = 0;
  while (k < count) {
    int m = 0;
    for (; k < count && m < DerivativeChunk::kSize; k += 8, m += 8) {
      const std::size_t rest = count - k;
      const __mmask8 lanes = rest >= 8 ? __mmask8(0xff) : __mmask8((1u << rest) - 1);
      // (A lambda for the loads would not inherit this function's target attribute.)
      used +=
          formSamples8(_mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, qx + k), cx),
                       _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, qy + k), cy),
                       _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, qz + k), cz),
                       _mm512_maskz_loadu_pd(lanes, nx + k), _mm512_maskz_loadu_pd(lanes, ny + k),
                       _mm512_maskz_loadu_pd(lanes, nz + k), _mm512_maskz_loadu_pd(lanes, e + k),
                       lanes, constants, chunk, m);
    }
    accumulateAvx512(chunk, m, sums);
  }
  return used;
}
#endif

}  // namespace

int addDerivativeColumns(const NeighborColumns& c, const double* e, const Vec3& x,
                         const WeightKernel& weight, DerivativeSums& sums, SimdKernel kernel) {
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel)) return addColumnsAvx512(c, e, x, weight, sums);
#endif
  return addColumnsOneByOne(c, e, x, weight, sums, kernel);
}

void accumulateDerivativeSums(const DerivativeChunk& chunk, int m, DerivativeSums& sums,
                              SimdKernel kernel) {
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel)) {
    accumulateAvx512(chunk, m, sums);
    return;
  }
  if (useAvx2Fma(kernel)) {
    accumulateAvx2(chunk, m, sums);
    return;
  }
#endif
  (void)kernel;
  accumulatePortable(chunk, m, sums);
}

}  // namespace scalespace
