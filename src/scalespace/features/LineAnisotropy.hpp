#pragma once
// Linear anisotropy of the minimal-curvature lines around each point (Sec. 3.5.2): the covariance
// of the tangents v_i of the line vertices q_i within t of x,
//   Sigma_t(x) = sum_i (1 - tanh(nu_i)) w_t(x - q_i) v_i v_i^T        (Eq. 3.8, w_t of Eq. 1.6)
// and sigma = (lambda1 - lambda2) / (lambda1 + lambda2 + lambda3)     (Eq. 3.9).
// With the same weights each point also gets the lines' mean direction (Sigma's first
// eigenvector), normal and signed kappa1 at this scale: the region growing of Eq. 3.10 compares
// directions and normals of the scale, not the raw normals (two strands of a cable must join at a
// coarse scale), and the tubes read their radius from kappa1.
//
// (Not in the thesis.) A point only counts the vertices on its own side of the surface, those
// whose normal makes an angle below 90 degrees with the point's own normal: where two strands of
// a cable touch, or on the two sides of a thin wall, the vertices of the other side lie within t
// but belong to another sheet. Without this, the strands of a cable share their normals along the
// groove between them and grow into one region at every scale.
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/features/CurvatureLines.hpp"

namespace scalespace {

struct LineAnisotropyField {
  double scale = 0;
  /// Per point; NaN where no weighted line vertex lies within t.
  std::vector<float> sigma;
  std::vector<Vec3> direction;  // unit (sign arbitrary); zero where sigma is NaN
  std::vector<Vec3> normal;     // unit weighted mean of the vertex normals; zero where NaN
  std::vector<float> kappa1;    // weighted mean of the vertices' signed kappa1; 0 where NaN
};

/// Eq. 3.8-3.9 at the points `positions` (oriented `normals`, one per point) from the vertices of
/// `lines` at scale t. Parallel; the result does not depend on the thread count. Throws Cancelled
/// on request.
LineAnisotropyField lineAnisotropy(const std::vector<Vec3>& positions,
                                   const std::vector<Vec3>& normals,
                                   const std::vector<const CurvatureLine*>& lines, double t,
                                   const ProgressCallback& progress = {});

}  // namespace scalespace
