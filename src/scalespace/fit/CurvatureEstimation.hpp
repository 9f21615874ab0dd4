#pragma once
// Runs one fit per point of a cloud (Sec. 1.4) and stores the results as named columns, one row per
// input point in input order. Invalid fits are flagged (fit_valid = 0, zeros elsewhere), not
// dropped.
#include <cstddef>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

struct CurvatureOptions {
  FitOptions fit;
  /// Support radius t in the cloud's units. Exactly one of `scale` and `scaleK` must be set.
  double scale = 0;
  /// Per-point t = distance to the K-th nearest neighbour (the point itself excluded), so that
  /// about K samples fall inside the support.
  int scaleK = 0;
};

struct CurvatureSummary {
  std::size_t points = 0;
  std::size_t invalid = 0;
  double meanNeighbors = 0;  // over valid fits
  double medianScale = 0;    // t (the same for all points unless scaleK is used)
  double seconds = 0;        // everything below, and the output (index build included)
  double setupSeconds = 0;   // spatial order and index build
  double fitSeconds = 0;     // neighbour queries and fits of all points (results handed over)
  /// When most fits are invalid: what and why (fit/FitDiagnosis.hpp), for the caller to show.
  std::vector<std::string> warnings;
};

/// OptionError naming the field unless exactly one of scale (finite, > 0) and scaleK (in
/// [1, kMaxNeighborCount]) is given and minNeighbors >= 1; what every entry point checks first.
void validateCurvatureOptions(const CurvatureOptions& options);

/// A warning when options.scale reaches the cloud's bounding-box diagonal: every neighbourhood is
/// then the whole cloud, each fit costs all N points (N^2 in all: hours for a million points) and
/// every point gets nearly the same global fit. Empty otherwise. The summaries carry it; a caller
/// can show it before the work starts.
std::vector<std::string> curvatureScaleWarnings(const PointCloud& cloud,
                                                const CurvatureOptions& options);

/// Names of the columns written by computeCurvatureColumns, in order.
const std::vector<std::string>& curvatureColumnNames();

/// Fits every point and appends (or overwrites) the curvature columns of `cloud`:
/// nx ny nz curv_mean curv_max curv_min dir_max_{x,y,z} dir_min_{x,y,z} gls_tau gls_kappa
/// gls_fitness anisotropy neighbors fit_valid. Requires oriented normals for the APSS estimators
/// (throws Error otherwise). Parallel (TBB); identical results for any thread count.
CurvatureSummary computeCurvatureColumns(PointCloud& cloud, const CurvatureOptions& options,
                                         const ProgressCallback& progress = {});

/// Same fits, returned as structs in input order (for library users and tests).
std::vector<LocalFit> fitAllPoints(const PointCloud& cloud, const CurvatureOptions& options,
                                   const ProgressCallback& progress = {},
                                   CurvatureSummary* summary = nullptr);

}  // namespace scalespace
