#pragma once
// The total least squares plane through a set of points (the smallest eigenvector of their
// covariance, unweighted), and coordinates in it: what the planes flatten their regions with and
// what the sensor-noise estimate (scales/PointNoise.hpp) fits to each neighbourhood.
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

using Vec2 = Eigen::Vector2d;

struct PlaneFit {
  Vec3 normal = Vec3::UnitZ();  // unit; the plane is {x : normal . x = offset}
  double offset = 0.0;
  double rms = 0.0;  // root mean square of the point-to-plane distances
  Vec3 centroid = Vec3::Zero();
  Vec3 axisU = Vec3::UnitX(), axisV = Vec3::UnitY();  // in-plane orthonormal basis
  bool valid = false;                                 // false for fewer than 3 points
};

/// Total least squares plane through positions[indices] (smallest eigenvector of the covariance).
PlaneFit fitPlane(const std::vector<Vec3>& positions, const std::vector<Index>& indices);

/// Coordinates of positions[indices] in the plane's (axisU, axisV) basis around its centroid.
std::vector<Vec2> projectOnPlane(const PlaneFit& plane, const std::vector<Vec3>& positions,
                                 const std::vector<Index>& indices);

/// Back to 3D: centroid + x axisU + y axisV.
Vec3 liftFromPlane(const PlaneFit& plane, const Vec2& p);

}  // namespace scalespace
