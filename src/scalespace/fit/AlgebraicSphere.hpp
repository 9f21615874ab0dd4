#pragma once
// The algebraic sphere f_u(y) = u_c + u_l . y + u_q |y|^2 (Eq. 1.3), with y measured from the
// sphere's frame origin: the evaluation point x of the fit (docs/THESIS_NOTES.md, frame centred at
// the evaluation point). Sign convention (same file): fitted to outward normals, grad f points
// outwards, u_q = 1/(2r) > 0 on a sphere of radius r, and the curvature 2 u_q / sqrt(Delta)
// (Eq. 1.32) is +1/r.
#include <cmath>

#include "scalespace/core/Types.hpp"

namespace scalespace {

struct AlgebraicSphere {
  double uc = 0;
  Vec3 ul = Vec3::Zero();
  double uq = 0;

  double value(const Vec3& y) const { return uc + ul.dot(y) + uq * y.squaredNorm(); }
  /// Gradient with constant parameters (Eq. 1.29).
  Vec3 gradient(const Vec3& y) const { return ul + 2 * uq * y; }
  /// Discriminant / Pratt norm Delta = |u_l|^2 - 4 u_q u_c (Eq. 1.11).
  double discriminant() const { return ul.squaredNorm() - 4 * uq * uc; }
  /// A surface exists only for Delta > 0 with finite parameters (Eq. 1.11; docs/THESIS_NOTES.md).
  bool isValid() const {
    const double d = discriminant();
    return std::isfinite(uc) && std::isfinite(uq) && ul.allFinite() && std::isfinite(d) && d > 0;
  }
  /// True when the sphere is numerically a plane at support size t (|u_q| t negligible w.r.t.
  /// |u_l|): the centre and radius are then meaningless.
  bool isPlane(double t) const { return std::abs(uq) * t <= 1e-12 * ul.norm(); }
  /// Centre -u_l / (2 u_q) and radius sqrt(Delta) / (2 |u_q|) (only when !isPlane).
  Vec3 center() const { return -ul / (2 * uq); }
  double radius() const { return std::sqrt(discriminant()) / (2 * std::abs(uq)); }

  /// Projection of y onto the zero set along the gradient (Eq. 1.10). Both branches of Eq. 1.10
  /// are computed by one cancellation-free form: since |g|^2 - Delta = 4 u_q f(y),
  /// (|g| - sqrt(Delta)) / (2 u_q |g|) = 2 f / (|g| (|g| + sqrt(Delta))), which is exactly the
  /// plane branch f/|g|^2 when u_q = 0 (|g| = sqrt(Delta)) and stays accurate when u_q -> 0.
  Vec3 project(const Vec3& y) const {
    const Vec3 g = gradient(y);
    const double gn = g.norm();
    const double sd = std::sqrt(std::max(discriminant(), 0.0));
    if (!(gn > 0)) return y;
    return y - (2 * value(y) / (gn * (gn + sd))) * g;
  }

  /// GLS parameters (Mellado 2012) divided by sqrt(Delta) (Sec. 1.3.2): tau = u_c/sqrt(Delta)
  /// (signed distance of the frame origin), eta = u_l/sqrt(Delta), kappa = 2 u_q/sqrt(Delta)
  /// (curvature of the sphere, Eq. 1.32).
  double tau() const { return uc / std::sqrt(discriminant()); }
  Vec3 eta() const { return ul / std::sqrt(discriminant()); }
  double kappa() const { return 2 * uq / std::sqrt(discriminant()); }

  /// The same sphere in a frame whose origin is shifted by `shift` (y_new = y_old - shift).
  AlgebraicSphere translated(const Vec3& shift) const {
    AlgebraicSphere s;
    s.uc = value(shift);
    s.ul = gradient(shift);
    s.uq = uq;
    return s;
  }
};

}  // namespace scalespace
