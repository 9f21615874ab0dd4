#include "scalespace/core/NormalEstimation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scalespace/core/SpatialOrder.hpp"

namespace scalespace {
namespace {

struct LocalNormal {
  Vec3 normal = Vec3::UnitZ();
  double surfaceVariation = 1.0 / 3.0;
  double rms = 0.0;  // of the neighbours' distances to the plane
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
  r.rms = std::sqrt(lambda(0));
  r.valid = true;
  return r;
}

// The planes a sheet normal chooses from pass through the point and two of its nearest this many
// neighbours (120 pairs): a large k or radius costs pairs x neighbours, not neighbours cubed.
constexpr std::size_t kSheetGenerators = 16;

// NormalEstimationOptions::sheetTolerance: the plane through the point and two neighbours that the
// most neighbours lie within `band` of (ties: the smaller sum of their distances), refitted to
// them. Pairs whose offsets are nearly parallel (sine below 0.3) span no plane. `fallback` when no
// pair does or the inliers are degenerate. `nbrs` is reordered (nearest first).
Vec3 sheetNormal(const std::vector<Vec3>& points, std::size_t i, std::vector<Neighbor>& nbrs,
                 double band, double colinearity, const Vec3& fallback,
                 std::vector<Neighbor>& inliers) {
  const Vec3& p = points[i];
  const std::size_t generators = std::min(nbrs.size(), kSheetGenerators + 1);  // + the point
  const auto nearer = [](const Neighbor& x, const Neighbor& y) {
    return x.distSq < y.distSq || (x.distSq == y.distSq && x.index < y.index);
  };
  std::partial_sort(nbrs.begin(), nbrs.begin() + std::ptrdiff_t(generators), nbrs.end(), nearer);
  std::size_t bestCount = 0;
  double bestSum = 0;
  Vec3 best = fallback;
  for (std::size_t a = 0; a < generators; ++a) {
    if (nbrs[a].index == i) continue;
    const Vec3 u = points[nbrs[a].index] - p;
    for (std::size_t b = a + 1; b < generators; ++b) {
      if (nbrs[b].index == i) continue;
      const Vec3 v = points[nbrs[b].index] - p;
      Vec3 normal = u.cross(v);
      const double norm = normal.norm();
      if (!(norm > 0.3 * u.norm() * v.norm())) continue;
      normal /= norm;
      std::size_t count = 0;
      double sum = 0;
      for (const Neighbor& m : nbrs) {
        const double d = std::abs(normal.dot(points[m.index] - p));
        if (d <= band) ++count, sum += d;
      }
      if (count > bestCount || (count == bestCount && sum < bestSum))
        bestCount = count, bestSum = sum, best = normal;
    }
  }
  if (bestCount == 0) return fallback;
  inliers.clear();
  for (const Neighbor& m : nbrs)
    if (std::abs(best.dot(points[m.index] - p)) <= band) inliers.push_back(m);
  const LocalNormal refit = fitPlane(points, inliers, colinearity);
  return refit.valid ? refit.normal : best;
}

/// NormalEstimationOptions::maxK: the smallest k (k, 2k, 4k, ... up to maxK) whose normals
/// differ from those of twice as many neighbours by at most maxNoiseAngleDegrees, median over
/// about 20,000 points spread through the cloud (every stride-th in index order; the same for any
/// thread count).
std::size_t noiseAdaptedK(const std::vector<Vec3>& points, const SpatialIndex& index,
                          const NormalEstimationOptions& options) {
  std::size_t k = options.k;
  if (options.radius > 0.0 || options.maxK <= k) return k;
  const std::size_t n = points.size();
  const std::size_t stride = std::max<std::size_t>(1, n / 20000);
  std::vector<std::size_t> sample;
  for (std::size_t i = 0; i < n; i += stride) sample.push_back(i);
  const double maxCos = std::cos(options.maxNoiseAngleDegrees * M_PI / 180.0);
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  const auto normalsAt = [&](std::size_t count, std::vector<Vec3>& normals,
                             std::vector<std::uint8_t>& valid) {
    normals.assign(sample.size(), Vec3::Zero());
    valid.assign(sample.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sample.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::vector<Neighbor>& nbrs = scratch.local();
                        for (std::size_t s = range.begin(); s != range.end(); ++s) {
                          index.knnSearch(points[sample[s]], count, nbrs);
                          const LocalNormal r = fitPlane(points, nbrs, options.colinearity);
                          normals[s] = r.normal;
                          valid[s] = r.valid ? 1 : 0;
                        }
                      });
  };
  std::vector<Vec3> current, doubled;
  std::vector<std::uint8_t> currentValid, doubledValid;
  normalsAt(k, current, currentValid);
  while (2 * k <= options.maxK && 2 * k <= std::min(n, kMaxNeighborCount)) {
    normalsAt(2 * k, doubled, doubledValid);
    std::vector<double> cosines;
    for (std::size_t s = 0; s < sample.size(); ++s)
      if (currentValid[s] && doubledValid[s])
        cosines.push_back(std::abs(current[s].dot(doubled[s])));
    if (cosines.empty()) break;
    // The median angle is above the bound when the median cosine is below its cosine.
    std::nth_element(cosines.begin(), cosines.begin() + std::ptrdiff_t(cosines.size() / 2),
                     cosines.end());
    if (cosines[cosines.size() / 2] >= maxCos) break;
    k *= 2;
    current.swap(doubled);
    currentValid.swap(doubledValid);
  }
  return k;
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
  if (!(options.sheetTolerance >= 0) || !std::isfinite(options.sheetTolerance))
    throw OptionError("NormalEstimationOptions::sheetTolerance must be finite and >= 0");
  if (!(options.sheetNoiseFactor >= 0) || !std::isfinite(options.sheetNoiseFactor))
    throw OptionError("NormalEstimationOptions::sheetNoiseFactor must be finite and >= 0");
  if (!(options.maxNoiseAngleDegrees > 0) || !(options.maxNoiseAngleDegrees < 90))
    throw OptionError("NormalEstimationOptions::maxNoiseAngleDegrees must be in (0, 90), got " +
                      std::to_string(options.maxNoiseAngleDegrees));
  const std::size_t n = points.size();
  NormalEstimationResult result;
  result.k = options.radius > 0.0 ? 0 : noiseAdaptedK(points, index, options);
  result.normals.assign(n, Vec3::UnitZ());
  result.surfaceVariation.assign(n, 1.0 / 3.0);
  result.valid.assign(n, 0);

