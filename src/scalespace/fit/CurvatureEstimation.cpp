#include "scalespace/fit/CurvatureEstimation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/fit/FitPoints.hpp"

namespace scalespace {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool needsNormals(EstimatorKind kind) {
  return kind == EstimatorKind::W1 || kind == EstimatorKind::W2 || kind == EstimatorKind::W3;
}

}  // namespace

void validateCurvatureOptions(const CurvatureOptions& options) {
  if ((options.scale > 0) == (options.scaleK > 0))
    throw OptionError(
        "give exactly one of a scale t > 0 (CurvatureOptions::scale) or a neighbour count "
        "(CurvatureOptions::scaleK)");
  if (!(std::isfinite(options.scale) && options.scale >= 0))
    throw OptionError("CurvatureOptions::scale must be a finite positive distance");
  if (options.scaleK < 0 || std::size_t(options.scaleK) > kMaxNeighborCount)
    throw OptionError("CurvatureOptions::scaleK must be in [1, " +
                      std::to_string(kMaxNeighborCount) + "], got " +
                      std::to_string(options.scaleK));
  validateFitOptions(options.fit);
}

std::vector<std::string> curvatureScaleWarnings(const PointCloud& cloud,
                                                const CurvatureOptions& options) {
  const double diagonal = cloud.boundingBoxDiagonal();
  if (!(options.scale > 0) || cloud.size() < 2 || !(options.scale >= diagonal)) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "the scale %g reaches the cloud's diagonal (%g): every neighbourhood is the whole "
                "cloud (%zu points per fit), so every point gets nearly the same fit and the work "
                "grows with the square of the points; a scale of a few point spacings to a "
                "fraction of the diagonal describes the surface",
                options.scale, diagonal, cloud.size());
  return {text};
}

namespace {

void validate(const PointCloud& cloud, const CurvatureOptions& options) {
  validateCurvatureOptions(options);
  if (needsNormals(options.fit.estimator) && !cloud.hasNormals())
    throw Error(std::string("the ") + estimatorName(options.fit.estimator) +
                " estimator needs oriented normals: estimate them first (scalespace normals)");
}

/// Per-point support radii: t_k = distance to the K-th nearest neighbour of point k (the point
/// itself excluded), widened by a hair because the support is open (|q| < t) and the K-th
/// neighbour must be inside it.
std::vector<double> scalesFromNeighborCount(const std::vector<Vec3>& positions,
                                            const SpatialIndex& index, std::size_t k) {
  std::vector<double> scales(positions.size());
  tbb::enumerable_thread_specific<std::vector<Neighbor>> found;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 256), [&](const auto& r) {
    std::vector<Neighbor>& nb = found.local();
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      index.knnSearch(positions[i], k + 1, nb);  // + 1: the point is its own nearest neighbour
      scales[i] = nb.empty() ? 0.0 : std::sqrt(nb.back().distSq) * (1.0 + 1e-9);
    }
  });
  return scales;
}

/// Calls `visit(k, fit)` for every point, in parallel, k in the processing order that it returns
/// in `order` (point k is the cloud's point order[k]). The samples are the cloud in spatial order
/// (core/SpatialOrder), so that consecutive fits touch the same memory, and the fits are
/// fitPoints' walk over them.
void forEachFit(const PointCloud& cloud, const CurvatureOptions& options,
                const ProgressCallback& progress, CurvatureSummary& summary,
                const std::function<void(std::size_t, const LocalFit&)>& visit,
                std::vector<Index>& order) {
  validate(cloud, options);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = cloud.size();
  summary = CurvatureSummary{};
  summary.points = n;
  if (n == 0) return;

  order = spatialOrder(cloud.positions());
  const std::vector<Vec3> positions = applyPermutation(cloud.positions(), order);
  const std::vector<Vec3> normals =
      cloud.hasNormals() ? applyPermutation(cloud.normals(), order) : std::vector<Vec3>{};
  const std::unique_ptr<SpatialIndex> index = makeSpatialIndex(positions);
  const SurfaceSamples samples{positions, normals, *index};
  summary.setupSeconds = secondsSince(start);
  const auto fitStart = std::chrono::steady_clock::now();

  const std::vector<double> scales =
      options.scaleK > 0 ? scalesFromNeighborCount(positions, *index, std::size_t(options.scaleK))
                         : std::vector<double>{options.scale};
  FitPointsOptions walk;
  walk.fit = options.fit;
  walk.walk = QueryWalk::AsGiven;
  const FitPointsSummary fits = fitPoints(
      samples, FitQueries{positions, scales}, walk,
      [&](std::size_t k, std::size_t, const LocalFit& f) { visit(k, f); }, progress);
  summary.fitSeconds = secondsSince(fitStart);

  summary.invalid = fits.invalid;
  const std::size_t valid = n - summary.invalid;
  summary.meanNeighbors = valid ? fits.validNeighbors / double(valid) : 0.0;
  FitCounts counts;
  counts.total = n;
  counts.invalid = summary.invalid;
  counts.largestScale = *std::max_element(scales.begin(), scales.end());
  counts.meanNeighbors = fits.neighbors / double(n);
  counts.minNeighbors = options.fit.minNeighbors;
  summary.warnings = curvatureScaleWarnings(cloud, options);
  for (std::string& w : invalidFitWarnings(cloud, counts)) summary.warnings.push_back(std::move(w));
  std::vector<double> median = scales;
  std::nth_element(median.begin(), median.begin() + median.size() / 2, median.end());
  summary.medianScale = median[median.size() / 2];
  summary.seconds = secondsSince(start);
}

}  // namespace

