#include "scalespace/scales/ScaleSeries.hpp"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"

namespace scalespace {

const char* scaleSpacingName(ScaleSpacing spacing) {
  return spacing == ScaleSpacing::Log ? "log" : "linear";
}

ScaleSpacing parseScaleSpacing(const std::string& name) {
  if (name == "log") return ScaleSpacing::Log;
  if (name == "linear") return ScaleSpacing::Linear;
  throw OptionError("ScaleSeriesOptions::spacing must be 'log' or 'linear', got '" + name + "'");
}

void validateScaleCount(int count) {
  if (count < 1 || count > kMaxScaleCount)
    throw OptionError("ScaleSeriesOptions::count must be in [1, " + std::to_string(kMaxScaleCount) +
                      "] (number of scales M), got " + std::to_string(count));
}

std::vector<double> scaleSeries(double tMin, double tMax, int count, ScaleSpacing spacing) {
  validateScaleCount(count);
  if (!std::isfinite(tMin) || !std::isfinite(tMax) || !(tMin > 0))
    throw OptionError(
        "ScaleSeriesOptions::tMin must be finite and > 0 and ScaleSeriesOptions::tMax finite, got "
        "tmin=" +
        std::to_string(tMin) + " tmax=" + std::to_string(tMax));
  if (count == 1 ? !(tMin <= tMax) : !(tMin < tMax))
    throw OptionError("ScaleSeriesOptions::tMin must be < ScaleSeriesOptions::tMax, got tmin=" +
                      std::to_string(tMin) + " tmax=" + std::to_string(tMax) +
                      " (lower ScaleSeriesOptions::tMin or raise ScaleSeriesOptions::tMax)");
  std::vector<double> t(static_cast<std::size_t>(count));
  if (count == 1) {
    t[0] = tMin;
    return t;
  }
  for (int j = 0; j < count; ++j) {
    const double u = double(j) / double(count - 1);  // (j-1)/(M-1) with 1-based j
    // Corrected Eq. 1.40 (geometric) and Eq. 1.39 (arithmetic).
    t[std::size_t(j)] =
        spacing == ScaleSpacing::Log ? tMin * std::pow(tMax / tMin, u) : tMin + u * (tMax - tMin);
  }
  t.front() = tMin;  // exact endpoints despite pow rounding
  t.back() = tMax;
  return t;
}

std::vector<double> knnRadii(const std::vector<Vec3>& positions, const SpatialIndex& index, int K) {
  if (K < 1)
    throw OptionError("K (neighbours enclosed by t_min) must be >= 1, got " + std::to_string(K));
  if (positions.size() < std::size_t(K) + 1)
    throw OptionError("the cloud has " + std::to_string(positions.size()) +
                      " points: at least K + 1 = " + std::to_string(K + 1) +
                      " are needed to compute t_min (set ScaleSeriesOptions::tMin explicitly)");
  std::vector<double> radii(positions.size());
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  parallelFor(positions.size(), [&](std::size_t i) {
    auto& nb = scratch.local();
    // K + 1 because the query point is its own nearest neighbour.
    index.knnSearch(positions[i], std::size_t(K) + 1, nb);
    radii[i] = std::sqrt(nb.back().distSq);
  });
  return radii;
}

double lowerMedian(std::vector<double> values) {
  if (values.empty()) throw OptionError("the median of no values is undefined");
  const std::size_t mid = (values.size() - 1) / 2;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(mid), values.end());
  return values[mid];
}

double medianKnnRadius(const std::vector<Vec3>& positions, const SpatialIndex& index, int K) {
  return lowerMedian(knnRadii(positions, index, K));
}

ScaleSeriesResult makeScaleSeries(const std::vector<Vec3>& positions,
                                  const ScaleSeriesOptions& options, const SpatialIndex* index) {
  if (options.tMin < 0 || options.tMax < 0)
    throw OptionError(
        "ScaleSeriesOptions::tMin and ScaleSeriesOptions::tMax must be >= 0 (0 = automatic)");
  ScaleSeriesResult r;
  r.tMinAuto = options.tMin == 0;
  r.tMaxAuto = options.tMax == 0;
  r.tMin = options.tMin;
  r.tMax = options.tMax;
  if (r.tMinAuto && options.knownMedianKnnRadius > 0) {
    r.tMin = options.knownMedianKnnRadius;
  } else if (r.tMinAuto) {
    std::unique_ptr<SpatialIndex> own;
    if (!index) {
      own = makeSpatialIndex(positions);
      index = own.get();
    }
    r.tMin = medianKnnRadius(positions, *index, options.K);
    if (!(r.tMin > 0))
      throw OptionError(
          "the median distance to the " + std::to_string(options.K) +
          "-th neighbour is 0 (duplicate points): set ScaleSeriesOptions::tMin explicitly");
  }
  if (r.tMaxAuto) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec3& p : positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    r.tMax = positions.empty() ? 0.0 : (hi - lo).norm();
  }
  r.scales = scaleSeries(r.tMin, r.tMax, options.count, options.spacing);
  return r;
}

}  // namespace scalespace
