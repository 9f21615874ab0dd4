#include "scalespace/fit/CurvatureEstimation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/fit/NeighborhoodCache.hpp"

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
  if (options.fit.minNeighbors < 1)
    throw OptionError("FitOptions::minNeighbors must be >= 1, got " +
                      std::to_string(options.fit.minNeighbors));
}

namespace {

void validate(const PointCloud& cloud, const CurvatureOptions& options) {
  validateCurvatureOptions(options);
  if (needsNormals(options.fit.estimator) && !cloud.hasNormals())
    throw Error(std::string("the ") + estimatorName(options.fit.estimator) +
                " estimator needs oriented normals: estimate them first (scalespace normals)");
}

/// Calls `visit(k, fit)` for every point, in parallel, k in the processing order that it returns
/// in `order` (point k is the cloud's point order[k]). The cloud is traversed in
/// spatial order (core/SpatialOrder) so that consecutive fits touch the same memory: this is
/// where most of the time goes (neighbour queries and accumulation over ~40 samples).
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
  std::vector<Vec3> positions(n), normals;
  for (std::size_t k = 0; k < n; ++k) positions[k] = cloud.positions()[order[k]];
  if (cloud.hasNormals()) {
    normals.resize(n);
    for (std::size_t k = 0; k < n; ++k) normals[k] = cloud.normals()[order[k]];
  }
  const std::unique_ptr<SpatialIndex> index = makeSpatialIndex(positions);
  const SurfaceSamples samples{positions, normals, *index};
  summary.setupSeconds = secondsSince(start);
  const auto fitStart = std::chrono::steady_clock::now();

  std::vector<double> scales(n, options.scale);
  struct Counters {
    std::size_t invalid = 0;
    double neighbors = 0, allNeighbors = 0;
    FitWorkspace workspace;
  };
  tbb::enumerable_thread_specific<Counters> counters;
  auto fitOne = [&](std::size_t k, Counters& c) {
    double t = options.scale;
    if (options.scaleK > 0) {
      // K + 1 because the point itself is its own nearest neighbour.
      index->knnSearch(positions[k], std::size_t(options.scaleK) + 1, c.workspace.neighbors);
      t = c.workspace.neighbors.empty() ? 0.0 : std::sqrt(c.workspace.neighbors.back().distSq);
      // The support is open (|q| < t): widen by a hair so the K-th neighbour is inside it.
      t *= 1.0 + 1e-9;
      scales[k] = t;
    }
    LocalFit fit;
    if (t > 0) fit = fitAt(positions[k], t, samples, options.fit, c.workspace);
    c.allNeighbors += fit.neighbors;
    if (fit.valid)
      c.neighbors += fit.neighbors;
    else
      ++c.invalid;
    visit(k, fit);
  };
  ProgressTracker tracker(progress, "fitting", n);
  // At a fixed scale, consecutive (Morton-ordered) points share most neighbours: their fits read
  // one prefetched ball per block (fit/NeighborhoodCache). Per-point scales (scaleK) query alone.
  const double slack = options.fit.mls ? kMlsSlack : 0.0;
  const std::size_t groups = (n + kPrefetchGroup - 1) / kPrefetchGroup;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups, 4), [&](const auto& range) {
    Counters& c = counters.local();
    for (std::size_t g = range.begin(); g != range.end(); ++g) {
      auto fit = [&](std::size_t k) { fitOne(k, c); };
      if (options.scaleK == 0) {
        tracker.advance(
            fitGroupByBlocks(positions, g, samples, options.scale, slack, c.workspace.cache, fit));
      } else {
        const std::size_t end = std::min(n, (g + 1) * kPrefetchGroup);
        for (std::size_t k = g * kPrefetchGroup; k < end; ++k) fit(k);
        tracker.advance(end - g * kPrefetchGroup);
      }
    }
  });
  tracker.finish();
  summary.fitSeconds = secondsSince(fitStart);

  double allNeighbors = 0;
  for (const Counters& c : counters) {
    summary.invalid += c.invalid;
    summary.meanNeighbors += c.neighbors;
    allNeighbors += c.allNeighbors;
  }
  const std::size_t valid = n - summary.invalid;
  summary.meanNeighbors = valid ? summary.meanNeighbors / double(valid) : 0.0;
  FitCounts counts;
  counts.total = n;
  counts.invalid = summary.invalid;
  counts.largestScale = n ? *std::max_element(scales.begin(), scales.end()) : 0.0;
  counts.meanNeighbors = n ? allNeighbors / double(n) : 0.0;
  counts.minNeighbors = options.fit.minNeighbors;
  summary.warnings = invalidFitWarnings(cloud, counts);
  std::nth_element(scales.begin(), scales.begin() + n / 2, scales.end());
  summary.medianScale = scales[n / 2];
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