const std::vector<std::string>& curvatureColumnNames() {
  static const std::vector<std::string> names = {
      "nx",        "ny",        "nz",          "curv_mean",  "curv_max",  "curv_min",
      "dir_max_x", "dir_max_y", "dir_max_z",   "dir_min_x",  "dir_min_y", "dir_min_z",
      "gls_tau",   "gls_kappa", "gls_fitness", "anisotropy", "neighbors", "fit_valid"};
  return names;
}

CurvatureSummary computeCurvatureColumns(PointCloud& cloud, const CurvatureOptions& options,
                                         const ProgressCallback& progress) {
  validate(cloud, options);
  const auto& names = curvatureColumnNames();
  // Columns are created up front (in the documented order) and filled in place: no per-point
  // result array, which keeps peak memory at the columns themselves.
  std::vector<double*> col(names.size());
  // Re-running on our own output moves the columns to the end instead of duplicating them.
  for (const std::string& name : names) cloud.removeAttribute(name);
  for (std::size_t c = 0; c < names.size(); ++c) {
    const ScalarType type = names[c] == "neighbors"   ? ScalarType::Int32
                            : names[c] == "fit_valid" ? ScalarType::UInt8
                                                      : ScalarType::Float32;
    cloud.addAttribute(names[c], type);
  }
  for (std::size_t c = 0; c < names.size(); ++c)
    col[c] = cloud.findAttribute(names[c])->values.data();

  CurvatureSummary summary;
  std::vector<Index> order;
  forEachFit(
      cloud, options, progress, summary,
      [&](std::size_t k, const LocalFit& f) {
        const double v[] = {f.normal.x(),
                            f.normal.y(),
                            f.normal.z(),
                            f.meanCurvature,
                            f.kMax,
                            f.kMin,
                            f.dirMax.x(),
                            f.dirMax.y(),
                            f.dirMax.z(),
                            f.dirMin.x(),
                            f.dirMin.y(),
                            f.dirMin.z(),
                            f.tau,
                            f.kappa,
                            f.fitness,
                            f.anisotropy,
                            double(f.neighbors),
                            f.valid ? 1.0 : 0.0};
        for (std::size_t c = 0; c < names.size(); ++c) col[c][k] = v[c];
      },
      order);
  // The columns were filled in processing order (consecutive fits write consecutive entries:
  // scattering 18 values per point over the whole cloud cost more than the neighbour queries);
  // each is put in input order on its own, which keeps the scattered writes in a few MB.
  std::vector<double> processed(cloud.size());
  for (double* column : col) {
    std::copy(column, column + cloud.size(), processed.begin());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cloud.size(), 4096), [&](const auto& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) column[order[k]] = processed[k];
    });
  }
  return summary;
}

std::vector<LocalFit> fitAllPoints(const PointCloud& cloud, const CurvatureOptions& options,
                                   const ProgressCallback& progress, CurvatureSummary* summary) {
  std::vector<LocalFit> fits(cloud.size());
  CurvatureSummary s;
  std::vector<Index> order;
  forEachFit(
      cloud, options, progress, s, [&](std::size_t k, const LocalFit& f) { fits[order[k]] = f; },
      order);
  if (summary) *summary = s;
  return fits;
}

}  // namespace scalespace
