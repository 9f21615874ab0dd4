#include "scalespace/param/ScaleSpaceFlattening.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/fit/FitPoints.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The fewest samples a pyramid level keeps (Sec. 1.5.2 decimates without a floor): a few
/// times the neighbours a fit needs, so every point of a shrunken cloud still has a fit.
constexpr std::size_t kMinSamples = 64;

double diagonalOf(const std::vector<Vec3>& positions) {
  Vec3 lo = positions.front(), hi = positions.front();
  for (const Vec3& p : positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// The points' spread across their main direction over the spread along it (square roots of the
// covariance's two largest eigenvalues): 0 for collinear points, which no surface holds.
double crossSpreadRatio(const std::vector<Vec3>& positions) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : positions) mean += p;
  mean /= double(positions.size());
  Mat3 covariance = Mat3::Zero();
  for (const Vec3& p : positions) covariance += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(covariance);
  const Vec3 ev = eig.eigenvalues();  // increasing
  return ev(2) > 0 ? std::sqrt(std::max(0.0, ev(1)) / ev(2)) : 0.0;
}

}  // namespace

FitOptions flatteningFitOptions() {
  FitOptions fit;
  fit.estimator = EstimatorKind::W1;
  fit.mls = true;
  fit.mlsMaxSteps = 10;
  fit.mlsTolerance = 0.01;
  return fit;
}

void validateFlatteningOptions(const FlatteningOptions& options) {
  if (options.scaleCount < 2 || options.scaleCount > kMaxScaleCount)
    throw OptionError("FlatteningOptions::scaleCount must be in [2, " +
                      std::to_string(kMaxScaleCount) + "], got " +
                      std::to_string(options.scaleCount));
  if (options.K < 1 || std::size_t(options.K) > kMaxNeighborCount)
    throw OptionError("FlatteningOptions::K must be in [1, " + std::to_string(kMaxNeighborCount) +
                      "]");
  if (!std::isfinite(options.tMax) || options.tMax < 0)
    throw OptionError("FlatteningOptions::tMax must be finite and >= 0 (0: the diagonal)");
  validatePyramidAlpha(options.alpha);
  validateFitOptions(options.fit);
  if (!options.fit.mls)
    throw OptionError("FlatteningOptions::fit.mls must be on: each step is a projection");
}

AlgebraicSphere fitGlobalSphere(const std::vector<Vec3>& positions,
                                const std::vector<Vec3>& normals, Vec3& origin) {
  const std::size_t n = positions.size();
  if (n < 3 || normals.size() != n)
    throw OptionError("the global sphere fit needs at least 3 points with normals");
  origin = Vec3::Zero();
  for (const Vec3& p : positions) origin += p;
  origin /= double(n);
  // Constant weights (Sec. 4.3): the sums of Eq. 1.7-1.9 with w = 1, in input order (the same
  // sum for any thread count).
  double sums[9] = {};
  double extent = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 q = positions[i] - origin;
    const Vec3& m = normals[i];
    const double item[9] = {1.0,   q.x(), q.y(),    q.z(),          m.x(),
                            m.y(), m.z(), q.dot(m), q.squaredNorm()};
    for (int k = 0; k < 9; ++k) sums[k] += item[k];
    extent = std::max(extent, q.norm());
  }
  AlgebraicSphere sphere;
  if (sphereFromSums(sums, int(std::min<std::size_t>(n, 1u << 30)), std::max(extent, 1e-300), 3,
                     sphere))
    return sphere;
  // No sphere (Delta <= 0, degenerate sums): the least-squares plane through the centroid,
  // oriented like the mean normal.
  Mat3 cov = Mat3::Zero();
  Vec3 meanNormal = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 q = positions[i] - origin;
    cov += q * q.transpose();
    meanNormal += normals[i];
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  Vec3 normal = eig.eigenvectors().col(0);
  if (normal.dot(meanNormal) < 0) normal = -normal;
  sphere.uc = 0;
  sphere.ul = normal;
  sphere.uq = 0;
  return sphere;
}

