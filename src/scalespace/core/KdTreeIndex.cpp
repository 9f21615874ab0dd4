#include "scalespace/core/KdTreeIndex.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nanoflann.hpp>

#include "scalespace/core/Error.hpp"

namespace scalespace {
namespace {

// nanoflann reads coordinates through this adaptor; the tree owns the storage (see Tree).
struct PointsAdaptor {
  const std::vector<Vec3>* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(Index i, std::size_t dim) const { return (*points)[i][dim]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using Metric = nanoflann::L2_Simple_Adaptor<double, PointsAdaptor, double, Index>;
using NanoTree = nanoflann::KDTreeSingleIndexAdaptor<Metric, PointsAdaptor, 3, Index>;

// nanoflann sums dx^2 + dy^2 + dz^2 in its own order and prunes with incrementally updated
// bounds; Eigen's squaredNorm may round differently in the last bits. The search bound handed to
// nanoflann is therefore widened by this relative margin (plus the smallest positive double, so a
// bound of 0 still admits exact duplicates), and every candidate is then re-tested with the exact
// expression BruteForceIndex uses. The margin only costs a few extra distance evaluations.
constexpr double kBoundMargin = 1e-9;
inline double widen(double d2) {
  return d2 + d2 * kBoundMargin + std::numeric_limits<double>::denorm_min();
}

// Result set for radius search: writes straight into the caller's vector (no pair copies).
struct RadiusCollector {
  const Vec3* slots;
  const Index* original;
  Vec3 q;
  double r2;
  double bound;
  std::vector<Neighbor>* out;

  std::size_t size() const { return out->size(); }
  bool full() const { return true; }
  double worstDist() const { return bound; }
  bool addPoint(double, Index slot) {
    const double d2 = (slots[slot] - q).squaredNorm();
    if (d2 < r2) out->push_back({original[slot], d2});
    return true;
  }
};

// Result set for knn: keeps `out` sorted by (distance, original index), at most k entries.
struct KnnCollector {
  const Vec3* slots;
  const Index* original;
  Vec3 q;
  std::size_t k;
  std::vector<Neighbor>* out;

  std::size_t size() const { return out->size(); }
  bool full() const { return out->size() == k; }
  double worstDist() const {
    return full() ? widen(out->back().distSq) : std::numeric_limits<double>::infinity();
  }
  static bool less(const Neighbor& a, const Neighbor& b) {
    return a.distSq < b.distSq || (a.distSq == b.distSq && a.index < b.index);
  }
  bool addPoint(double, Index slot) {
    const Neighbor n{original[slot], (slots[slot] - q).squaredNorm()};
    if (full()) {
      if (!less(n, out->back())) return true;
      out->pop_back();
    }
    // Insertion from the back. Measured against a max-heap (std::push_heap/pop_heap, sorted at
    // the end) on 1M points: the heap was 2-3x slower for k = 40 and ~1.5x for k = 10.
    out->push_back(n);
    std::size_t i = out->size() - 1;
    while (i > 0 && less(n, (*out)[i - 1])) {
      (*out)[i] = (*out)[i - 1];
      --i;
    }
    (*out)[i] = n;
    return true;
  }
};

}  // namespace

struct KdTreeIndex::Tree {
  std::vector<Vec3> slots;      // finite points, in the tree's leaf order after the build
  std::vector<Index> original;  // slot -> index in the caller's vector
  PointsAdaptor adaptor{&slots};
  std::unique_ptr<NanoTree> tree;
};

KdTreeIndex::KdTreeIndex(const std::vector<Vec3>& points, const KdTreeOptions& options)
    : tree_(std::make_unique<Tree>()), size_(points.size()) {
  if (options.leafSize == 0) throw OptionError("KdTreeOptions::leafSize must be >= 1");
  if (points.size() > std::size_t(std::numeric_limits<Index>::max()))
    throw OptionError("the kd-tree holds at most 2^32 - 1 points; split the cloud");
  Tree& t = *tree_;
  // Points with a non-finite coordinate are left out: no query can return them (a NaN distance
  // is never < r, as in BruteForceIndex) and they would break the tree's splits.
  t.slots.reserve(points.size());
  t.original.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    t.slots.push_back(points[i]);
    t.original.push_back(Index(i));
  }
  if (t.slots.empty()) return;
  t.tree = std::make_unique<NanoTree>(3, t.adaptor,
                                      nanoflann::KDTreeSingleIndexAdaptorParams(options.leafSize));
  // Store the points in leaf order and make the tree's accessor the identity, so that scanning
  // a leaf reads consecutive memory. Leaves refer to ranges of vAcc, which stay valid.
  std::vector<Index>& order = t.tree->vAcc;
  std::vector<Vec3> slots(t.slots.size());
  std::vector<Index> original(t.slots.size());
  for (std::size_t s = 0; s < order.size(); ++s) {
    slots[s] = t.slots[order[s]];
    original[s] = t.original[order[s]];
    order[s] = Index(s);
  }
  t.slots.swap(slots);
  t.original.swap(original);
}

KdTreeIndex::~KdTreeIndex() = default;

void KdTreeIndex::radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const {
  out.clear();
  const Tree& t = *tree_;
  if (!t.tree || !(radius > 0.0) || !q.allFinite()) return;
  const double r2 = radius * radius;
  RadiusCollector collector{t.slots.data(), t.original.data(), q, r2, widen(r2), &out};
  t.tree->findNeighbors(collector, q.data(), nanoflann::SearchParams(32, 0.0f, false));
}

void KdTreeIndex::knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const {
  out.clear();
  const Tree& t = *tree_;
  if (!t.tree || k == 0 || !q.allFinite()) return;
  k = std::min(k, t.slots.size());
  out.reserve(k);
  KnnCollector collector{t.slots.data(), t.original.data(), q, k, &out};
  t.tree->findNeighbors(collector, q.data(), nanoflann::SearchParams());
}

}  // namespace scalespace
