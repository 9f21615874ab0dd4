#pragma once
// Tiny forward-mode differentiation used by the closed-form sphere fit (Eq. 1.7-1.9): the sums
// over neighbours carry their spatial gradient and Hessian with respect to the evaluation point,
// and the quotient/product rules below propagate them to u_c, u_l, u_q (what W2 and W3 need,
// Eq. 1.33-1.37). Jet1 holds value + gradient, Jet2 adds the Hessian, Dual holds one scale
// derivative (d/dt, for the GLS geometric variation).
#include <cmath>

#include "scalespace/core/Types.hpp"

namespace scalespace {

struct Jet1 {
  double v = 0;
  Vec3 g = Vec3::Zero();
};
inline Jet1 operator+(const Jet1& a, const Jet1& b) { return {a.v + b.v, a.g + b.g}; }
inline Jet1 operator-(const Jet1& a, const Jet1& b) { return {a.v - b.v, a.g - b.g}; }
inline Jet1 operator*(double s, const Jet1& a) { return {s * a.v, s * a.g}; }
inline Jet1 operator*(const Jet1& a, const Jet1& b) { return {a.v * b.v, a.v * b.g + b.v * a.g}; }
inline Jet1 inverse(const Jet1& b) { return {1 / b.v, -b.g / (b.v * b.v)}; }
inline Jet1 operator/(const Jet1& a, const Jet1& b) { return a * inverse(b); }
inline const Jet1& firstOrder(const Jet1& a) { return a; }

/// Value, gradient and Hessian. The Hessian is symmetric: only its 6 distinct entries are stored
/// (xx, yy, zz, xy, xz, yz), which saves a third of the Hessian arithmetic of the W3 solve (about
/// 20 products and 2 reciprocals per fit).
struct Jet2 {
  double v = 0;
  Vec3 g = Vec3::Zero();
  double h[6] = {0, 0, 0, 0, 0, 0};
  /// Row and column of each stored entry.
  static constexpr int kRow[6] = {0, 1, 2, 0, 0, 1}, kCol[6] = {0, 1, 2, 1, 2, 2};
  Mat3 hessian() const {
    Mat3 m;
    m << h[0], h[3], h[4], h[3], h[1], h[5], h[4], h[5], h[2];
    return m;
  }
};
inline Jet2 operator+(const Jet2& a, const Jet2& b) {
  Jet2 r{a.v + b.v, a.g + b.g};
  for (int k = 0; k < 6; ++k) r.h[k] = a.h[k] + b.h[k];
  return r;
}
inline Jet2 operator-(const Jet2& a, const Jet2& b) {
  Jet2 r{a.v - b.v, a.g - b.g};
  for (int k = 0; k < 6; ++k) r.h[k] = a.h[k] - b.h[k];
  return r;
}
inline Jet2 operator*(double s, const Jet2& a) {
  Jet2 r{s * a.v, s * a.g};
  for (int k = 0; k < 6; ++k) r.h[k] = s * a.h[k];
  return r;
}
// (ab)'' = a b'' + b a'' + a' b'^T + b' a'^T
inline Jet2 operator*(const Jet2& a, const Jet2& b) {
  Jet2 r{a.v * b.v, a.v * b.g + b.v * a.g};
  for (int k = 0; k < 6; ++k) {
    const int i = Jet2::kRow[k], j = Jet2::kCol[k];
    r.h[k] = a.v * b.h[k] + b.v * a.h[k] + a.g[i] * b.g[j] + b.g[i] * a.g[j];
  }
  return r;
}
// (1/b)'' = -b'' / b^2 + 2 b' b'^T / b^3
inline Jet2 inverse(const Jet2& b) {
  const double i = 1 / b.v, i2 = i * i, i3 = 2 * i2 * i;
  Jet2 r{i, -i2 * b.g};
  for (int k = 0; k < 6; ++k) r.h[k] = -i2 * b.h[k] + i3 * b.g[Jet2::kRow[k]] * b.g[Jet2::kCol[k]];
  return r;
}
inline Jet2 operator/(const Jet2& a, const Jet2& b) { return a * inverse(b); }
/// The value and gradient of a Jet2 (what a quantity needs when only its first derivatives are
/// used further).
inline Jet1 firstOrder(const Jet2& a) { return {a.v, a.g}; }

struct Dual {
  double v = 0;
  double d = 0;
};
inline Dual operator+(const Dual& a, const Dual& b) { return {a.v + b.v, a.d + b.d}; }
inline Dual operator-(const Dual& a, const Dual& b) { return {a.v - b.v, a.d - b.d}; }
inline Dual operator*(double s, const Dual& a) { return {s * a.v, s * a.d}; }
inline Dual operator*(const Dual& a, const Dual& b) { return {a.v * b.v, a.v * b.d + b.v * a.d}; }
inline Dual inverse(const Dual& b) { return {1 / b.v, -b.d / (b.v * b.v)}; }
inline double inverse(double b) { return 1 / b; }
inline Dual operator/(const Dual& a, const Dual& b) {
  return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)};
}
inline Dual sqrt(const Dual& a) {
  const double s = std::sqrt(a.v);
  return {s, a.d / (2 * s)};
}

}  // namespace scalespace
