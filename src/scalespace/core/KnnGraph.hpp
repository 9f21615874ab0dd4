#pragma once
// The k-nearest-neighbour graph of a cloud (Sec. 2.3.1: k = 10), the neighbourhood structure the
// region grower (core/RegionGrower.hpp) walks, with a Morton-ordered copy for that walk.
#include <cstddef>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// Directed k-nearest-neighbour graph (self excluded), compressed rows: the neighbours of point i
/// are neighbors[offsets[i] .. offsets[i+1]).
struct KnnGraph {
  std::vector<std::size_t> offsets;
  std::vector<Index> neighbors;
  std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  /// The same graph renumbered along a Morton curve (filled by buildKnnGraph; may be empty):
  /// vertex v is point order[v], point i is vertex rank[i], and the neighbours of vertex v are
  /// the vertices localNeighbors[offsets[v] .. offsets[v+1]) (every point has the same number of
  /// neighbours, so the offsets are shared). Region growing walks this one: in input order the
  /// neighbours of a point lie anywhere in memory and the walk waits on cache misses.
  std::vector<Index> order, rank, localNeighbors;
  /// Per point, the distance to its k-th nearest other point (knnRadii of scales/ScaleSeries with
  /// K = k, from the same queries): its median is the automatic t_min of the stack, which then
  /// needs no second round of k-NN queries (filled by buildKnnGraph when n > k).
  std::vector<double> kthDistance;
};

/// Builds the graph with makeSpatialIndex (k = 10 in Sec. 2.3.1). Parallel; deterministic.
KnnGraph buildKnnGraph(const std::vector<Vec3>& positions, std::size_t k = 10,
                       const ProgressCallback& progress = {});

}  // namespace scalespace
