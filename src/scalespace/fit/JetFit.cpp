#include "scalespace/fit/JetFit.hpp"

#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace scalespace {
namespace {
using Kernel = CGAL::Simple_cartesian<double>;
using Fitting = CGAL::Monge_via_jet_fitting<Kernel>;
using CgalPoint = Kernel::Point_3;
Vec3 toVec(const Kernel::Vector_3& v) { return Vec3(v.x(), v.y(), v.z()); }
Vec3 toVec(const CgalPoint& p) { return Vec3(p.x(), p.y(), p.z()); }
}  // namespace

LocalFit fitJet(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                const SurfaceSamples& samples, int minNeighbors) {
  LocalFit fit;
  const double t2 = t * t;
  std::vector<CgalPoint> pts;
  pts.reserve(nbrs.size());
  std::size_t nearest = 0;
  double nearestD = 1e300;
  Vec3 meanNormal = Vec3::Zero();
  for (const Neighbor& nb : nbrs) {
    if (!(nb.distSq < t2)) continue;
    // Coordinates relative to x (better conditioned; CGAL also recentres internally).
    const Vec3 q = samples.positions[nb.index] - x;
    if (nb.distSq < nearestD) {
      nearestD = nb.distSq;
      nearest = pts.size();
    }
    pts.emplace_back(q.x(), q.y(), q.z());
    if (!samples.normals.empty()) meanNormal += samples.normals[nb.index];
  }
  fit.neighbors = static_cast<int>(pts.size());
  if (fit.neighbors < std::max(minNeighbors, 6)) return fit;  // 6 coefficients (degree 2)
  // CGAL's PCA and SVD read uninitialised values (and may crash) when the points do not span a
  // surface: refuse neighbourhoods whose covariance has a second eigenvalue ~0 (all points
  // identical or colinear); they are invalid fits, like any other degenerate neighbourhood.
  Vec3 mean = Vec3::Zero();
  for (const CgalPoint& p : pts) mean += toVec(p);
  mean /= double(pts.size());
  Mat3 cov = Mat3::Zero();
  for (const CgalPoint& p : pts) {
    const Vec3 d = toVec(p) - mean;
    cov.noalias() += d * d.transpose();
  }
  cov /= double(pts.size());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()[1] > 1e-12 * t2)) return fit;
  std::swap(pts[0], pts[nearest]);
  try {
    Fitting fitter;
    const Fitting::Monge_form m = fitter(pts.begin(), pts.end(), 2, 2);
    Vec3 n = toVec(m.normal_direction());
    double k1 = m.principal_curvatures(0), k2 = m.principal_curvatures(1);
    Vec3 d1 = toVec(m.maximal_principal_direction()), d2 = toVec(m.minimal_principal_direction());
    // CGAL's Monge form z = (k1 x^2 + k2 y^2)/2 + ... along n: a surface bending away from n has
    // negative k. Our convention is the opposite (positive away from the outward normal).
    if (meanNormal.squaredNorm() > 0 && n.dot(meanNormal) < 0) {
      n = -n;  // flipping n flips the sign of CGAL's curvatures, which matches ours already
    } else {
      k1 = -k1;
      k2 = -k2;
    }
    if (k1 < k2) {
      std::swap(k1, k2);
      std::swap(d1, d2);
    }
    fit.normal = n.normalized();
    fit.kMax = k1;
    fit.kMin = k2;
    fit.meanCurvature = 0.5 * (k1 + k2);
    fit.dirMax = d1.normalized();
    fit.dirMin = d2.normalized();
    fit.projection = x + toVec(m.origin());
    fit.valid = std::isfinite(k1) && std::isfinite(k2) && fit.normal.allFinite() &&
                fit.dirMax.allFinite() && fit.dirMin.allFinite() && fit.projection.allFinite();
  } catch (...) {
    fit.valid = false;  // CGAL precondition failures (degenerate neighbourhoods) are per-point
  }
  if (!fit.valid) markInvalid(fit);
  return fit;
}

}  // namespace scalespace
