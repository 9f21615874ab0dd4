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

struct Jet2 {
  double v = 0;
  Vec3 g = Vec3::Zero();
  Mat3 h = Mat3::Zero();
};
inline Jet2 operator+(const Jet2& a, const Jet2& b) { return {a.v + b.v, a.g + b.g, a.h + b.h}; }
inline Jet2 operator-(const Jet2& a, const Jet2& b) { return {a.v - b.v, a.g - b.g, a.h - b.h}; }
inline Jet2 operator*(double s, const Jet2& a) { return {s * a.v, s * a.g, s * a.h}; }
inline Jet2 operator*(const Jet2& a, const Jet2& b) {
  Mat3 cross = a.g * b.g.transpose();
  return {a.v * b.v, a.v * b.g + b.v * a.g, a.v * b.h + b.v * a.h + cross + cross.transpose()};
}
inline Jet2 inverse(const Jet2& b) {
  const double i = 1 / b.v, i2 = i * i;
  return {i, -b.g * i2, -b.h * i2 + 2 * i2 * i * b.g * b.g.transpose()};
}
inline Jet2 operator/(const Jet2& a, const Jet2& b) { return a * inverse(b); }

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
