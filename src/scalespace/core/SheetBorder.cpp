#include "scalespace/core/SheetBorder.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/PointMoments.hpp"

namespace scalespace {

std::vector<float> sheetBorderShare(const std::vector<Vec3>& positions, const SpatialIndex& index,
                                    const std::vector<Vec3>& queries,
                                    const SheetBorderOptions& options,
                                    const std::vector<std::uint8_t>& skip) {
  if (!(options.radius > 0 && std::isfinite(options.radius)))
    throw OptionError("SheetBorderOptions::radius must be finite and > 0");
  if (options.minCount < 3) throw OptionError("SheetBorderOptions::minCount must be >= 3");
  if (!(options.maxVariation >= 0 && options.maxVariation <= 1))
    throw OptionError("SheetBorderOptions::maxVariation must be in [0, 1]");
  if (!skip.empty() && skip.size() != queries.size())
    throw OptionError("sheetBorderShare: skip holds " + std::to_string(skip.size()) +
                      " flags for " + std::to_string(queries.size()) + " queries");
  std::vector<float> share(queries.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 512), [&](const auto& r) {
    std::vector<Neighbor> found;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      if (!skip.empty() && skip[i]) continue;
      index.radiusSearch(queries[i], options.radius, found);
      if (found.size() < options.minCount) continue;
      // The index returns a query's neighbours in the same order whatever the thread: the sums
      // are the same for any thread count.
      PointMoments moments;
      for (const Neighbor& nb : found) moments.add(positions[nb.index] - queries[i]);
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(moments.covariance());
      const Vec3 lambda = eig.eigenvalues();
      if (!(lambda[0] <= options.maxVariation * lambda.sum())) continue;
      const Vec3 normal = eig.eigenvectors().col(0);
      const Vec3 offset = moments.mean - normal.dot(moments.mean) * normal;
      share[i] = float(std::min(1.0, offset.norm() / options.radius));
    }
  });
  return share;
}

}  // namespace scalespace
