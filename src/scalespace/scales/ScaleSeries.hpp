#pragma once
// The scale series of the multi-scale representation (Sec. 1.5.1): M support radii t_1 < ... < t_M
// between t_min (the median distance to the K-th nearest neighbour: below it fits have too few
// neighbours) and t_max (the bounding-box diagonal: above it every fit sees the whole cloud).
#include <string>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

enum class ScaleSpacing {
  Log,    // geometric series, Eq. 1.40 corrected (docs/THESIS_NOTES.md): constant ratio t_{j+1}/t_j
  Linear  // arithmetic series, Eq. 1.39: constant difference t_{j+1} - t_j
};

/// "log" / "linear"; parse throws OptionError on anything else.
const char* scaleSpacingName(ScaleSpacing spacing);
ScaleSpacing parseScaleSpacing(const std::string& name);

/// The most scales a series may have: a stack holds every point at every scale (19 bytes each), and
/// 10^5 scales of even a small cloud ran without bound. The thesis uses 50.
constexpr int kMaxScaleCount = 1000;
/// OptionError naming ScaleSeriesOptions::count unless 1 <= count <= kMaxScaleCount: callers check
/// before their long work (reading, normals) what scaleSeries checks again.
void validateScaleCount(int count);

struct ScaleSeriesOptions {
  int count = 50;  // M (Chapters 2-3 use 50 scales)
  ScaleSpacing spacing = ScaleSpacing::Log;
  double tMin = 0;  // 0: median K-NN radius (Sec. 1.5.1)
  double tMax = 0;  // 0: bounding-box diagonal (Sec. 1.5.1)
  int K = 10;       // neighbours enclosed by t_min (Sec. 1.5.1: K = 10)
  /// The median K-NN radius when the caller has the K-NN distances already (planes/: from the
  /// k-NN graph of Sec. 2.3.1, whose k is this K): used for the automatic t_min instead of
  /// querying every point again. 0: computed. Must be lowerMedian(knnRadii(positions, ., K)).
  double knownMedianKnnRadius = 0;
};

/// t_j for j = 1..M (returned 0-based). Log: t_j = tMin (tMax/tMin)^((j-1)/(M-1)) (corrected
/// Eq. 1.40); Linear: t_j = tMin + (j-1)(tMax - tMin)/(M-1) (Eq. 1.39). M = 1 gives {tMin}.
/// Throws OptionError unless M >= 1 and 0 < tMin < tMax (tMin <= tMax when M = 1), all finite.
std::vector<double> scaleSeries(double tMin, double tMax, int count, ScaleSpacing spacing);

/// Per point, the distance to its K-th nearest neighbour (the point itself not counted), i.e. the
/// adaptive t_min of Chapter 4. Parallel, deterministic. Throws OptionError if K < 1 or the cloud
/// has fewer than K + 1 points.
std::vector<double> knnRadii(const std::vector<Vec3>& positions, const SpatialIndex& index, int K);

/// The homogeneous t_min of Sec. 1.5.1: the median of knnRadii (lower median for even counts).
double medianKnnRadius(const std::vector<Vec3>& positions, const SpatialIndex& index, int K);

/// The lower median of `values` (what medianKnnRadius takes of the radii). Throws OptionError
/// when empty.
double lowerMedian(std::vector<double> values);

struct ScaleSeriesResult {
  std::vector<double> scales;  // t_1..t_M
  double tMin = 0, tMax = 0;
  bool tMinAuto = false, tMaxAuto = false;  // whether they were computed from the cloud
};

/// Resolves tMin/tMax (auto when 0) from the cloud and builds the series. `index` must be built on
/// `positions`; pass nullptr to build one when tMin is auto.
ScaleSeriesResult makeScaleSeries(const std::vector<Vec3>& positions,
                                  const ScaleSeriesOptions& options,
                                  const SpatialIndex* index = nullptr);

}  // namespace scalespace
