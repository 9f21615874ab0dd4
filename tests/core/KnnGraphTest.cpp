// KnnGraph: the rows are the brute-force k nearest other points, and the Morton-ordered copy is
// the same graph renumbered.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "CoreTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/SpatialIndex.hpp"

using namespace scalespace;

TEST(KnnGraph, RowsAreTheBruteForceNearestOtherPoints) {
  const std::vector<Vec3> pts = testclouds::uniformCube(700, 11);
  const std::size_t k = 6;
  const KnnGraph graph = buildKnnGraph(pts, k);
  ASSERT_EQ(graph.size(), pts.size());
  const BruteForceIndex brute(pts);
  std::vector<Neighbor> found;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_EQ(graph.offsets[i + 1] - graph.offsets[i], k);
    brute.knnSearch(pts[i], k + 1, found);
    std::vector<Index> expected;
    for (const Neighbor& nb : found)
      if (nb.index != i) expected.push_back(nb.index);
    expected.resize(k);
    std::vector<Index> row(graph.neighbors.begin() + std::ptrdiff_t(graph.offsets[i]),
                           graph.neighbors.begin() + std::ptrdiff_t(graph.offsets[i + 1]));
    std::sort(row.begin(), row.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(row, expected) << i;
  }
}

TEST(KnnGraph, MortonCopyIsTheSameGraphRenumbered) {
  const std::vector<Vec3> pts = testclouds::uniformCube(500, 3);
  const KnnGraph graph = buildKnnGraph(pts, 10);
  const std::size_t n = pts.size();
  ASSERT_EQ(graph.order.size(), n);
  ASSERT_EQ(graph.rank.size(), n);
  ASSERT_EQ(graph.localNeighbors.size(), graph.neighbors.size());
  for (std::size_t v = 0; v < n; ++v) {
    const Index i = graph.order[v];
    ASSERT_EQ(graph.rank[i], v);
    for (std::size_t e = 0; e < 10; ++e)
      EXPECT_EQ(graph.order[graph.localNeighbors[graph.offsets[v] + e]],
                graph.neighbors[graph.offsets[i] + e]);
  }
  EXPECT_THROW(buildKnnGraph(pts, 0), OptionError);
  EXPECT_EQ(buildKnnGraph({}, 10).size(), 0u);
}
