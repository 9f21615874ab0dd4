#pragma once
// fitPoints: the one driver that runs fits (fit/LocalFit) at many points (Sec. 1.4, 1.5). The
// query points are any positions, cloud points or not (the stack's projections, curvature-line
// vertices, points moved by a parametrization), each with its own support radius or one for all.
//
// Where the time goes is the neighbour queries and the accumulation over the samples, so the
// driver walks the queries along a Morton curve and, at a fixed scale, answers the queries of a
// block of nearby points with one prefetched ball (fit/NeighborhoodCache); the robust APSS fits of
// a block make their first MLS step eight at a time (fitAtBatch). Groups of points are fixed, so
// the results do not depend on the thread count.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

/// In which order fitPoints walks the queries (FitPointsOptions::walk).
enum class QueryWalk {
  Spatial,  // along a Morton curve of the queries, whatever their order
  AsGiven   // in the given order: the queries are spatially coherent already (a Morton-ordered
            // cloud, a stack's projections of one)
};

struct FitPointsOptions {
  FitOptions fit;
  QueryWalk walk = QueryWalk::Spatial;
};

/// The points to fit at. `scales` holds one support radius t for every point (size 1) or one per
/// point, each finite and >= 0; t = 0 (no support: duplicate points at a per-point scale) gives
/// an invalid fit. `convergedAtFirstStep`, when set, holds one flag per point: 1 where a similar
/// earlier fit of that point converged at its first MLS step (the previous scale of a stack), the
/// FitOptions::expectFirstStepConverged hint point by point.
struct FitQueries {
  const std::vector<Vec3>& points;
  const std::vector<double>& scales;
  const std::vector<std::uint8_t>* convergedAtFirstStep = nullptr;
};

/// Receives the fit of query `query`, which was the `rank`-th processed (QueryWalk::AsGiven: rank
/// = query). Called from several threads at once, for distinct queries; a consumer that stores
/// results by rank writes consecutive entries (the cheap order; FitPointsSummary::order maps them
/// back).
using FitVisitor = std::function<void(std::size_t query, std::size_t rank, const LocalFit& fit)>;

struct FitPointsSummary {
  std::size_t points = 0;
  std::size_t invalid = 0;
  double validNeighbors = 0;  // sum of LocalFit::neighbors over the valid fits
  double neighbors = 0;       // the same over every fit
  double mlsSteps = 0;        // sum of LocalFit::mlsSteps over every fit
  /// The processing order, order[rank] = query (QueryWalk::Spatial); empty with AsGiven.
  std::vector<Index> order;
};

/// OptionError naming the field unless minNeighbors >= 1, mlsMaxSteps >= 1, mlsTolerance > 0,
/// robustIterations >= 0 and robustTolerance >= 0 (finite).
void validateFitOptions(const FitOptions& options);

/// Fits at every query (MLS-projects it when options.fit.mls) against `samples` and hands each
/// fit to `visit`. Throws OptionError before any fit on invalid options or queries (sizes,
/// scales), an estimator that needs normals on samples without them; Cancelled when `progress`
/// asks to stop. Identical results for any thread count.
FitPointsSummary fitPoints(const SurfaceSamples& samples, const FitQueries& queries,
                           const FitPointsOptions& options, const FitVisitor& visit,
                           const ProgressCallback& progress = {});

/// The same, the fits returned in query order.
std::vector<LocalFit> fitPoints(const SurfaceSamples& samples, const FitQueries& queries,
                                const FitPointsOptions& options,
                                const ProgressCallback& progress = {},
                                FitPointsSummary* summary = nullptr);

}  // namespace scalespace
