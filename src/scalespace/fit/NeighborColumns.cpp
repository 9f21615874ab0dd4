#include "scalespace/fit/NeighborColumns.hpp"

#include <algorithm>

#include "scalespace/fit/SimdIntrinsics.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

void NeighborColumns::push(const Vec3& q, const Vec3& n, double kernelWeight) {
  if (size_ == qx.size()) reserve(std::max<std::size_t>(16, 2 * size_));
  const std::size_t k = size_++;
  qx[k] = q.x(), qy[k] = q.y(), qz[k] = q.z();
  nx[k] = n.x(), ny[k] = n.y(), nz[k] = n.z();
  d2[k] = q.squaredNorm();
  weight[k] = kernelWeight;
}

void NeighborColumns::reserve(std::size_t n) {
  if (qx.size() >= n) return;
  for (auto* v : {&qx, &qy, &qz, &nx, &ny, &nz, &d2, &weight}) v->resize(n);
}

namespace {

/// Raw pointers to the columns: stores through the output vectors could alias the vectors
/// themselves, and the compiler would reload their data pointers at every candidate.
struct Outputs {
  double *qx, *qy, *qz, *nx, *ny, *nz, *d2, *w;
  explicit Outputs(NeighborColumns& c)
      : qx(c.qx.data()),
        qy(c.qy.data()),
        qz(c.qz.data()),
        nx(c.nx.data()),
        ny(c.ny.data()),
        nz(c.nz.data()),
        d2(c.d2.data()),
        w(c.weight.data()) {}
};

std::size_t gatherPortable(const SampleColumns& s, const Vec3& y, double t, Outputs o) {
  const WeightKernel kernel(t);
  const double t2 = t * t;
  const std::size_t count = s.size();
  std::size_t kept = 0;
  // Branch-free: about half of the candidates are kept, in no predictable pattern. Every
  // candidate is written at `kept`, which only advances past the kept ones.
  for (std::size_t k = 0; k < count; ++k) {
    const Vec3 q(s.px[k] - y.x(), s.py[k] - y.y(), s.pz[k] - y.z());
    const double d2 = q.squaredNorm();
    o.qx[kept] = q.x(), o.qy[kept] = q.y(), o.qz[kept] = q.z();
    o.nx[kept] = s.nx[k], o.ny[kept] = s.ny[k], o.nz[kept] = s.nz[k];
    o.d2[kept] = d2;
    o.w[kept] = WeightKernel::value(kernel.ratio(d2));
    kept += d2 < t2 ? 1 : 0;  // the index's test: |p - y|^2 < t^2
  }
  return kept;
}

#ifdef SCALESPACE_HAVE_AVX2_TARGET
/// Eight candidates at a time: the kept lanes are packed to the front of a register
/// (vcompresspd) and the whole vector is stored at the output's end (the columns have 8 entries
/// of slack); the next block overwrites the lanes past the kept ones. Compressing straight to
/// memory is microcoded on AMD's Zen 4 and made the whole multi-scale stack 1.6 times slower
/// there (bench/README.md, fit/NeighborColumns). Gathering and filling the columns one candidate
/// at a time (scalar code) was a large part of fitAt's own time in a robust stack's profile.
SCALESPACE_TARGET_AVX512 std::size_t gatherAvx512(const SampleColumns& s, const Vec3& y, double t,
                                                  Outputs o) {
  const WeightKernel kernel(t);
  const __m512d yx = _mm512_set1_pd(y.x()), yy = _mm512_set1_pd(y.y()), yz = _mm512_set1_pd(y.z());
  const __m512d t2 = _mm512_set1_pd(t * t), invT2 = _mm512_set1_pd(kernel.invT2);
  const __m512d one = _mm512_set1_pd(1.0);
  const double *px = s.px.data(), *py = s.py.data(), *pz = s.pz.data();
  const double *nx = s.nx.data(), *ny = s.ny.data(), *nz = s.nz.data();
  const std::size_t count = s.size();
  std::size_t kept = 0;
  for (std::size_t k = 0; k < count; k += 8) {
    const __mmask8 lanes = count - k >= 8 ? __mmask8(0xff) : __mmask8((1u << (count - k)) - 1);
    const __m512d qx = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, px + k), yx);
    const __m512d qy = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, py + k), yy);
    const __m512d qz = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, pz + k), yz);
    const __m512d d2 = _mm512_fmadd_pd(qx, qx, _mm512_fmadd_pd(qy, qy, _mm512_mul_pd(qz, qz)));
    const __mmask8 in = _mm512_mask_cmp_pd_mask(lanes, d2, t2, _CMP_LT_OQ);
    if (!in) continue;
    // r < 1 on every kept lane: WeightKernel::value is (r - 1)^2 there.
    const __m512d rm1 = _mm512_sub_pd(_mm512_mul_pd(d2, invT2), one);
    _mm512_storeu_pd(o.qx + kept, _mm512_maskz_compress_pd(in, qx));
    _mm512_storeu_pd(o.qy + kept, _mm512_maskz_compress_pd(in, qy));
    _mm512_storeu_pd(o.qz + kept, _mm512_maskz_compress_pd(in, qz));
    _mm512_storeu_pd(o.nx + kept,
                     _mm512_maskz_compress_pd(in, _mm512_maskz_loadu_pd(lanes, nx + k)));
    _mm512_storeu_pd(o.ny + kept,
                     _mm512_maskz_compress_pd(in, _mm512_maskz_loadu_pd(lanes, ny + k)));
    _mm512_storeu_pd(o.nz + kept,
                     _mm512_maskz_compress_pd(in, _mm512_maskz_loadu_pd(lanes, nz + k)));
    _mm512_storeu_pd(o.d2 + kept, _mm512_maskz_compress_pd(in, d2));
    _mm512_storeu_pd(o.w + kept, _mm512_maskz_compress_pd(in, _mm512_mul_pd(rm1, rm1)));
    kept += std::size_t(__builtin_popcount(in));
  }
  return kept;
}
#endif

}  // namespace

void gatherWithin(const SampleColumns& samples, const Vec3& y, double t, NeighborColumns& out,
                  SimdKernel kernel) {
  // Slack of one vector: the AVX-512 gather stores eight lanes at the output's end.
  out.reserve(samples.size() + 8);
  std::size_t kept = 0;
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  if (useAvx512(kernel))
    kept = gatherAvx512(samples, y, t, Outputs(out));
  else
#endif
    kept = gatherPortable(samples, y, t, Outputs(out));
  (void)kernel;
  out.setSize(kept);
}

}  // namespace scalespace
