#pragma once
// SpatialIndex: the small interface every algorithm uses for neighbour queries. Implementations:
// KdTreeIndex (nanoflann, points stored in spatial order) and BruteForceIndex (tests, reference).
// Queries are const and thread-safe: call them from many threads at once.
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

/// The most neighbours an option may ask a k-NN query for. A query keeps its k best sorted, so its
/// cost grows like k^2: 10^5 neighbours of 2*10^4 points ran for over ten minutes. Fits and normals
/// use 10-100; a larger k is better expressed as a radius.
constexpr std::size_t kMaxNeighborCount = 1000;

struct Neighbor {
  Index index;    // index into the positions the index was built on
  double distSq;  // squared Euclidean distance to the query
};

class SpatialIndex {
 public:
  virtual ~SpatialIndex() = default;
  /// All points with |p - q| < radius, in no particular order. `out` is cleared first.
  virtual void radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const = 0;
  /// The k nearest points (fewer if the cloud is smaller), sorted by increasing distance.
  virtual void knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const = 0;
  virtual std::size_t size() const = 0;
};

/// Exhaustive search: O(n) per query. The reference that tests compare every index against.
class BruteForceIndex final : public SpatialIndex {
 public:
  explicit BruteForceIndex(const std::vector<Vec3>& points) : points_(points) {}
  void radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const override;
  void knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const override;
  std::size_t size() const override { return points_.size(); }

 private:
  const std::vector<Vec3>& points_;
};

}  // namespace scalespace

#include <memory>
namespace scalespace {
/// The default index for `points` (a kd-tree). `points` must outlive the index.
std::unique_ptr<SpatialIndex> makeSpatialIndex(const std::vector<Vec3>& points);
}  // namespace scalespace
