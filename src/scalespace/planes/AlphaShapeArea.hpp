#pragma once
// Area and outline of the regularized 2D alpha shape of planar points (the region filter of
// Sec. 2.3.1 and the component outlines), plus the least-squares plane used to flatten them.
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

using Vec2 = Eigen::Vector2d;

struct AlphaShape {
  double area = 0.0;  // total area of the regular (interior) faces
  /// Closed boundary loops (first vertex not repeated), interior on the left. Only filled when
  /// asked for.
  std::vector<std::vector<Vec2>> outlines;
};

/// Regularized alpha shape (CGAL::Alpha_shape_2, REGULARIZED mode). `alpha` is CGAL's alpha, a
/// SQUARED radius (docs/THESIS_NOTES.md: radius 2t -> alpha = (2t)^2). Fewer than 3 points:
/// area 0.
AlphaShape alphaShape2(const std::vector<Vec2>& points, double alpha, bool withOutlines = false);

/// alphaShape2(points, alpha).area >= minArea, decided without triangulating every point when
/// the triangles near the middle of the set already cover minArea (the region filter of
/// Sec. 2.3.1 only needs this answer; large regions pass it from a small patch).
bool alphaShapeAreaAtLeast(const std::vector<Vec2>& points, double alpha, double minArea);

/// A lower bound of alphaShape2(points, alpha).area from the alpha shape of a subset (one point
/// per grid cell of side `cell`): the subset's area minus, for each of its boundary edges, the
/// circular segment of radius sqrt(alpha) on that edge (AlphaShapeArea.cpp gives the proof).
/// Nearly tight for dense points when cell << sqrt(alpha); 0 for fewer than 3 subset points.
double alphaShapeAreaLowerBound(const std::vector<Vec2>& points, double alpha, double cell);

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
