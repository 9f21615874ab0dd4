#include "scalespace/param/MapDefects.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/param/LocalMapSample.hpp"
#include "scalespace/param/MeshlessDistortion.hpp"

namespace scalespace {

void validateMapDefectOptions(const MapDefectOptions& options) {
  if (options.neighbors < 3) throw OptionError("MapDefectOptions::neighbors must be >= 3");
  if (options.domainNeighbors < 1)
    throw OptionError("MapDefectOptions::domainNeighbors must be >= 1");
  if (!(options.overlapFactor > 1) || !std::isfinite(options.overlapFactor))
    throw OptionError("MapDefectOptions::overlapFactor must be finite and > 1");
  if (!(options.maxConditionNumber > 1) || !std::isfinite(options.maxConditionNumber))
    throw OptionError("MapDefectOptions::maxConditionNumber must be finite and > 1");
}

MapDefects findMapDefects(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                          const DomainMap& domain, const MapDefectOptions& options,
                          const ProgressCallback& progress) {
  validateMapDefectOptions(options);
  const std::size_t n = positions.size();
  if (domain.size() != n || (!normals.empty() && normals.size() != n))
    throw OptionError("the cloud and its parametrization have different point counts");
  MapDefects result;
  result.fold.assign(n, 0);
  result.overlap.assign(n, 0);
  result.localScale.assign(n, 0);
  result.stretch.assign(n, 0);
  if (n < 3) return result;

  const auto index = makeSpatialIndex(positions);
  // Pass 1: the local linear map A_i (least squares: A = (sum w b a^T)(sum w a a^T)^-1).
  std::vector<Eigen::Matrix2d> jacobian(n, Eigen::Matrix2d::Zero());
  std::vector<std::uint8_t> determined(n, 0);
  std::vector<double> radius(n, 0);
  ProgressTracker tracker(progress, "folds", 2 * n);
  const std::size_t k = std::size_t(options.neighbors);
  forEachLocalMap(positions, normals, *index, domain, k, tracker,
                  [&](std::size_t i, const LocalMapSample& sample, LocalMapSample&) {
                    radius[i] = sample.radius;
                    Eigen::Matrix2d aa = Eigen::Matrix2d::Zero(), ba = Eigen::Matrix2d::Zero();
                    for (std::size_t s = 0; s < sample.weight.size(); ++s) {
                      aa += sample.weight[s] * sample.tangent[s] * sample.tangent[s].transpose();
                      ba += sample.weight[s] * sample.domain[s] * sample.tangent[s].transpose();
                    }
                    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(aa);
                    const double lo = eig.eigenvalues()(0), hi = eig.eigenvalues()(1);
                    const double c2 = options.maxConditionNumber * options.maxConditionNumber;
                    if (!(hi > 0) || !(lo * c2 > hi)) return;  // collinear neighbours
                    const Eigen::Matrix2d a = ba * aa.inverse();
                    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(a);
                    const double s0 = svd.singularValues()(0), s1 = svd.singularValues()(1);
                    if (!std::isfinite(s0) || !(s0 > 0) || !(s1 * options.maxConditionNumber > s0))
                      return;  // the domain collapses the neighbourhood onto a line
                    jacobian[i] = a;
                    determined[i] = 1;
                    result.localScale[i] = float(std::sqrt(std::abs(a.determinant())));
                    result.stretch[i] = float(s0 / s1);
                  });
  std::size_t positive = 0, negative = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!determined[i]) {
      ++result.undetermined;
      continue;
    }
    (jacobian[i].determinant() > 0 ? positive : negative) += 1;
  }
  result.majoritySign = positive >= negative ? 1 : -1;
  result.medianStretch = positiveQuantile(result.stretch, 0.5);
  result.p90Stretch = positiveQuantile(result.stretch, 0.9);
  for (std::size_t i = 0; i < n; ++i)
    if (determined[i] && (jacobian[i].determinant() > 0 ? 1 : -1) != result.majoritySign) {
      result.fold[i] = 1;
      ++result.folds;
    }

  // Pass 2: overlaps, from the nearest neighbours in the domain.
  std::vector<Vec3> embedded(n);
  for (std::size_t i = 0; i < n; ++i) embedded[i] = domain.embedded(i);
  const auto domainIndex = makeSpatialIndex(embedded);
  const std::size_t kd = std::size_t(options.domainNeighbors) + 1;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 512),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Neighbor> near;
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (!determined[i]) continue;
          const double smallest =
              Eigen::JacobiSVD<Eigen::Matrix2d>(jacobian[i]).singularValues()(1);
          domainIndex->knnSearch(embedded[i], kd, near);
          for (const Neighbor& nb : near) {
            if (nb.index == i) continue;
            const double allowed = std::max(std::sqrt(nb.distSq) / smallest, radius[i]);
            if ((positions[nb.index] - positions[i]).norm() > options.overlapFactor * allowed) {
              result.overlap[i] = 1;
              break;
            }
          }
        }
        tracker.advance(range.size());
      });
  tracker.finish();
  for (std::uint8_t o : result.overlap) result.overlaps += o;
  return result;
}

}  // namespace scalespace
