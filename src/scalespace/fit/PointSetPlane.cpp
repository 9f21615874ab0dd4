#include "scalespace/fit/PointSetPlane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace scalespace {

PlaneFit fitPlane(const std::vector<Vec3>& positions, const std::vector<Index>& indices) {
  PlaneFit fit;
  if (indices.size() < 3) return fit;
  Vec3 c = Vec3::Zero();
  for (Index i : indices) c += positions[i];
  c /= double(indices.size());
  Mat3 cov = Mat3::Zero();
  for (Index i : indices) {
    const Vec3 d = positions[i] - c;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  fit.centroid = c;
  fit.normal = eig.eigenvectors().col(0).normalized();
  fit.axisU = eig.eigenvectors().col(2).normalized();
  fit.axisV = fit.normal.cross(fit.axisU);
  fit.offset = fit.normal.dot(c);
  // The smallest eigenvalue is the sum of squared distances to the plane.
  fit.rms = std::sqrt(std::max(0.0, eig.eigenvalues()(0)) / double(indices.size()));
  fit.valid = true;
  return fit;
}

std::vector<Vec2> projectOnPlane(const PlaneFit& plane, const std::vector<Vec3>& positions,
                                 const std::vector<Index>& indices) {
  std::vector<Vec2> out;
  out.reserve(indices.size());
  for (Index i : indices) {
    const Vec3 d = positions[i] - plane.centroid;
    out.emplace_back(d.dot(plane.axisU), d.dot(plane.axisV));
  }
  return out;
}

Vec3 liftFromPlane(const PlaneFit& plane, const Vec2& p) {
  return plane.centroid + p.x() * plane.axisU + p.y() * plane.axisV;
}

}  // namespace scalespace
