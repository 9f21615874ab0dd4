#include "scalespace/fit/PlaneFit.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "scalespace/fit/ShapeOperator.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

WeightedCovariance weightedCovariance(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                                      const SurfaceSamples& samples) {
  WeightedCovariance c;
  const WeightKernel kernel(t);
  c.hasNormals = !samples.normals.empty();
  Vec3 sum = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (const Neighbor& nb : nbrs) {
    const double w = WeightKernel::value(kernel.ratio(nb.distSq));
    if (!(w > 0)) continue;
    const Vec3 q = samples.positions[nb.index] - x;
    ++c.count;
    c.weightSum += w;
    sum += w * q;
    second.noalias() += w * q * q.transpose();
    if (c.hasNormals) c.meanNormal += w * samples.normals[nb.index];
  }
  if (c.weightSum > 0) {
    c.mean = sum / c.weightSum;
    c.covariance = second / c.weightSum - c.mean * c.mean.transpose();  // Eq. 1.1 (weighted)
  }
  return c;
}

PcaFrame pcaFrame(const WeightedCovariance& cov) {
  PcaFrame f;
  if (!(cov.weightSum > 0) || !cov.covariance.allFinite()) return f;
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov.covariance);
  if (eig.info() != Eigen::Success) return f;
  const auto& ev = eig.eigenvalues();  // ascending
  // Degenerate when the neighbours do not span a plane (all on a point or a line).
  if (!(ev(1) > 1e-14 * std::max(ev(2), 1e-300))) return f;
  f.normal = eig.eigenvectors().col(0);
  if (cov.hasNormals && f.normal.dot(cov.meanNormal) < 0) f.normal = -f.normal;
  f.e1 = eig.eigenvectors().col(2);
  f.e2 = f.normal.cross(f.e1);
  f.valid = true;
  return f;
}

LocalFit fitPlane(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                  const SurfaceSamples& samples, int minNeighbors) {
  LocalFit fit;
  const WeightedCovariance cov = weightedCovariance(x, t, nbrs, samples);
  fit.neighbors = cov.count;
  if (cov.count < minNeighbors) return fit;
  const PcaFrame frame = pcaFrame(cov);
  if (!frame.valid) return fit;
  // x is the frame origin: its signed height above the plane through the barycentre.
  const double d = -cov.mean.dot(frame.normal);
  fit.valid = true;
  fit.normal = frame.normal;
  fit.projection = x - d * frame.normal;
  fit.meanCurvature = fit.kMax = fit.kMin = 8 * d / (t * t);  // Sec. 1.4.3
  tangentBasis(fit.normal, fit.dirMax, fit.dirMin);
  return fit;
}

LocalFit fitMean(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                 const SurfaceSamples& samples, int minNeighbors) {
  LocalFit fit;
  const WeightedCovariance cov = weightedCovariance(x, t, nbrs, samples);
  fit.neighbors = cov.count;
  if (cov.count < minNeighbors || !cov.hasNormals) return fit;
  const double nn = cov.meanNormal.norm();
  if (!(nn > 0) || !std::isfinite(nn)) return fit;
  const Vec3 n = cov.meanNormal / nn;
  const double d = -cov.mean.dot(n);
  fit.valid = true;
  fit.normal = n;
  fit.projection = x - d * n;
  fit.meanCurvature = fit.kMax = fit.kMin = 8 * d / (t * t);  // Sec. 1.4.3
  tangentBasis(fit.normal, fit.dirMax, fit.dirMin);
  return fit;
}

}  // namespace scalespace
