#include "scalespace/fit/NeighborhoodCache.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

namespace {
// A query ball must lie inside the cached ball with this relative room to spare, so that the
// rounding of |q - c| + r never admits a ball that pokes out of the cached one.
constexpr double kContainmentMargin = 1e-9;
}  // namespace

void NeighborhoodCache::prefetch(const SurfaceSamples& samples, const Vec3& center, double radius) {
  clear();
  if (!(radius > 0) || !std::isfinite(radius) || !center.allFinite()) return;
  samples.index.radiusSearch(center, radius, found_);
  const bool withNormals = samples.normals.size() == samples.positions.size();
  positions_.resize(found_.size());
  normals_.resize(withNormals ? found_.size() : 0);
  for (std::size_t k = 0; k < found_.size(); ++k) {
    positions_[k] = samples.positions[found_[k].index];
    if (withNormals) normals_[k] = samples.normals[found_[k].index];
  }
  source_ = &samples.index;
  center_ = center;
  radius_ = radius;
}

bool NeighborhoodCache::covers(const SurfaceSamples& samples, const Vec3& q, double r) const {
  return source_ == &samples.index && r > 0 && q.allFinite() &&
         (q - center_).norm() + r <= radius_ * (1 - kContainmentMargin);
}

std::size_t prefetchBlock(const std::vector<Vec3>& points, std::size_t k, std::size_t last,
                          const SurfaceSamples& samples, double t, double slack,
                          NeighborhoodCache& cache) {
  Eigen::AlignedBox3d box(points[k]);
  std::size_t end = k + 1;
  for (; end < last; ++end) {
    Eigen::AlignedBox3d grown = box;
    grown.extend(points[end]);
    if (!(grown.diagonal().norm() <= 2 * kBlockSpread * t)) break;
    box = grown;
  }
  if (end - k < 2) {
    cache.clear();
  } else {
    cache.prefetch(samples, box.center(), t * (1 + slack) + box.diagonal().norm() / 2);
  }
  return end;
}

}  // namespace scalespace