FlatteningResult flattenScaleSpace(const std::vector<Vec3>& inputPositions,
                                   const std::vector<Vec3>& inputNormals,
                                   const FlatteningOptions& options,
                                   const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  validateFlatteningOptions(options);
  const std::size_t n = inputPositions.size();
  if (inputNormals.size() != n)
    throw OptionError("the flattening needs one oriented normal per point");
  if (n < std::size_t(options.K) + 1)
    throw OptionError("the flattening needs more than FlatteningOptions::K = " +
                      std::to_string(options.K) + " points, got " + std::to_string(n));
  ThreadLimit limit(options.threads);

  FlatteningResult result;
  result.diagonal = diagonalOf(inputPositions);
  if (!(result.diagonal > 0))
    throw OptionError("the flattening needs points that are not all equal");
  // A line has no surface to flow onto: the map would be a curve's, silently (a strip a thousand
  // times longer than wide is one at every scale the flattening visits).
  if (const double ratio = crossSpreadRatio(inputPositions); ratio < 1e-3) {
    // Two small clumps far apart (two scans in different frames) read the same way.
    char text[200];
    std::snprintf(text, sizeof text,
                  "the flattening needs points spread over a surface; these lie along a line, on "
                  "it or in clumps far apart (their spread across it is %.3g of their spread along "
                  "it)",
                  ratio);
    throw OptionError(text);
  }
  result.tMax = options.tMax > 0 ? options.tMax : result.diagonal;

  // Points along a Morton curve of the input: they move coherently, so the order stays a good
  // walk for the fits (QueryWalk::AsGiven) at every step.
  const std::vector<Index> order = spatialOrder(inputPositions);
  std::vector<Vec3> current = applyPermutation(inputPositions, order);
  std::vector<Vec3> currentNormals = applyPermutation(inputNormals, order);
  // The fits read unit normals (a longer normal weighs more in Eq. 1.7-1.9).
  for (Vec3& m : currentNormals) {
    if (!m.allFinite() || !(m.squaredNorm() > 0))
      throw OptionError("the flattening needs finite non-zero normals at every point");
    m.normalize();
  }

  // Per-point first scale: the point's K-NN distance (the heterogeneous series of Sec. 1.5.1).
  std::vector<double> tMin;
  {
    const auto index = makeSpatialIndex(current);
    tMin = knnRadii(current, *index, options.K);
  }
  for (double& t : tMin) t = std::min(t, result.tMax);
  result.medianTMin = lowerMedian(tMin);

  const std::size_t m = std::size_t(options.scaleCount);
  std::vector<Vec3> next(n), nextNormals(n);
  std::vector<std::uint16_t> failed(n, 0);
  std::vector<std::uint8_t> failedNow(n, 0);
  std::vector<double> scales(n), separations(n);
  std::vector<Index> members(n);
  for (std::size_t k = 0; k < n; ++k) members[k] = Index(k);
  FitPointsOptions walk;
  walk.fit = options.fit;
  walk.walk = QueryWalk::AsGiven;

  for (std::size_t j = 0; j < m; ++j) {
    const auto t0 = std::chrono::steady_clock::now();
    // Eq. 1.39 per point: t_j = t_min + j (t_max - t_min) / (M - 1), j = 0..M-1.
    const double f = double(j) / double(m - 1);
    for (std::size_t k = 0; k < n; ++k) {
      scales[k] = tMin[k] + f * (result.tMax - tMin[k]);
      separations[k] = poissonDiskSeparation(options.alpha, scales[k]);
    }
    // The pyramid level of this step, drawn from the previous level on the moved points. A
    // cloud that shrank as it flowed (thin parts merging, a rounded body) would be decimated to
    // a handful of samples at the largest scales, too few for any fit: below kMinSamples the
    // previous level is kept.
    if (options.alpha > 0) {
      std::vector<Index> level = poissonDiskSampleAdaptive(current, members, separations,
                                                           pyramidLevelSeed(options.seed, j));
      if (level.size() >= std::min(members.size(), kMinSamples)) members = std::move(level);
    }
    std::vector<Vec3> samplePositions(members.size()), sampleNormals(members.size());
    for (std::size_t s = 0; s < members.size(); ++s) {
      samplePositions[s] = current[members[s]];
      sampleNormals[s] = currentNormals[members[s]];
    }
    const auto index = makeSpatialIndex(samplePositions);
    const SurfaceSamples samples{samplePositions, sampleNormals, *index};

    const ProgressCallback stepProgress =
        progress ? ProgressCallback([&](double fraction, std::string_view) {
          return progress((double(j) + fraction) / double(m),
                          "scale " + std::to_string(j + 1) + "/" + std::to_string(m));
        })
                 : ProgressCallback();
    auto record = [&](std::size_t k, std::size_t, const LocalFit& fit) {
      // A projection that leaves the support is no projection onto this scale's surface.
      const bool ok = fit.valid && fit.projection.allFinite() && fit.normal.allFinite() &&
                      (fit.projection - current[k]).norm() <= scales[k];
      if (ok) {
        next[k] = fit.projection;
        nextNormals[k] = fit.normal;
      } else {
        next[k] = current[k];
        nextNormals[k] = currentNormals[k];
        if (failed[k] < 65535) ++failed[k];
      }
      failedNow[k] = !ok;
    };
    fitPoints(samples, FitQueries{current, scales}, walk, record, stepProgress);

    FlatteningStep step;
    // t_j is increasing in t_min (Eq. 1.39, f <= 1): its median is that of t_min, mapped.
    step.tMedian = result.medianTMin + f * (result.tMax - result.medianTMin);
    step.samples = members.size();
    double moved = 0;
    for (std::size_t k = 0; k < n; ++k) moved += (next[k] - current[k]).norm();
    step.meanMove = moved / double(n) / result.diagonal;
    std::swap(current, next);
    std::swap(currentNormals, nextNormals);
    for (std::uint8_t bad : failedNow) step.invalid += bad;
    step.seconds = secondsSince(t0);
    result.steps.push_back(step);
  }
  // The last, global fit without weights (Sec. 4.3), then every point onto it.
  result.sphere = fitGlobalSphere(current, currentNormals, result.sphereOrigin);
  const std::vector<Index> rank = invertPermutation(order);
  result.positions.resize(n);
  result.normals.resize(n);
  result.failedSteps.resize(n);
  double residual = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = rank[i];
    const Vec3 y = current[k] - result.sphereOrigin;
    const Vec3 projected = result.sphere.project(y);
    residual += (projected - y).norm();
    result.positions[i] = projected + result.sphereOrigin;
    const Vec3 g = result.sphere.gradient(projected);
    result.normals[i] = g.norm() > 0 ? Vec3(g.normalized()) : currentNormals[k];
    result.failedSteps[i] = failed[k];
  }
  result.residual = residual / double(n) / result.diagonal;
  result.seconds = secondsSince(start);
  return result;
}

}  // namespace scalespace