  // Queries along the Morton curve walk the same branches of the index one after another (a
  // scan's points may come in any order); each point's result is its own, so nothing changes.
  const std::vector<Index> order = spatialOrder(points);
  const bool sheets = options.sheetTolerance > 0;
  ProgressTracker tracker(progress, "normal estimation", sheets ? 2 * n : n);
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch, inlierScratch;
  const auto neighbours = [&](std::size_t i, std::vector<Neighbor>& nbrs) {
    if (options.radius > 0.0)
      index.radiusSearch(points[i], options.radius, nbrs);
    else
      index.knnSearch(points[i], result.k, nbrs);
  };
  std::vector<double> rms(n, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (tracker.cancelled()) return;
                      std::vector<Neighbor>& nbrs = scratch.local();
                      for (std::size_t v = range.begin(); v != range.end(); ++v) {
                        const std::size_t i = order[v];
                        neighbours(i, nbrs);
                        const LocalNormal r = fitPlane(points, nbrs, options.colinearity);
                        result.normals[i] = r.normal;
                        result.surfaceVariation[i] = r.surfaceVariation;
                        result.valid[i] = r.valid ? 1 : 0;
                        rms[i] = r.rms;
                      }
                      tracker.advance(range.size());
                    });
  for (std::uint8_t v : result.valid) result.invalidCount += v ? 0 : 1;
  std::vector<double> validRms;
  validRms.reserve(n - result.invalidCount);
  for (std::size_t i = 0; i < n; ++i)
    if (result.valid[i]) validRms.push_back(rms[i]);
  if (!validRms.empty()) {
    std::nth_element(validRms.begin(), validRms.begin() + validRms.size() / 2, validRms.end());
    result.noiseRms = validRms[validRms.size() / 2];
  }
  if (sheets) {
    result.planeNormals = result.normals;
    const double noiseBand = options.sheetNoiseFactor * result.noiseRms;
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1024),
        [&](const tbb::blocked_range<std::size_t>& range) {
          if (tracker.cancelled()) return;
          std::vector<Neighbor>& nbrs = scratch.local();
          for (std::size_t v = range.begin(); v != range.end(); ++v) {
            const std::size_t i = order[v];
            if (!result.valid[i]) continue;
            neighbours(i, nbrs);
            double farthest = 0;
            for (const Neighbor& m : nbrs) farthest = std::max(farthest, m.distSq);
            const double band = std::max(options.sheetTolerance * std::sqrt(farthest), noiseBand);
            // A neighbourhood its PCA plane already holds within the band (a smooth surface, a
            // curved one included) keeps the PCA normal: the plane with the most inliers there is
            // one tangent off the point, tilted by the curvature (kitten.xyz: 1.4% of the normals
            // more than 20 degrees off, against 0.04% with PCA).
            if (rms[i] <= band) continue;
            result.normals[i] = sheetNormal(points, i, nbrs, band, options.colinearity,
                                            result.normals[i], inlierScratch.local());
          }
          tracker.advance(range.size());
        });
  }
  tracker.finish();
  return result;
}

NormalEstimationResult estimateNormals(const std::vector<Vec3>& points,
                                       const NormalEstimationOptions& options,
                                       const ProgressCallback& progress) {
  const auto index = makeSpatialIndex(points);
  return estimateNormals(points, *index, options, progress);
}

}  // namespace scalespace
