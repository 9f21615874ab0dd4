#include "scalespace/fit/FitPoints.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/fit/FitScratch.hpp"

namespace scalespace {
namespace {

/// The shortest run of a block that fitAtBatch takes (shorter runs are fitted point by point):
/// its lanes cost the same whether they are full or not, so a short run wastes most of them. The
/// value is the best of those compared on a robust stack's time (bench/bench_planes --scene
/// stairs; the figures are in bench/README.md).
constexpr std::size_t kMinBatch = 6;

void validate(const SurfaceSamples& samples, const FitQueries& queries,
              const FitPointsOptions& options) {
  validateFitOptions(options.fit);
  const std::size_t n = queries.points.size();
  if (queries.scales.size() != 1 && queries.scales.size() != n)
    throw OptionError("FitQueries::scales must hold one scale or one per point (" +
                      std::to_string(n) + "), got " + std::to_string(queries.scales.size()));
  for (const double t : queries.scales)
    if (!(std::isfinite(t) && t >= 0))
      throw OptionError("FitQueries::scales must be finite and >= 0, got " + std::to_string(t));
  if (queries.convergedAtFirstStep && queries.convergedAtFirstStep->size() != n)
    throw OptionError("FitQueries::convergedAtFirstStep must hold one flag per point (" +
                      std::to_string(n) + "), got " +
                      std::to_string(queries.convergedAtFirstStep->size()));
  if (samples.positions.size() != samples.index.size())
    throw OptionError("SurfaceSamples: the index was not built on these positions");
  if (estimatorNeedsNormals(options.fit.estimator) &&
      samples.normals.size() != samples.positions.size())
    throw OptionError(std::string("the ") + estimatorName(options.fit.estimator) +
                      " estimator (FitOptions::estimator) needs one normal per sample");
}

struct Tally {
  FitWorkspace workspace;
  std::size_t invalid = 0;
  double validNeighbors = 0, neighbors = 0, mlsSteps = 0;
  void count(const LocalFit& f) {
    neighbors += f.neighbors;
    mlsSteps += f.mlsSteps;
    if (f.valid)
      validNeighbors += f.neighbors;
    else
      ++invalid;
  }
};

}  // namespace

void validateFitOptions(const FitOptions& options) {
  auto require = [](bool ok, const std::string& what, double got) {
    if (!ok) throw OptionError("FitOptions::" + what + ", got " + std::to_string(got));
  };
  require(options.minNeighbors >= 1, "minNeighbors must be >= 1", options.minNeighbors);
  require(options.mlsMaxSteps >= 1, "mlsMaxSteps must be >= 1", options.mlsMaxSteps);
  require(std::isfinite(options.mlsTolerance) && options.mlsTolerance > 0,
          "mlsTolerance must be > 0 (a fraction of t)", options.mlsTolerance);
  require(options.robustIterations >= 0, "robustIterations must be >= 0", options.robustIterations);
  require(std::isfinite(options.robustTolerance) && options.robustTolerance >= 0,
          "robustTolerance must be >= 0", options.robustTolerance);
}

FitPointsSummary fitPoints(const SurfaceSamples& samples, const FitQueries& queries,
                           const FitPointsOptions& options, const FitVisitor& visit,
                           const ProgressCallback& progress) {
  validate(samples, queries, options);
  FitPointsSummary summary;
  const std::size_t n = queries.points.size();
  summary.points = n;
  if (n == 0) return summary;

  // The walk: the queries themselves, or their Morton-ordered copy (rank k is query order[k]).
  const bool spatial = options.walk == QueryWalk::Spatial;
  if (spatial) summary.order = spatialOrder(queries.points);
  const std::vector<Index>& order = summary.order;
  std::vector<Vec3> sorted;
  if (spatial) sorted = applyPermutation(queries.points, order);
  const std::vector<Vec3>& points = spatial ? sorted : queries.points;
  auto queryOf = [&](std::size_t k) -> std::size_t { return spatial ? order[k] : k; };
  const bool oneScale = queries.scales.size() == 1;
  // A point's hint, when given, sets FitOptions::expectFirstStepConverged: one of two copies made
  // here, not a copy per fit.
  FitOptions expectConverged = options.fit, expectNot = options.fit;
  expectConverged.expectFirstStepConverged = true;
  expectNot.expectFirstStepConverged = false;
  auto fitOptionsOf = [&](std::size_t q) -> const FitOptions& {
    if (!queries.convergedAtFirstStep) return options.fit;
    return (*queries.convergedAtFirstStep)[q] ? expectConverged : expectNot;
  };

  tbb::enumerable_thread_specific<Tally> tallies;
  auto fitAlone = [&](std::size_t k, double t, Tally& tally) {
    const std::size_t q = queryOf(k);
    const LocalFit f =
        t > 0 ? fitAt(points[k], t, samples, fitOptionsOf(q), tally.workspace) : LocalFit{};
    tally.count(f);
    visit(q, k, f);
  };
  // One scale: each block's samples are fetched once; a run of at least kMinBatch points of a
  // block goes through fitAtBatch, a shorter one (the blocks of the finest scales) point by
  // point, where a lane kernel would run mostly empty.
  auto fitGroupAtOneScale = [&](std::size_t g, Tally& tally) {
    const double t = queries.scales[0];
    const double slack = options.fit.mls ? kMlsSlack : 0.0;
    FitScratch& scratch = tally.workspace.scratch();
    return fitGroupInRuns(points, g, samples, t, slack, scratch.cache, kFitBatch,
                          [&](std::size_t k, std::size_t count) {
                            if (count < kMinBatch || !(t > 0)) {
                              for (std::size_t i = k; i < k + count; ++i) fitAlone(i, t, tally);
                              return;
                            }
                            LocalFit fits[kFitBatch];
                            fitAtBatch(&points[k], count, t, samples, options.fit, tally.workspace,
                                       fits);
                            for (std::size_t i = 0; i < count; ++i) {
                              tally.count(fits[i]);
                              visit(queryOf(k + i), k + i, fits[i]);
                            }
                          });
  };
  // A scale per point: no shared ball, each point queries the index alone.
  auto fitGroupPointByPoint = [&](std::size_t g, Tally& tally) {
    tally.workspace.scratch().cache.clear();
    const std::size_t begin = g * kPrefetchGroup, end = std::min(n, begin + kPrefetchGroup);
    for (std::size_t k = begin; k < end; ++k) fitAlone(k, queries.scales[queryOf(k)], tally);
    return end - begin;
  };

  ProgressTracker tracker(progress, "fitting", n);
  const std::size_t groups = (n + kPrefetchGroup - 1) / kPrefetchGroup;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups, 4), [&](const auto& range) {
    Tally& tally = tallies.local();
    for (std::size_t g = range.begin(); g != range.end(); ++g)
      tracker.advance(oneScale ? fitGroupAtOneScale(g, tally) : fitGroupPointByPoint(g, tally));
  });
  tracker.finish();
  for (const Tally& tally : tallies) {
    summary.invalid += tally.invalid;
    summary.validNeighbors += tally.validNeighbors;
    summary.neighbors += tally.neighbors;
    summary.mlsSteps += tally.mlsSteps;
  }
  return summary;
}

std::vector<LocalFit> fitPoints(const SurfaceSamples& samples, const FitQueries& queries,
                                const FitPointsOptions& options, const ProgressCallback& progress,
                                FitPointsSummary* summary) {
  std::vector<LocalFit> fits(queries.points.size());
  FitPointsSummary s = fitPoints(
      samples, queries, options,
      [&](std::size_t query, std::size_t, const LocalFit& f) { fits[query] = f; }, progress);
  if (summary) *summary = std::move(s);
  return fits;
}

}  // namespace scalespace
