#include "scalespace/fit/OrientedSphereFit.hpp"

#include <cmath>

#include "scalespace/fit/DerivativeSums.hpp"
#include "scalespace/fit/Jet.hpp"

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
  s_.setZero();
  if (order_ >= FitDerivatives::First) g_.setZero();
  if (order_ >= FitDerivatives::Second) {
    a_.setZero();
    b_.setZero();
  }
  if (scale_) dt_.setZero();
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
  Item item;
  item << 1.0, q.x(), q.y(), q.z(), n.x(), n.y(), n.z(), q.dot(n), d2;
  s_.noalias() += w * item;
  if (order_ >= FitDerivatives::First) {
    // grad_x w = -grad_q w = -4 (r - 1) q / t^2 (dq/dx = -I).
    const Vec3 gx = (-4 * rm1 * kernel_.invT2 * extraWeight) * q;
    g_.noalias() += item * gx.transpose();
  }
  if (order_ >= FitDerivatives::Second) {
    // hess_x w = hess_q w = 4 (r - 1) I / t^2 + 8 q q^T / t^4 (two sign flips cancel).
    const double a = 4 * rm1 * kernel_.invT2 * extraWeight;
    const double b = 8 * kernel_.invT2 * kernel_.invT2 * extraWeight;
    a_.noalias() += a * item;
    Eigen::Matrix<double, 1, 6> qq;
    qq << q.x() * q.x(), q.y() * q.y(), q.z() * q.z(), q.x() * q.y(), q.x() * q.z(), q.y() * q.z();
    b_.noalias() += (b * item) * qq;
  }
  if (scale_) dt_.noalias() += (kernel_.scaleDerivative(r) * extraWeight) * item;
}

void OrientedSphereFit::addBatchWithDerivatives(const Vec3* p, const Vec3* n,
                                                const double* extraWeight, std::size_t count) {
  // add()'s sums as one 9 x 12 block (fit/DerivativeSums.hpp): the block stays in registers
  // instead of updating 108 member sums per sample.
  DerivativeSums sums = {};
  const int used = addDerivativeSamples(p, n, extraWeight, count, x_, kernel_, sums);
  addDerivativeBlock(sums, used);
}

void OrientedSphereFit::addDerivativeBlock(const double (&sums)[9][12], int used) {
  count_ += used;
  for (int i = 0; i < 9; ++i) {
    s_[i] += sums[i][0];
    if (order_ >= FitDerivatives::First)
      for (int c = 0; c < 3; ++c) g_(i, c) += sums[i][1 + c];
    if (order_ >= FitDerivatives::Second) {
      a_[i] += sums[i][4];
      for (int c = 0; c < 6; ++c) b_(i, c) += sums[i][5 + c];
    }
    if (scale_) dt_[i] += sums[i][11];
  }
}

void OrientedSphereFit::addColumns(const NeighborColumns& columns, const double* extraWeight) {
  if (order_ != FitDerivatives::None || scale_) {
    DerivativeSums sums = {};
    const int used = addDerivativeColumns(columns, extraWeight, x_, kernel_, sums);
    addDerivativeBlock(sums, used);
    return;
  }
  for (std::size_t k = 0; k < columns.size(); ++k)
    add(Vec3(columns.qx[k], columns.qy[k], columns.qz[k]),
        Vec3(columns.nx[k], columns.ny[k], columns.nz[k]), extraWeight[k]);
}

void OrientedSphereFit::addBatch(const Vec3* p, const Vec3* n, const double* extraWeight,
                                 std::size_t count) {
  if (order_ != FitDerivatives::None || scale_) {
    addBatchWithDerivatives(p, n, extraWeight, count);
    return;
  }
  // Same arithmetic as add(), accumulated in locals: the member sums would be reloaded and
  // stored at every sample (a loop-carried dependency through memory).
  double s0 = 0, sq0 = 0, sq1 = 0, sq2 = 0, sn0 = 0, sn1 = 0, sn2 = 0, sqn = 0, sqq = 0;
  int used = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const Vec3 q = p[k] - x_;
    const double d2 = q.squaredNorm();
    const double r = kernel_.ratio(d2);
    if (r >= 1) continue;
    const double rm1 = r - 1;
    const double w = rm1 * rm1 * extraWeight[k];
    if (!(w > 0)) continue;
    ++used;
    s0 += w;
    sq0 += w * q.x(), sq1 += w * q.y(), sq2 += w * q.z();
    sn0 += w * n[k].x(), sn1 += w * n[k].y(), sn2 += w * n[k].z();
    sqn += w * q.dot(n[k]);
    sqq += w * d2;
  }
  count_ += used;
  Item item;
  item << s0, sq0, sq1, sq2, sn0, sn1, sn2, sqn, sqq;
  s_ += item;
}

