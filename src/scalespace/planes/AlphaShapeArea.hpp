#pragma once
// Area and outline of the regularized 2D alpha shape of planar points (the region filter of
// Sec. 2.3.1 and the component outlines); the least-squares plane that flattens them is in
// fit/PointSetPlane.hpp.
#include <vector>

#include "scalespace/core/Types.hpp"
#include "scalespace/fit/PointSetPlane.hpp"

namespace scalespace {

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

}  // namespace scalespace
