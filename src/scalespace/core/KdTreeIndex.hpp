#pragma once
// KdTreeIndex: the default SpatialIndex, a kd-tree (nanoflann 1.4.3) over a private copy of the
// points stored in the tree's leaf order, so that a leaf scan reads contiguous memory. Results are
// exactly those of BruteForceIndex: radius search keeps |p - q| < r (strict), knn is sorted by
// distance with ties broken by the smaller index, and distances are computed with the same
// expression (p - q).squaredNorm() so that the boundary decisions are bit-identical.
#include <memory>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {

struct KdTreeOptions {
  /// Maximum points per leaf: in the middle of the range of leaf sizes whose queries are fastest
  /// (leaf-size rows of bench/bench_spatial_index.cpp). Larger leaves build faster.
  std::size_t leafSize = 16;
};

class KdTreeIndex final : public SpatialIndex {
 public:
  /// Builds the tree (O(n log n)). The points are copied: `points` need not outlive the index.
  explicit KdTreeIndex(const std::vector<Vec3>& points, const KdTreeOptions& options = {});
  ~KdTreeIndex() override;
  KdTreeIndex(const KdTreeIndex&) = delete;
  KdTreeIndex& operator=(const KdTreeIndex&) = delete;

  void radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const override;
  void knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const override;
  std::size_t size() const override { return size_; }

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
  std::size_t size_ = 0;
};

}  // namespace scalespace
