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
  const std::size_t n = found_.size();
  for (auto* v : {&samples_.px, &samples_.py, &samples_.pz}) v->resize(n);
  for (auto* v : {&samples_.nx, &samples_.ny, &samples_.nz}) v->resize(withNormals ? n : 0);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& p = samples.positions[found_[k].index];
    samples_.px[k] = p.x(), samples_.py[k] = p.y(), samples_.pz[k] = p.z();
  }
  if (withNormals) {
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3& nk = samples.normals[found_[k].index];
      samples_.nx[k] = nk.x(), samples_.ny[k] = nk.y(), samples_.nz[k] = nk.z();
    }
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
