#pragma once
// The APSS weight w_t(q) = K(|q|/t) with K(x) = (x^2 - 1)^2 for x < 1, else 0 (Eq. 1.6;
// docs/THESIS_NOTES.md, weight kernel). Written as a polynomial in r = |q|^2/t^2 so no square root
// is needed: w = (r - 1)^2.
// Spatial derivatives are taken with respect to q (the sample relative to the evaluation point);
// with q = p - x, derivatives with respect to x flip the sign of the gradient (dq/dx = -I).
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct WeightKernel {
  double t = 1;
  double invT2 = 1;  // 1/t^2

  explicit WeightKernel(double support) : t(support), invT2(1.0 / (support * support)) {}

  /// r = |q|^2/t^2; the kernel is zero for r >= 1.
  double ratio(double distSq) const { return distSq * invT2; }
  /// w = (r - 1)^2 (Eq. 1.6).
  static double value(double r) { return r < 1 ? (r - 1) * (r - 1) : 0.0; }
  /// grad_q w = 4 (r - 1) q / t^2.
  Vec3 gradient(const Vec3& q, double r) const {
    return r < 1 ? Vec3(4 * (r - 1) * invT2 * q) : Vec3::Zero();
  }
  /// hess_q w = 4 (r - 1) I / t^2 + 8 q q^T / t^4, returned as the two coefficients a, b of
  /// a I + b q q^T so callers can accumulate without forming the matrix.
  void hessianCoefficients(double r, double& a, double& b) const {
    if (r >= 1) {
      a = b = 0;
      return;
    }
    a = 4 * (r - 1) * invT2;
    b = 8 * invT2 * invT2;
  }
  Mat3 hessian(const Vec3& q, double r) const {
    double a, b;
    hessianCoefficients(r, a, b);
    return a * Mat3::Identity() + b * q * q.transpose();
  }
  /// dw/dt at fixed q: dr/dt = -2 r / t, so dw/dt = 2 (r - 1) dr/dt = -4 (r - 1) r / t.
  double scaleDerivative(double r) const { return r < 1 ? -4 * (r - 1) * r / t : 0.0; }
};

}  // namespace scalespace
