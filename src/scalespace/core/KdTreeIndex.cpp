#include "scalespace/core/KdTreeIndex.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <nanoflann.hpp>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/RadixSort.hpp"

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

// Exact duplicates share one slot of the tree (see Tree); a slot's points are these original
// indices, ascending. Without duplicates every group is its slot's one point.
struct Groups {
  const Index* original;  // slot -> original index (no duplicates in the cloud)
  const Index* start;     // with duplicates: slot -> first of its members
  const Index* members;   // with duplicates: original indices, ascending within a slot
  template <class Visit>
  void forEach(Index slot, Visit&& visit) const {
    if (!start) {
      visit(original[slot]);
      return;
    }
    for (Index m = start[slot]; m < start[slot + 1]; ++m)
      if (!visit(members[m])) return;
  }
};

// Result set for radius search: writes straight into the caller's vector (no pair copies).
struct RadiusCollector {
  const Vec3* slots;
  Groups groups;
  Vec3 q;
  double r2;
  double bound;
  std::vector<Neighbor>* out;

  std::size_t size() const { return out->size(); }
  bool full() const { return true; }
  double worstDist() const { return bound; }
  bool addPoint(double, Index slot) {
    const double d2 = (slots[slot] - q).squaredNorm();
    if (d2 < r2)
      groups.forEach(slot, [&](Index i) {
        out->push_back({i, d2});
        return true;
      });
    return true;
  }
};

