#include "scalespace/core/KnnGraph.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/SpatialOrder.hpp"

namespace scalespace {

KnnGraph buildKnnGraph(const std::vector<Vec3>& positions, std::size_t k,
                       const ProgressCallback& progress) {
  if (k == 0) throw OptionError("the neighbour graph needs k >= 1");
  const std::size_t n = positions.size();
  KnnGraph graph;
  graph.offsets.resize(n + 1, 0);
  if (n == 0) return graph;
  const std::size_t perPoint = std::min(k, n - 1);
  graph.neighbors.resize(n * perPoint);
  for (std::size_t i = 0; i <= n; ++i) graph.offsets[i] = i * perPoint;
  const auto index = makeSpatialIndex(positions);
  if (n > k) graph.kthDistance.resize(n);
  // The queries run along the Morton curve: consecutive queries walk the same branches of the
  // tree (in input order, a scan's points may come in any order). Each query is independent, so
  // the graph is the same.
  graph.order = spatialOrder(positions);
  ProgressTracker tracker(progress, "neighbour graph", n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& range) {
    std::vector<Neighbor> found;
    for (std::size_t v = range.begin(); v != range.end(); ++v) {
      const std::size_t i = graph.order[v];
      index->knnSearch(positions[i], perPoint + 1, found);
      // The k + 1 nearest, the point itself included: what knnRadii queries for K = k.
      if (!graph.kthDistance.empty()) graph.kthDistance[i] = std::sqrt(found.back().distSq);
      std::size_t out = graph.offsets[i];
      for (const Neighbor& nb : found) {
        if (nb.index == i || out == graph.offsets[i + 1]) continue;
        graph.neighbors[out++] = nb.index;
      }
      // Duplicated points may push i itself out of its own k+1 list: fill with the farthest.
      while (out < graph.offsets[i + 1]) graph.neighbors[out++] = found.back().index;
    }
    tracker.advance(range.size());
  });
  tracker.finish();
  graph.rank.resize(n);
  for (std::size_t v = 0; v < n; ++v) graph.rank[graph.order[v]] = Index(v);
  graph.localNeighbors.resize(graph.neighbors.size());
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t v) {
    const std::size_t from = graph.offsets[graph.order[v]];
    for (std::size_t e = 0; e < perPoint; ++e)
      graph.localNeighbors[graph.offsets[v] + e] = graph.rank[graph.neighbors[from + e]];
  });
  return graph;
}

}  // namespace scalespace
