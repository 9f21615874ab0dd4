#pragma once
// Union-find over indices 0..n-1, with path halving and union by size: the MST of the normal
// orientation (Kruskal) and the joining of feature-curve pieces share it.
#include <utility>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n), size_(n, 1) {
    for (std::size_t i = 0; i < n; ++i) parent_[i] = Index(i);
  }
  Index find(Index x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /// Joins the sets of a and b; false when they were one already. Ties go to the smaller root, so
  /// the roots depend on the unions made, not on the order of equal-size sets' indices.
  bool unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b] || (size_[a] == size_[b] && a > b)) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }

 private:
  std::vector<Index> parent_;
  std::vector<Index> size_;
};

}  // namespace scalespace
