#include "scalespace/fit/OrientedSphereFit.hpp"

#include <cmath>
#include <type_traits>

#include "scalespace/fit/DerivativeSums.hpp"
#include "scalespace/fit/Jet.hpp"
#include "scalespace/fit/SimdIntrinsics.hpp"

namespace scalespace {
namespace {

// u_l is only ever differentiated once (W3's Hessian, Eq. 1.36, needs its Jacobian), so for a
// Jet2 it is carried as a Jet1; every other type keeps its own.
template <class S>
struct LowerOrder {
  using type = S;
};
template <>
struct LowerOrder<Jet2> {
  using type = Jet1;
};
template <class S>
const S& firstOrder(const S& s) {
  return s;
}

template <class S>
struct SphereTerms {
  S uc, uq;
  typename LowerOrder<S>::type ul[3];
  bool ok = false;
};

template <class S>
double valueOf(const S& s) {
  return s.v;
}
template <>
double valueOf<double>(const double& s) {
  return s;
}

/// Eq. 1.7-1.9 on sums of any differentiable scalar type. `item` holds the sums of 1, q (3),
/// n (3), q.n, |q|^2. `degenerate` is the threshold below which the position variance is zero.
template <class S>
SphereTerms<S> solveSphere(const S* item, double degenerate) {
  SphereTerms<S> r;
  const S& s0 = item[0];
  const S* sp = item + 1;
  const S* sn = item + 4;
  const S& spn = item[7];
  const S& spp = item[8];
  const S pn = sp[0] * sn[0] + sp[1] * sn[1] + sp[2] * sn[2];
  const S pp = sp[0] * sp[0] + sp[1] * sp[1] + sp[2] * sp[2];
  const S num = s0 * spn - pn;  // Eq. 1.7 numerator
  const S den = s0 * spp - pp;
  if (!(valueOf(den) > degenerate)) return r;  // all samples (numerically) at one position
  r.uq = 0.5 * (num / den);                    // Eq. 1.7
  const S invS0 = inverse(s0);
  // Eq. 1.9 with u_l of Eq. 1.8 substituted: u_c = -(u_l.sp + u_q spp) / s0
  // = -(sp.sn + u_q (den - |sp|^2)) / s0^2, from sums already formed, so that u_l itself needs
  // no Hessian (for W3 that saves 9 of the solve's 23 Jet2 products).
  r.uc = -1.0 * ((pn + r.uq * (den - pp)) * (invS0 * invS0));
  using L = typename LowerOrder<S>::type;
  const L uq = firstOrder(r.uq), inv = firstOrder(invS0);
  for (int k = 0; k < 3; ++k)
    r.ul[k] = (firstOrder(sn[k]) - 2.0 * (uq * firstOrder(sp[k]))) * inv;  // Eq. 1.8
  r.ok = true;
  return r;
}

/// Eq. 1.7-1.9 on plain sums (no derivatives); false when degenerate.
bool solvePlain(const double* sums, double t, AlgebraicSphere& sphere) {
  const double degenerate = 1e-14 * sums[0] * sums[0] * (t * t);
  const auto u = solveSphere<double>(sums, degenerate);
  if (!u.ok) return false;
  sphere.uc = u.uc;
  sphere.uq = u.uq;
  sphere.ul = Vec3(u.ul[0], u.ul[1], u.ul[2]);
  return true;
}

/// What finish() reads from a W2 or W3 solve: Eq. 1.7-1.9 with the first derivatives of u_c,
/// u_q and u_l, and for W3 the second derivatives of u_c.
struct SphereJets {
  bool ok = false;
  double uc = 0, uq = 0;
  Vec3 ul = Vec3::Zero();
  Vec3 gradUc = Vec3::Zero(), gradUq = Vec3::Zero();
  Mat3 jacobianUl = Mat3::Zero(), hessianUc = Mat3::Zero();
};

template <class S>
SphereJets jetsOf(const SphereTerms<S>& u) {
  SphereJets r;
  if (!u.ok) return r;
  r.ok = true;
  r.uc = u.uc.v;
  r.uq = u.uq.v;
  for (int k = 0; k < 3; ++k) {
    r.ul[k] = u.ul[k].v;
    r.jacobianUl.row(k) = u.ul[k].g.transpose();
  }
  r.gradUc = u.uc.g;
  r.gradUq = u.uq.g;
  if constexpr (std::is_same_v<S, Jet2>) r.hessianUc = u.uc.hessian();
  return r;
}

#ifdef SCALESPACE_HAVE_AVX2_TARGET
// The same solve with each Jet2 in two registers: (v, g) in four lanes and the six Hessian
// entries (Jet2's order) in eight, the last two zero. A product is a dozen vector instructions
// instead of ~50 scalar ones: the scalar solve showed in a robust stack's profile, spread over
// ~1800 instructions of finish().
struct Jet2x {
  __m256d vg;  // v, g_x, g_y, g_z
  __m512d h;   // xx, yy, zz, xy, xz, yz, 0, 0
};

/// The gradient entries that Hessian entry k pairs (Jet2::kRow, Jet2::kCol), from (v, g).
SCALESPACE_TARGET_AVX512 inline __m512d rowEntries(__m256d vg) {
  return _mm512_permutexvar_pd(_mm512_setr_epi64(1, 2, 3, 1, 1, 2, 0, 0),
                               _mm512_castpd256_pd512(vg));
}
SCALESPACE_TARGET_AVX512 inline __m512d colEntries(__m256d vg) {
  return _mm512_permutexvar_pd(_mm512_setr_epi64(1, 2, 3, 2, 3, 3, 0, 0),
                               _mm512_castpd256_pd512(vg));
}
constexpr __mmask8 kHessianLanes = 0x3F;

/// (ab)' = a b' + b a' on (v, g): lane 0 is a.v b.v alone.
SCALESPACE_TARGET_AVX512 inline __m256d mul1(__m256d a, __m256d b) {
  return _mm256_fmadd_pd(_mm256_permute4x64_pd(a, 0), b,
                         _mm256_maskz_mul_pd(0xE, _mm256_permute4x64_pd(b, 0), a));
}
// (ab)'' = a b'' + b a'' + a' b'^T + b' a'^T (Jet.hpp)
SCALESPACE_TARGET_AVX512 inline Jet2x mul(const Jet2x& a, const Jet2x& b) {
  const __m512d av = _mm512_broadcastsd_pd(_mm256_castpd256_pd128(a.vg));
  const __m512d bv = _mm512_broadcastsd_pd(_mm256_castpd256_pd128(b.vg));
  const __m512d cross = _mm512_fmadd_pd(rowEntries(a.vg), colEntries(b.vg),
                                        _mm512_mul_pd(rowEntries(b.vg), colEntries(a.vg)));
  return {mul1(a.vg, b.vg),
          _mm512_maskz_mov_pd(kHessianLanes,
                              _mm512_fmadd_pd(av, b.h, _mm512_fmadd_pd(bv, a.h, cross)))};
}
SCALESPACE_TARGET_AVX512 inline Jet2x add(const Jet2x& a, const Jet2x& b) {
  return {_mm256_add_pd(a.vg, b.vg), _mm512_add_pd(a.h, b.h)};
}
SCALESPACE_TARGET_AVX512 inline Jet2x sub(const Jet2x& a, const Jet2x& b) {
  return {_mm256_sub_pd(a.vg, b.vg), _mm512_sub_pd(a.h, b.h)};
}
SCALESPACE_TARGET_AVX512 inline Jet2x scale(double s, const Jet2x& a) {
  return {_mm256_mul_pd(_mm256_set1_pd(s), a.vg), _mm512_mul_pd(_mm512_set1_pd(s), a.h)};
}
/// (1/b)' = -b' / b^2 on (v, g).
SCALESPACE_TARGET_AVX512 inline __m256d inverse1(__m256d b, double i) {
  return _mm256_mask_blend_pd(0x1, _mm256_mul_pd(_mm256_set1_pd(-i * i), b), _mm256_set1_pd(i));
}
// (1/b)'' = -b'' / b^2 + 2 b' b'^T / b^3
SCALESPACE_TARGET_AVX512 inline Jet2x inverse(const Jet2x& b) {
  const double i = 1 / _mm256_cvtsd_f64(b.vg), i2 = i * i, i3 = 2 * i2 * i;
  const __m512d outer = _mm512_mul_pd(rowEntries(b.vg), colEntries(b.vg));
  return {
      inverse1(b.vg, i),
      _mm512_maskz_mov_pd(kHessianLanes, _mm512_fmadd_pd(_mm512_set1_pd(i3), outer,
                                                         _mm512_mul_pd(_mm512_set1_pd(-i2), b.h)))};
}

/// solveSphere<Jet2> (the same operations in the same order; fused multiply-adds round once).
SCALESPACE_TARGET_AVX512 SphereJets secondOrderAvx512(const Jet2* items, double degenerate) {
  Jet2x it[9];
  for (int k = 0; k < 9; ++k)
    it[k] = {_mm256_setr_pd(items[k].v, items[k].g.x(), items[k].g.y(), items[k].g.z()),
             _mm512_maskz_loadu_pd(kHessianLanes, items[k].h)};
  const Jet2x& s0 = it[0];
  const Jet2x* sp = it + 1;
  const Jet2x* sn = it + 4;
  const Jet2x pn = add(add(mul(sp[0], sn[0]), mul(sp[1], sn[1])), mul(sp[2], sn[2]));
  const Jet2x pp = add(add(mul(sp[0], sp[0]), mul(sp[1], sp[1])), mul(sp[2], sp[2]));
  const Jet2x num = sub(mul(s0, it[7]), pn);  // Eq. 1.7 numerator
  const Jet2x den = sub(mul(s0, it[8]), pp);
  SphereJets r;
  if (!(_mm256_cvtsd_f64(den.vg) > degenerate)) return r;
  const Jet2x uq = scale(0.5, mul(num, inverse(den)));  // Eq. 1.7
  const Jet2x invS0 = inverse(s0);
  // Eq. 1.9 as in solveSphere: u_c = -(sp.sn + u_q (den - |sp|^2)) / s0^2.
  const Jet2x uc = scale(-1.0, mul(add(pn, mul(uq, sub(den, pp))), mul(invS0, invS0)));
  alignas(64) double lanes[8];
  for (int k = 0; k < 3; ++k) {
    // Eq. 1.8 to first order: (sn - 2 u_q sp) / s0.
    const __m256d two = _mm256_set1_pd(2.0);
    const __m256d ul =
        mul1(_mm256_sub_pd(sn[k].vg, _mm256_mul_pd(two, mul1(uq.vg, sp[k].vg))), invS0.vg);
    _mm256_store_pd(lanes, ul);
    r.ul[k] = lanes[0];
    r.jacobianUl.row(k) = Eigen::RowVector3d(lanes[1], lanes[2], lanes[3]);
  }
  _mm256_store_pd(lanes, uq.vg);
  r.uq = lanes[0];
  r.gradUq = Vec3(lanes[1], lanes[2], lanes[3]);
  _mm256_store_pd(lanes, uc.vg);
  r.uc = lanes[0];
  r.gradUc = Vec3(lanes[1], lanes[2], lanes[3]);
  _mm512_store_pd(lanes, uc.h);
  r.hessianUc << lanes[0], lanes[3], lanes[4], lanes[3], lanes[1], lanes[5], lanes[4], lanes[5],
      lanes[2];
  r.ok = true;
  return r;
}
#endif

}  // namespace

bool sphereFromSums(const double* sums, int count, double t, int minNeighbors,
                    AlgebraicSphere& sphere) {
  if (count < minNeighbors || count < 1 || !(sums[0] > 0)) return false;
  return solvePlain(sums, t, sphere) && sphere.isValid() && sphere.ul.squaredNorm() > 0;
}

void OrientedSphereFit::begin(const Vec3& x, double t, FitDerivatives order, bool scale) {
  x_ = x;
  kernel_ = WeightKernel(t);
  order_ = order;
  scale_ = scale;
  count_ = 0;
  for (auto& row : sums_)
    for (double& v : row) v = 0;
}

void OrientedSphereFit::add(const Vec3& p, const Vec3& n, double extraWeight) {
  const Vec3 q = p - x_;
  const double d2 = q.squaredNorm();
  const double r = kernel_.ratio(d2);
  if (r >= 1) return;
  const double rm1 = r - 1;
  const double w = rm1 * rm1 * extraWeight;
  if (!(w > 0)) return;
  ++count_;
  const double item[9] = {1.0, q.x(), q.y(), q.z(), n.x(), n.y(), n.z(), q.dot(n), d2};
  for (int i = 0; i < 9; ++i) sums_[i][0] += w * item[i];
  if (order_ >= FitDerivatives::First) {
    // grad_x w = -grad_q w = -4 (r - 1) q / t^2 (dq/dx = -I).
    const Vec3 gx = (-4 * rm1 * kernel_.invT2 * extraWeight) * q;
    for (int i = 0; i < 9; ++i)
      for (int c = 0; c < 3; ++c) sums_[i][1 + c] += item[i] * gx[c];
  }
  if (order_ >= FitDerivatives::Second) {
    // hess_x w = hess_q w = 4 (r - 1) I / t^2 + 8 q q^T / t^4 (two sign flips cancel).
    const double a = 4 * rm1 * kernel_.invT2 * extraWeight;
    const double b = 8 * kernel_.invT2 * kernel_.invT2 * extraWeight;
    const double qq[6] = {q.x() * q.x(), q.y() * q.y(), q.z() * q.z(),
                          q.x() * q.y(), q.x() * q.z(), q.y() * q.z()};
    for (int i = 0; i < 9; ++i) {
      sums_[i][4] += a * item[i];
      for (int c = 0; c < 6; ++c) sums_[i][5 + c] += (b * item[i]) * qq[c];
    }
  }
  if (scale_) {
    const double dt = kernel_.scaleDerivative(r) * extraWeight;
    for (int i = 0; i < 9; ++i) sums_[i][11] += dt * item[i];
  }
}

void OrientedSphereFit::addColumns(const NeighborColumns& columns, const double* extraWeight) {
  if (order_ != FitDerivatives::None || scale_) {
    // add()'s sums as one 9 x 12 block (fit/DerivativeSums.hpp), accumulated in registers
    // chunk by chunk straight onto the members (the columns an order does not need are formed
    // too, and never read).
    count_ += addDerivativeColumns(columns, extraWeight, x_, kernel_, sums_);
    return;
  }
  for (std::size_t k = 0; k < columns.size(); ++k)
    add(Vec3(columns.qx[k], columns.qy[k], columns.qz[k]),
        Vec3(columns.nx[k], columns.ny[k], columns.nz[k]), extraWeight[k]);
}

namespace {

/// Neighbours (nearly) on one line leave the sphere free to turn about that line: the solve then
/// succeeds on rounding noise and reports curvatures in the thousands. The first-derivative sums
/// hold M = sum c q q^T (rows and columns 1-3, c = 4 (1 - r) / t^2 >= 0), the neighbours' second
/// moment about the fit point; with eigenvalues l1 >= l2 >= l3, the sum of its 2 x 2 principal
/// minors over trace^2 is about l2 / l1, the squared width/length ratio of the neighbourhood (1/4
/// for a disc). Below kLineRatio (a strip 1/1000 as wide as it is long) the fit is degenerate.
constexpr double kLineRatio = 1e-6;

bool neighboursOnALine(const double (&sums)[9][12]) {
  const auto m = [&](int i, int j) { return sums[1 + i][1 + j]; };
  const double trace = m(0, 0) + m(1, 1) + m(2, 2);
  const double minors = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0) + m(0, 0) * m(2, 2) -
                        m(0, 2) * m(2, 0) + m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1);
  return !(minors > kLineRatio * trace * trace);
}

}  // namespace