void OrientedSphereFit::addSums(const double* sums, int count) {
  for (int k = 0; k < 9; ++k) s_[k] += sums[k];
  count_ += count;
}

OrientedSphereFitResult OrientedSphereFit::finish(int minNeighbors) const {
  OrientedSphereFitResult res;
  res.neighbors = count_;
  res.weightSum = s_[0];
  if (count_ < minNeighbors || count_ < 1 || !(s_[0] > 0)) return res;
  const double t2 = kernel_.t * kernel_.t;
  const double degenerate = 1e-14 * s_[0] * s_[0] * t2;
  AlgebraicSphere sphere;
  if (order_ == FitDerivatives::None) {
    if (!solvePlain(s_.data(), kernel_.t, sphere)) return res;
    res.gradient = sphere.ul;
  } else if (order_ == FitDerivatives::First) {
    Jet1 items[9];
    for (int k = 0; k < 9; ++k) items[k] = {s_[k], g_.row(k).transpose()};
    const auto u = solveSphere<Jet1>(items, degenerate);
    if (!u.ok) return res;
    sphere.uc = u.uc.v;
    sphere.uq = u.uq.v;
    for (int k = 0; k < 3; ++k) {
      sphere.ul[k] = u.ul[k].v;
      res.jacobianUl.row(k) = u.ul[k].g.transpose();
    }
    res.gradUc = u.uc.g;
    res.gradUq = u.uq.g;
  } else {
    Jet2 items[9];
    for (int k = 0; k < 9; ++k) {
      // hess_x of the sum: a I + b qq^T (add(): xx, yy, zz, xy, xz, yz)
      items[k].v = s_[k];
      items[k].g = g_.row(k).transpose();
      for (int e = 0; e < 6; ++e) items[k].h[e] = b_(k, e) + (e < 3 ? a_[k] : 0.0);
    }
    const auto u = solveSphere<Jet2>(items, degenerate);
    if (!u.ok) return res;
    sphere.uc = u.uc.v;
    sphere.uq = u.uq.v;
    for (int k = 0; k < 3; ++k) {
      sphere.ul[k] = u.ul[k].v;
      res.jacobianUl.row(k) = u.ul[k].g.transpose();
    }
    res.gradUc = u.uc.g;
    res.gradUq = u.uq.g;
    // Eq. 1.36 at x = 0: the terms in x vanish, leaving hess u_c + J + J^T + 2 u_q I.
    res.hessianW3 = u.uc.hessian() + res.jacobianUl + res.jacobianUl.transpose() +
                    2 * sphere.uq * Mat3::Identity();
  }
  if (order_ >= FitDerivatives::First) {
    // Eq. 1.33 at x = 0: grad u_c + u_l; Eq. 1.34 at x = 0: J + 2 u_q I.
    res.gradient = res.gradUc + sphere.ul;
    res.hessianW2 = res.jacobianUl + 2 * sphere.uq * Mat3::Identity();
  }
  if (scale_) {
    Dual items[9];
    for (int k = 0; k < 9; ++k) items[k] = {s_[k], dt_[k]};
    const auto u = solveSphere<Dual>(items, degenerate);
    if (u.ok) {
      res.dUcDt = u.uc.d;
      res.dUqDt = u.uq.d;
      res.dUlDt = Vec3(u.ul[0].d, u.ul[1].d, u.ul[2].d);
    }
  }
  res.sphere = sphere;
  res.valid = sphere.isValid() && res.gradient.allFinite() && res.hessianW2.allFinite() &&
              res.hessianW3.allFinite() && res.gradient.squaredNorm() > 0;
  return res;
}

}  // namespace scalespace
