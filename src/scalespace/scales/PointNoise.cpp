#include "scalespace/scales/PointNoise.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scalespace/fit/PointSetPlane.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

double pointNoiseRms(const std::vector<Vec3>& positions, const KnnGraph& knn) {
  const std::size_t n = knn.size();
  if (n == 0 || positions.size() != n) return 0.0;
  std::vector<double> rms(n, std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const auto& range) {
    std::vector<Index> patch;  // the point and its neighbours, reused along the range
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      patch.assign(1, Index(i));
      patch.insert(patch.end(), knn.neighbors.begin() + std::ptrdiff_t(knn.offsets[i]),
                   knn.neighbors.begin() + std::ptrdiff_t(knn.offsets[i + 1]));
      const double m = double(patch.size());
      if (m < 4) continue;  // too few for a plane: reads nothing rather than 0
      rms[i] = fitPlane(positions, patch).rms * std::sqrt(m / (m - 3));
    }
  });
  rms.erase(std::remove_if(rms.begin(), rms.end(), [](double r) { return !std::isfinite(r); }),
            rms.end());
  return rms.empty() ? 0.0 : lowerMedian(std::move(rms));
}

namespace {

/// The RMS residual of z = c0 + c1 x + c2 y + c3 x^2 + c4 xy + c5 y^2 over `patch` in its PCA
/// frame, scaled for the six coefficients; NaN when the normal equations are singular (the
/// neighbours on a line or a few positions).
double quadricResidual(const std::vector<Vec3>& positions, const std::vector<Index>& patch) {
  const PlaneFit plane = fitPlane(positions, patch);
  const std::vector<Vec2> uv = projectOnPlane(plane, positions, patch);
  // Coordinates over the patch's extent keep the normal equations well conditioned.
  double extent = 0;
  for (const Vec2& p : uv) extent = std::max(extent, p.norm());
  if (!(extent > 0)) return std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atz = Eigen::Matrix<double, 6, 1>::Zero();
  std::vector<Eigen::Matrix<double, 6, 1>> rows(patch.size());
  std::vector<double> heights(patch.size());
  for (std::size_t j = 0; j < patch.size(); ++j) {
    const double x = uv[j].x() / extent, y = uv[j].y() / extent;
    rows[j] << 1, x, y, x * x, x * y, y * y;
    heights[j] = (positions[patch[j]] - plane.centroid).dot(plane.normal);
    ata += rows[j] * rows[j].transpose();
    atz += rows[j] * heights[j];
  }
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(ata);
  const auto d = solver.vectorD();
  if (solver.info() != Eigen::Success || !(d.minCoeff() > 1e-9 * d.maxCoeff()))
    return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix<double, 6, 1> c = solver.solve(atz);
  double sum = 0;
  for (std::size_t j = 0; j < patch.size(); ++j) {
    const double r = heights[j] - rows[j].dot(c);
    sum += r * r;
  }
  const double m = double(patch.size());
  return std::sqrt(sum / (m - 6));
}

}  // namespace

double surfaceNoiseRms(const std::vector<Vec3>& positions, const SpatialIndex& index,
                       const SurfaceNoiseOptions& options) {
  const std::size_t n = positions.size();
  const std::size_t k = std::size_t(std::max(options.neighbors, 7));
  if (n < 7 || index.size() != n) return 0.0;
  const std::size_t samples = std::min(n, std::max<std::size_t>(options.maxSamples, 1));
  std::vector<double> rms(samples, std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples, 64), [&](const auto& range) {
    std::vector<Neighbor> found;
    std::vector<Index> patch;
    for (std::size_t s = range.begin(); s != range.end(); ++s) {
      // Evenly spread over the input order, the same points for any thread count.
      const std::size_t i = s * n / samples;
      index.knnSearch(positions[i], k, found);
      if (found.size() < 7) continue;
      patch.clear();
      for (const Neighbor& nb : found) patch.push_back(nb.index);
      rms[s] = quadricResidual(positions, patch);
    }
  });
  rms.erase(std::remove_if(rms.begin(), rms.end(), [](double r) { return !std::isfinite(r); }),
            rms.end());
  return rms.empty() ? 0.0 : lowerMedian(std::move(rms));
}

}  // namespace scalespace