OrientedSphereFitResult OrientedSphereFit::finish(int minNeighbors, SimdKernel kernel) const {
  (void)kernel;  // only the AVX-512 build of the W3 solve reads it
  OrientedSphereFitResult res;
  res.neighbors = count_;
  double s[9];  // sum w item
  for (int k = 0; k < 9; ++k) s[k] = sums_[k][0];
  res.weightSum = s[0];
  if (count_ < minNeighbors || count_ < 1 || !(s[0] > 0)) return res;
  const double t2 = kernel_.t * kernel_.t;
  const double degenerate = 1e-14 * s[0] * s[0] * t2;
  AlgebraicSphere sphere;
  if (order_ == FitDerivatives::None) {
    if (!solvePlain(s, kernel_.t, sphere)) return res;
    res.gradient = sphere.ul;
  } else {
    SphereJets u;
    if (order_ == FitDerivatives::First) {
      Jet1 items[9];
      for (int k = 0; k < 9; ++k) items[k] = {s[k], Vec3(sums_[k][1], sums_[k][2], sums_[k][3])};
      u = jetsOf(solveSphere<Jet1>(items, degenerate));
    } else {
      Jet2 items[9];
      for (int k = 0; k < 9; ++k) {
        // hess_x of the sum: a I + b qq^T (add(): xx, yy, zz, xy, xz, yz)
        items[k].v = s[k];
        items[k].g = Vec3(sums_[k][1], sums_[k][2], sums_[k][3]);
        for (int e = 0; e < 6; ++e) items[k].h[e] = sums_[k][5 + e] + (e < 3 ? sums_[k][4] : 0.0);
      }
#ifdef SCALESPACE_HAVE_AVX2_TARGET
      u = useAvx512(kernel) ? secondOrderAvx512(items, degenerate)
                            : jetsOf(solveSphere<Jet2>(items, degenerate));
#else
      u = jetsOf(solveSphere<Jet2>(items, degenerate));
#endif
    }
    if (!u.ok) return res;
    sphere.uc = u.uc;
    sphere.uq = u.uq;
    sphere.ul = u.ul;
    res.jacobianUl = u.jacobianUl;
    res.gradUc = u.gradUc;
    res.gradUq = u.gradUq;
    // Eq. 1.36 at x = 0: the terms in x vanish, leaving hess u_c + J + J^T + 2 u_q I.
    if (order_ == FitDerivatives::Second)
      res.hessianW3 = u.hessianUc + res.jacobianUl + res.jacobianUl.transpose() +
                      2 * sphere.uq * Mat3::Identity();
  }
  if (order_ >= FitDerivatives::First) {
    // Eq. 1.33 at x = 0: grad u_c + u_l; Eq. 1.34 at x = 0: J + 2 u_q I.
    res.gradient = res.gradUc + sphere.ul;
    res.hessianW2 = res.jacobianUl + 2 * sphere.uq * Mat3::Identity();
  }
  if (scale_) {
    Dual items[9];
    for (int k = 0; k < 9; ++k) items[k] = {s[k], sums_[k][11]};
    const auto u = solveSphere<Dual>(items, degenerate);
    if (u.ok) {
      res.dUcDt = u.uc.d;
      res.dUqDt = u.uq.d;
      res.dUlDt = Vec3(u.ul[0].d, u.ul[1].d, u.ul[2].d);
    }
  }
  res.sphere = sphere;
  res.valid = sphere.isValid() && res.gradient.allFinite() && res.hessianW2.allFinite() &&
              res.hessianW3.allFinite() && res.gradient.squaredNorm() > 0 &&
              (order_ == FitDerivatives::None || !neighboursOnALine(sums_));
  return res;
}

}  // namespace scalespace
