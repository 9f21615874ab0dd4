#include "scalespace/param/MeshlessDistortion.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/param/LocalMapSample.hpp"

namespace scalespace {
namespace {

struct Ellipse {
  double anisotropy = 0, area = 0;
};

/// Semi-axes = square roots of the covariance's eigenvalues.
Ellipse ellipseOf(const Eigen::Matrix2d& cov) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov, Eigen::EigenvaluesOnly);
  const double l2 = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
  const double l1 = std::sqrt(std::max(eig.eigenvalues()(1), 0.0));
  Ellipse e;
  if (l1 > 0) e.anisotropy = l2 / l1;
  e.area = kPi * l1 * l2;
  return e;
}

double ratio(double a, double b) {
  const double hi = std::max(a, b), lo = std::min(a, b);
  if (!(lo > 0)) return kMaxDistortion;
  return std::min(hi / lo, kMaxDistortion);
}

}  // namespace

void validateDistortionOptions(const DistortionOptions& options) {
  if (options.neighbors.empty())
    throw OptionError("DistortionOptions::neighbors needs at least one size");
  for (int k : options.neighbors)
    if (k < 3 || std::size_t(k) > kMaxNeighborCount)
      throw OptionError("DistortionOptions::neighbors: each size must be in [3, " +
                        std::to_string(kMaxNeighborCount) + "], got " + std::to_string(k));
}

double positiveQuantile(const std::vector<float>& values, double q) {
  std::vector<float> v;
  v.reserve(values.size());
  for (float x : values)
    if (x > 0) v.push_back(x);
  if (v.empty()) return 0;
  const std::size_t at = std::min(
      v.size() - 1, std::size_t(std::floor(std::clamp(q, 0.0, 1.0) * double(v.size() - 1))));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(at), v.end());
  return v[at];
}

DistortionResult measureDistortion(const std::vector<Vec3>& positions,
                                   const std::vector<Vec3>& normals, const DomainMap& domain,
                                   const DistortionOptions& options,
                                   const ProgressCallback& progress) {
  validateDistortionOptions(options);
  const std::size_t n = positions.size();
  if (domain.size() != n || (!normals.empty() && normals.size() != n))
    throw OptionError("the cloud and its parametrization have different point counts");
  DistortionResult result;
  const std::size_t sizes = options.neighbors.size();
  result.sizes.resize(sizes);
  // Per size: the 3D and domain ellipses' anisotropies and areas.
  std::vector<std::vector<Ellipse>> in3d(sizes, std::vector<Ellipse>(n)),
      in2d(sizes, std::vector<Ellipse>(n));
  if (n >= 3) {
    const auto index = makeSpatialIndex(positions);
    const std::size_t kMax =
        std::size_t(*std::max_element(options.neighbors.begin(), options.neighbors.end()));
    ProgressTracker tracker(progress, "distortion", n);
    forEachLocalMap(positions, normals, *index, domain, kMax, tracker,
                    [&](std::size_t i, const LocalMapSample& all, LocalMapSample& sample) {
                      for (std::size_t s = 0; s < sizes; ++s) {
                        truncateLocalMap(all, std::size_t(options.neighbors[s]), sample);
                        in3d[s][i] = ellipseOf(weightedCovariance(sample.tangent, sample.weight));
                        in2d[s][i] = ellipseOf(weightedCovariance(sample.domain, sample.weight));
                      }
                    });
    tracker.finish();
  }
  for (std::size_t s = 0; s < sizes; ++s) {
    DistortionAtSize& out = result.sizes[s];
    out.neighbors = options.neighbors[s];
    out.conformal.assign(n, 0);
    out.authalic.assign(n, 0);
    std::vector<float> areaRatios;
    areaRatios.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      if (in3d[s][i].area > 0 && in2d[s][i].area > 0)
        areaRatios.push_back(float(in3d[s][i].area / in2d[s][i].area));
    out.areaFactor = positiveQuantile(areaRatios, 0.5);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(in3d[s][i].area > 0)) {
        ++out.undetermined;
        continue;
      }
      out.conformal[i] = float(ratio(in3d[s][i].anisotropy, in2d[s][i].anisotropy));
      out.authalic[i] = float(ratio(in3d[s][i].area, out.areaFactor * in2d[s][i].area));
    }
    out.medianConformal = positiveQuantile(out.conformal, 0.5);
    out.p90Conformal = positiveQuantile(out.conformal, 0.9);
    out.medianAuthalic = positiveQuantile(out.authalic, 0.5);
    out.p90Authalic = positiveQuantile(out.authalic, 0.9);
  }
  return result;
}

}  // namespace scalespace
