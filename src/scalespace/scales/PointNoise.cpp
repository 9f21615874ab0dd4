#include "scalespace/scales/PointNoise.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

}  // namespace scalespace
