#include "scalespace/core/NormalEstimation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <vector>

#include "scalespace/core/SpatialOrder.hpp"

namespace scalespace {
namespace {

struct LocalNormal {
  Vec3 normal = Vec3::UnitZ();
  double surfaceVariation = 1.0 / 3.0;
  bool valid = false;
};

LocalNormal fitPlane(const std::vector<Vec3>& points, const std::vector<Neighbor>& nbrs,
                     double colinearity) {
  LocalNormal r;
  if (nbrs.size() < 3) return r;
  // Centroid first, then the covariance of the centred points: the two-pass form avoids the
  // cancellation of E[pp^T] - E[p]E[p]^T on points far from the origin.
  Vec3 centroid = Vec3::Zero();
  for (const Neighbor& n : nbrs) centroid += points[n.index];
  centroid /= double(nbrs.size());
  Mat3 cov = Mat3::Zero();
  for (const Neighbor& n : nbrs) {
    const Vec3 d = points[n.index] - centroid;
    cov.noalias() += d * d.transpose();
  }
  cov /= double(nbrs.size());
  if (!cov.allFinite()) return r;
  // Iterative (tridiagonal QR) solver rather than computeDirect(): the closed form loses the
  // small eigenvector when eigenvalues are close, which is exactly the nearly planar case.
  Eigen::SelfAdjointEigenSolver<Mat3> solver(cov);
  if (solver.info() != Eigen::Success) return r;
  const Vec3 lambda = solver.eigenvalues().cwiseMax(0.0);  // ascending
  const Vec3 normal = solver.eigenvectors().col(0);
  // All-identical points give lambda2 == 0; colinear ones lambda1 ~ 0: the normal is then any
  // direction orthogonal to the line, so it is kept (unit) but flagged.
  const double sum = lambda.sum();
  if (!(lambda(2) > 0.0) || lambda(1) <= colinearity * lambda(2) || !normal.allFinite()) {
    if (normal.allFinite() && normal.norm() > 0.5) r.normal = normal.normalized();
    return r;
  }
  r.normal = normal.normalized();
  r.surfaceVariation = lambda(0) / sum;
  r.valid = true;
  return r;
}

}  // namespace

NormalEstimationResult estimateNormals(const std::vector<Vec3>& points, const SpatialIndex& index,
                                       const NormalEstimationOptions& options,
                                       const ProgressCallback& progress) {
  if (!(options.radius >= 0.0) || !std::isfinite(options.radius))
    throw OptionError("normal estimation radius must be finite and >= 0 (0 = use k), got " +
                      std::to_string(options.radius));
  if (options.radius == 0.0 && (options.k < 3 || options.k > kMaxNeighborCount))
    throw OptionError("NormalEstimationOptions::k must be in [3, " +
                      std::to_string(kMaxNeighborCount) + "] neighbours, got " +
                      std::to_string(options.k));
  if (index.size() != points.size())
    throw OptionError("estimateNormals: the index holds " + std::to_string(index.size()) +
                      " points but " + std::to_string(points.size()) + " were given");
  const std::size_t n = points.size();
  NormalEstimationResult result;
  result.normals.assign(n, Vec3::UnitZ());
  result.surfaceVariation.assign(n, 1.0 / 3.0);
  result.valid.assign(n, 0);

  // Queries along the Morton curve walk the same branches of the index one after another (a
  // scan's points may come in any order); each point's result is its own, so nothing changes.
  const std::vector<Index> order = spatialOrder(points);
  ProgressTracker tracker(progress, "normal estimation", n);
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (tracker.cancelled()) return;
                      std::vector<Neighbor>& nbrs = scratch.local();
                      for (std::size_t v = range.begin(); v != range.end(); ++v) {
                        const std::size_t i = order[v];
                        if (options.radius > 0.0)
                          index.radiusSearch(points[i], options.radius, nbrs);
                        else
                          index.knnSearch(points[i], options.k, nbrs);
                        const LocalNormal r = fitPlane(points, nbrs, options.colinearity);
                        result.normals[i] = r.normal;
                        result.surfaceVariation[i] = r.surfaceVariation;
                        result.valid[i] = r.valid ? 1 : 0;
                      }
                      tracker.advance(range.size());
                    });
  tracker.finish();
  for (std::uint8_t v : result.valid) result.invalidCount += v ? 0 : 1;
  return result;
}

NormalEstimationResult estimateNormals(const std::vector<Vec3>& points,
                                       const NormalEstimationOptions& options,
                                       const ProgressCallback& progress) {
  const auto index = makeSpatialIndex(points);
  return estimateNormals(points, *index, options, progress);
}

}  // namespace scalespace