// Result set for knn: keeps `out` sorted by (distance, original index), at most k entries.
struct KnnCollector {
  const Vec3* slots;
  Groups groups;
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
    const double d2 = (slots[slot] - q).squaredNorm();
    // A group's members come in ascending index at one distance: once one is not kept, none of
    // the rest is, so a thousand duplicates cost what k do.
    groups.forEach(slot, [&](Index i) { return insert(Neighbor{i, d2}); });
    return true;
  }
  bool insert(const Neighbor& n) {
    if (full()) {
      if (!less(n, out->back())) return false;
      out->pop_back();
    }
    // Insertion from the back: cheaper than a max-heap (std::push_heap/pop_heap, sorted at the
    // end) for the small k of the fits (kNN rows of bench/bench_spatial_index.cpp).
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

namespace {

std::uint64_t positionHash(const Vec3& p) {
  std::uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (int c = 0; c < 3; ++c) {
    double v = p[c] + 0.0;  // -0 and +0 are one position
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 0xff51afd7ed558ccdULL;
    h ^= h >> 32;
  }
  return h;
}

/// For each point, the first point with the same position (itself when it has no earlier
/// duplicate); empty when all positions are distinct. Hashes sorted by a radix sort, then exact
/// comparisons within runs of equal hash: linear time, also when every point is the same.
std::vector<Index> firstOfDuplicates(const std::vector<Vec3>& points) {
  std::vector<KeyedIndex> items(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) items[i] = {positionHash(points[i]), Index(i)};
  radixSortStable(items);
  std::vector<Index> first;
  std::vector<Index> heads;  // distinct positions of the current run of equal hashes
  for (std::size_t a = 0; a < items.size();) {
    std::size_t b = a + 1;
    while (b < items.size() && items[b].key == items[a].key) ++b;
    if (b - a > 1) {
      if (first.empty()) {
        first.resize(points.size());
        for (std::size_t i = 0; i < points.size(); ++i) first[i] = Index(i);
      }
      heads.clear();
      for (std::size_t k = a; k < b; ++k) {  // ascending index (stable sort)
        const Index i = items[k].index;
        auto same = std::find_if(heads.begin(), heads.end(),
                                 [&](Index h) { return points[h] == points[i]; });
        if (same == heads.end())
          heads.push_back(i);
        else
          first[i] = *same;
      }
    }
    a = b;
  }
  bool any = false;
  for (std::size_t i = 0; i < first.size() && !any; ++i) any = first[i] != Index(i);
  if (!any) first.clear();
  return first;
}

}  // namespace

// Exact duplicates (scans repeat points: overlapping strips, zero returns, pasted tiles) become
// one slot whose members are listed in `members`: a kd-tree over N copies of a point has no split
// that separates them, so every query would visit all N.
struct KdTreeIndex::Tree {
  std::vector<Vec3> slots;      // distinct finite points, in the tree's leaf order after the build
  std::vector<Index> original;  // slot -> index in the caller's vector (no duplicates)
  std::vector<Index> start;     // with duplicates: slot -> its first member; size slots + 1
  std::vector<Index> members;   // with duplicates: original indices, ascending per slot
  PointsAdaptor adaptor{&slots};
  std::unique_ptr<NanoTree> tree;

  Groups groups() const {
    return start.empty() ? Groups{original.data(), nullptr, nullptr}
                         : Groups{nullptr, start.data(), members.data()};
  }
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
  // Group duplicates: slots keep one copy of each position; group g's members are
  // groupMembers[groupStart[g] .. groupStart[g + 1]), ascending.
  std::vector<Index> groupStart, groupMembers;
  if (const std::vector<Index> first = firstOfDuplicates(t.slots); !first.empty()) {
    std::vector<Index> groupOf(t.slots.size());
    std::vector<Vec3> distinct;
    for (std::size_t s = 0; s < t.slots.size(); ++s) {
      if (first[s] == Index(s)) {
        groupOf[s] = Index(distinct.size());
        distinct.push_back(t.slots[s]);
        groupStart.push_back(0);
      } else {
        groupOf[s] = groupOf[first[s]];  // first[s] < s: already assigned
      }
      ++groupStart[groupOf[s]];
    }
    groupStart.push_back(0);
    Index sum = 0;
    for (Index& c : groupStart) c = std::exchange(sum, sum + c);
    groupMembers.resize(t.slots.size());
    std::vector<Index> fill(groupStart.begin(), groupStart.end() - 1);
    for (std::size_t s = 0; s < t.slots.size(); ++s)  // ascending: s and original[s] increase
      groupMembers[fill[groupOf[s]]++] = t.original[s];
    t.slots.swap(distinct);
    t.original.clear();
  }
  t.tree = std::make_unique<NanoTree>(3, t.adaptor,
                                      nanoflann::KDTreeSingleIndexAdaptorParams(options.leafSize));
  // Store the points in leaf order and make the tree's accessor the identity, so that scanning
  // a leaf reads consecutive memory. Leaves refer to ranges of vAcc, which stay valid.
  std::vector<Index>& order = t.tree->vAcc;
  std::vector<Vec3> slots(t.slots.size());
  for (std::size_t s = 0; s < order.size(); ++s) slots[s] = t.slots[order[s]];
  if (groupStart.empty()) {
    std::vector<Index> original(t.slots.size());
    for (std::size_t s = 0; s < order.size(); ++s) original[s] = t.original[order[s]];
    t.original.swap(original);
  } else {
    t.start.reserve(order.size() + 1);
    t.members.reserve(groupMembers.size());
    for (std::size_t s = 0; s < order.size(); ++s) {
      t.start.push_back(Index(t.members.size()));
      t.members.insert(t.members.end(), groupMembers.begin() + groupStart[order[s]],
                       groupMembers.begin() + groupStart[order[s] + 1]);
    }
    t.start.push_back(Index(t.members.size()));
  }
  for (std::size_t s = 0; s < order.size(); ++s) order[s] = Index(s);
  t.slots.swap(slots);
}

KdTreeIndex::~KdTreeIndex() = default;

void KdTreeIndex::radiusSearch(const Vec3& q, double radius, std::vector<Neighbor>& out) const {
  out.clear();
  const Tree& t = *tree_;
  if (!t.tree || !(radius > 0.0) || !q.allFinite()) return;
  const double r2 = radius * radius;
  RadiusCollector collector{t.slots.data(), t.groups(), q, r2, widen(r2), &out};
  t.tree->findNeighbors(collector, q.data(), nanoflann::SearchParams(32, 0.0f, false));
}

void KdTreeIndex::knnSearch(const Vec3& q, std::size_t k, std::vector<Neighbor>& out) const {
  out.clear();
  const Tree& t = *tree_;
  if (!t.tree || k == 0 || !q.allFinite()) return;
  k = std::min(k, t.start.empty() ? t.slots.size() : t.members.size());
  out.reserve(k);
  KnnCollector collector{t.slots.data(), t.groups(), q, k, &out};
  t.tree->findNeighbors(collector, q.data(), nanoflann::SearchParams());
}

}  // namespace scalespace
