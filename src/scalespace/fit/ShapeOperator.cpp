#include "scalespace/fit/ShapeOperator.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace scalespace {

void tangentBasis(const Vec3& n, Vec3& u, Vec3& v) {
  // Start from the axis least aligned with n so the projection is well conditioned.
  int axis = 0;
  n.cwiseAbs().minCoeff(&axis);
  const Vec3 a = Vec3::Unit(axis);
  u = (a - a.dot(n) * n).normalized();
  v = n.cross(u);
}

PrincipalCurvatures shapeOperatorCurvatures(const Vec3& gradient, const Mat3& hessian) {
  PrincipalCurvatures pc;
  const double gn = gradient.norm();
  if (!(gn > 0) || !std::isfinite(gn) || !hessian.allFinite()) return pc;
  const Vec3 n = gradient / gn;
  Vec3 u, v;
  tangentBasis(n, u, v);
  Eigen::Matrix<double, 3, 2> P;
  P.col(0) = u;
  P.col(1) = v;
  Eigen::Matrix2d W = P.transpose() * hessian * P / gn;  // Eq. 1.28
  // Closed-form eigen-decomposition of the symmetric 2 x 2 [[a, b], [b, d]] instead of Eigen's
  // iterative solver, which was a large part of this function's cost:
  // lambda = (a + d) / 2 +- hypot((a - d) / 2, b).
  const double a = W(0, 0), d = W(1, 1), b = 0.5 * (W(0, 1) + W(1, 0));
  const double half = 0.5 * (a - d);
  // sqrt, not std::hypot (slower, as it avoids overflow): curvatures squared are far from it.
  const double radius = std::sqrt(half * half + b * b);
  pc.kMax = 0.5 * (a + d) + radius;
  pc.kMin = 0.5 * (a + d) - radius;
  pc.mean = 0.5 * (a + d);
  // Eigenvector of kMax: (half + radius, b) or, equivalently, (b, radius - half); take the one
  // without cancellation. Umbilic (radius 0): any direction, u.
  Eigen::Vector2d vMax(1, 0);
  if (radius > 0) {
    vMax = half >= 0 ? Eigen::Vector2d(half + radius, b) : Eigen::Vector2d(b, radius - half);
    vMax.normalize();
  }
  const Eigen::Vector2d vMin(-vMax.y(), vMax.x());
  pc.dirMin = (P * vMin).normalized();
  pc.dirMax = n.cross(pc.dirMin);  // exactly orthogonal, unit
  if (pc.dirMax.dot(P * vMax) < 0) pc.dirMax = -pc.dirMax;
  pc.normal = n;
  pc.valid = std::isfinite(pc.kMax) && std::isfinite(pc.kMin);
  if (!pc.valid) pc = PrincipalCurvatures{};
  return pc;
}

}  // namespace scalespace
