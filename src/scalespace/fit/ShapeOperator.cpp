#include "scalespace/fit/ShapeOperator.hpp"

#include <Eigen/Eigenvalues>
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
  W = 0.5 * (W + W.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(W);  // ascending eigenvalues
  if (eig.info() != Eigen::Success) return pc;
  pc.kMin = eig.eigenvalues()(0);
  pc.kMax = eig.eigenvalues()(1);
  pc.mean = 0.5 * (pc.kMax + pc.kMin);
  pc.dirMin = (P * eig.eigenvectors().col(0)).normalized();
  pc.dirMax = n.cross(pc.dirMin);  // exactly orthogonal, unit
  if (pc.dirMax.dot(P * eig.eigenvectors().col(1)) < 0) pc.dirMax = -pc.dirMax;
  pc.normal = n;
  pc.valid = std::isfinite(pc.kMax) && std::isfinite(pc.kMin);
  if (!pc.valid) pc = PrincipalCurvatures{};
  return pc;
}

}  // namespace scalespace
