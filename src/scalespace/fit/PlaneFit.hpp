#pragma once
// Baseline estimators of Sec. 1.4.3 built on the weighted covariance (Eq. 1.1 with the APSS
// weights of Eq. 1.6): "Plane" (weighted PCA plane) and "Mean" (weighted barycentre + averaged
// normals, MeanFit.hpp). Both estimate H = 8 d / t^2 from the signed distance d of x to the fitted
// plane (Sec. 1.4.3: the normal displacement is H t^2 / 8 + o(t^2) under this kernel), with the
// sign chosen so that a sphere with outward normals has H > 0 (docs/THESIS_NOTES.md, sign
// convention).
// They have no principal curvatures: the fits report kMax = kMin = H (umbilic, like W1) and an
// arbitrary orthonormal tangent pair (tangentBasis of the normal) as directions.
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

/// Weighted barycentre and covariance of the neighbours of x, in the frame centred at x.
struct WeightedCovariance {
  int count = 0;  // neighbours with non-zero weight
  double weightSum = 0;
  Vec3 mean = Vec3::Zero();  // relative to x
  Mat3 covariance = Mat3::Zero();
  Vec3 meanNormal = Vec3::Zero();  // weighted sum of the input normals (not normalised)
  bool hasNormals = false;
};
WeightedCovariance weightedCovariance(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                                      const SurfaceSamples& samples);

/// PCA frame of a covariance: normal = eigenvector of the smallest eigenvalue, oriented along
/// meanNormal when the samples have normals; e1, e2 the other eigenvectors (e1 x e2 = normal).
struct PcaFrame {
  bool valid = false;
  Vec3 normal = Vec3::Zero(), e1 = Vec3::Zero(), e2 = Vec3::Zero();
};
PcaFrame pcaFrame(const WeightedCovariance& cov);

/// Plane estimator (one fit at x; LocalFit fields in the frame of x's coordinates).
LocalFit fitPlane(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                  const SurfaceSamples& samples, int minNeighbors);

}  // namespace scalespace
