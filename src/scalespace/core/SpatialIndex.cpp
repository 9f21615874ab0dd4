#include "scalespace/core/SpatialIndex.hpp"

#include <algorithm>

namespace scalespace {

void BruteForceIndex::radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const {
  out.clear();
  const double r2 = radius * radius;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const double d2 = (points_[i] - q).squaredNorm();
    if (d2 < r2) out.push_back({Index(i), d2});
  }
}

void BruteForceIndex::knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const {
  out.clear();
  out.reserve(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i)
    out.push_back({Index(i), (points_[i] - q).squaredNorm()});
  k = std::min(k, out.size());
  // Ties broken by index so results are deterministic.
  auto less = [](const Neighbor& a, const Neighbor& b) {
    return a.distSq < b.distSq || (a.distSq == b.distSq && a.index < b.index);
  };
  std::partial_sort(out.begin(), out.begin() + k, out.end(), less);
  out.resize(k);
}

}  // namespace scalespace

#include "scalespace/core/KdTreeIndex.hpp"
namespace scalespace {
std::unique_ptr<SpatialIndex> makeSpatialIndex(const std::vector<Vec3>& points) {
  return std::make_unique<KdTreeIndex>(points);
}
}  // namespace scalespace
