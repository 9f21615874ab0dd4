// RegionGrower: the generic seeded region growing of Sec. 2.3.1 against a plain breadth-first
// reference, the seed order, ineligible points, and the seed-order helper.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <vector>

#include "CoreTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/RegionGrower.hpp"

using namespace scalespace;

namespace {

// A point joins when its value is within `tolerance` of the seed's value.
struct NearSeedValue {
  const std::vector<double>& value;
  double tolerance;
  double payload(Index point) const { return value[point]; }
  bool accept(double seed, double, double candidate) const {
    return std::abs(candidate - seed) <= tolerance;
  }
};

// A point joins when its value is within `step` of the point it is reached from (and within
// `tolerance` of the seed's): a criterion that reads the edge, not only the seed.
struct SmallSteps {
  const std::vector<double>& value;
  double tolerance, step;
  double payload(Index point) const { return value[point]; }
  bool accept(double seed, double from, double candidate) const {
    return std::abs(candidate - seed) <= tolerance && std::abs(candidate - from) <= step;
  }
};

// The 4-neighbour graph of a width x height grid (point x + width * y), in input order only.
KnnGraph gridGraph(std::size_t width, std::size_t height) {
  KnnGraph g;
  g.offsets.push_back(0);
  for (std::size_t y = 0; y < height; ++y)
    for (std::size_t x = 0; x < width; ++x) {
      if (x > 0) g.neighbors.push_back(Index(x - 1 + width * y));
      if (x + 1 < width) g.neighbors.push_back(Index(x + 1 + width * y));
      if (y > 0) g.neighbors.push_back(Index(x + width * (y - 1)));
      if (y + 1 < height) g.neighbors.push_back(Index(x + width * (y + 1)));
      g.offsets.push_back(g.neighbors.size());
    }
  return g;
}

// The definition, written plainly: for each seed in turn that is free and eligible, a
// breadth-first search over the graph's edges (input numbering) through free eligible points
// accepted against the seed.
template <class Criterion>
Segmentation referenceGrow(const KnnGraph& graph, const std::vector<Index>& seeds,
                           const std::vector<std::uint8_t>& eligible, const Criterion& criterion) {
  Segmentation seg;
  seg.labels.assign(graph.size(), -1);
  for (const Index seed : seeds) {
    if (!eligible[seed] || seg.labels[seed] >= 0) continue;
    const int id = int(seg.regions.size());
    std::vector<Index> region{seed};
    seg.labels[seed] = id;
    std::queue<Index> queue;
    queue.push(seed);
    while (!queue.empty()) {
      const Index p = queue.front();
      queue.pop();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        const Index q = graph.neighbors[e];
        if (!eligible[q] || seg.labels[q] >= 0 ||
            !criterion.accept(criterion.payload(seed), criterion.payload(p), criterion.payload(q)))
          continue;
        seg.labels[q] = id;
        region.push_back(q);
        queue.push(q);
      }
    }
    std::sort(region.begin(), region.end());
    seg.regions.push_back(std::move(region));
  }
  return seg;
}

// The grower's regions, checked against the reference's.
template <class Criterion>
Segmentation grownLikeTheReference(const KnnGraph& graph, const std::vector<Index>& seeds,
                                   const std::vector<std::uint8_t>& eligible,
                                   const Criterion& criterion) {
  const Segmentation seg = growRegionsFromSeeds(graph, seeds, eligible, criterion);
  const Segmentation expected = referenceGrow(graph, seeds, eligible, criterion);
  EXPECT_EQ(seg.labels, expected.labels);
  EXPECT_EQ(seg.regions, expected.regions);
  return seg;
}

std::vector<Index> allPointsInOrder(std::size_t n) {
  std::vector<Index> seeds(n);
  for (std::size_t i = 0; i < n; ++i) seeds[i] = Index(i);
  return seeds;
}

}  // namespace

TEST(RegionGrower, LineOfValuesKnownAnswerFollowsTheSeedOrder) {
  // Values 0 1 2 3 4 on a path graph, tolerance 1 against the SEED's value: a region spans at
  // most the seed and its neighbours within 1, and which ones depends on which seed comes first.
  const KnnGraph line = gridGraph(5, 1);
  const std::vector<double> value{0, 1, 2, 3, 4};
  const std::vector<std::uint8_t> eligible(5, 1);
  const NearSeedValue criterion{value, 1.0};
  const Segmentation forward = growRegionsFromSeeds(line, {0, 1, 2, 3, 4}, eligible, criterion);
  EXPECT_EQ(forward.regions, (std::vector<std::vector<Index>>{{0, 1}, {2, 3}, {4}}));
  EXPECT_EQ(forward.labels, (std::vector<int>{0, 0, 1, 1, 2}));
  const Segmentation backward = growRegionsFromSeeds(line, {4, 3, 2, 1, 0}, eligible, criterion);
  EXPECT_EQ(backward.regions, (std::vector<std::vector<Index>>{{3, 4}, {1, 2}, {0}}));
  const Segmentation middle = growRegionsFromSeeds(line, {2, 0, 4}, eligible, criterion);
  EXPECT_EQ(middle.regions, (std::vector<std::vector<Index>>{{1, 2, 3}, {0}, {4}}));
  // Points that are no seed and that no region reaches stay unlabelled.
  const Segmentation one = growRegionsFromSeeds(line, {0}, eligible, criterion);
  EXPECT_EQ(one.labels, (std::vector<int>{0, 0, -1, -1, -1}));
}

// A terrace: values 0 0 0 1 1 1 on a path. Against the seed alone (tolerance 2) it is one region;
// with steps of at most 0.5 between neighbours, the jump splits it, whatever the seed order.
TEST(RegionGrower, AStepLargerThanAllowedSplitsARegionTheSeedWouldAccept) {
  const KnnGraph line = gridGraph(6, 1);
  const std::vector<double> value{0, 0, 0, 1, 1, 1};
  const std::vector<std::uint8_t> eligible(6, 1);
  EXPECT_EQ(
      grownLikeTheReference(line, allPointsInOrder(6), eligible, NearSeedValue{value, 2.0}).regions,
      (std::vector<std::vector<Index>>{{0, 1, 2, 3, 4, 5}}));
  const SmallSteps steps{value, 2.0, 0.5};
  EXPECT_EQ(grownLikeTheReference(line, allPointsInOrder(6), eligible, steps).regions,
            (std::vector<std::vector<Index>>{{0, 1, 2}, {3, 4, 5}}));
  EXPECT_EQ(grownLikeTheReference(line, {5, 0}, eligible, steps).regions,
            (std::vector<std::vector<Index>>{{3, 4, 5}, {0, 1, 2}}));
}

// On a grid, a field with ramps and cliffs: the step criterion gives the reference's regions.
TEST(RegionGrower, StepCriterionOnAGridMatchesTheBreadthFirstReference) {
  const std::size_t w = 40, h = 30;
  const KnnGraph grid = gridGraph(w, h);
  std::vector<double> value(w * h);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x)
      value[x + w * y] = 0.05 * double(x) + (x % 13 == 0 ? 1.0 : 0.0) + (y > 17 ? 2.0 : 0.0);
  std::vector<std::uint8_t> eligible(w * h, 1);
  for (std::size_t i = 0; i < eligible.size(); i += 29) eligible[i] = 0;
  std::vector<Index> seeds = allPointsInOrder(w * h);
  std::reverse(seeds.begin(), seeds.end());
  const Segmentation seg =
      grownLikeTheReference(grid, seeds, eligible, SmallSteps{value, 0.6, 0.3});
  EXPECT_GT(seg.regions.size(), 4u);
}

TEST(RegionGrower, IneligiblePointsJoinNothingAndBlockTheWay) {
  // One value everywhere: without the ineligible middle column the grid would be one region.
  const KnnGraph grid = gridGraph(5, 3);
  const std::vector<double> value(15, 7.0);
  std::vector<std::uint8_t> eligible(15, 1);
  for (std::size_t y = 0; y < 3; ++y) eligible[2 + 5 * y] = 0;
  const Segmentation seg =
      growRegionsFromSeeds(grid, allPointsInOrder(15), eligible, NearSeedValue{value, 0.0});
  ASSERT_EQ(seg.regions.size(), 2u);
  EXPECT_EQ(seg.regions[0], (std::vector<Index>{0, 1, 5, 6, 10, 11}));
  EXPECT_EQ(seg.regions[1], (std::vector<Index>{3, 4, 8, 9, 13, 14}));
  for (std::size_t y = 0; y < 3; ++y) EXPECT_EQ(seg.labels[2 + 5 * y], -1);
  // An ineligible seed is skipped, not grown.
  const Segmentation fromIneligible =
      growRegionsFromSeeds(grid, {2, 7, 12}, eligible, NearSeedValue{value, 0.0});
  EXPECT_TRUE(fromIneligible.regions.empty());
  EXPECT_EQ(fromIneligible.labels, std::vector<int>(15, -1));
}

TEST(RegionGrower, ScalarFieldOnAGridMatchesTheBreadthFirstReference) {
  // A smooth field plus noise on a 60 x 40 grid, a tolerance that cuts it into many regions,
  // seeds in a shuffled order, some points ineligible.
  const std::size_t width = 60, height = 40, n = width * height;
  const KnnGraph grid = gridGraph(width, height);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  std::vector<double> value(n);
  std::vector<std::uint8_t> eligible(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = double(i % width), y = double(i / width);
    value[i] = std::sin(0.15 * x) + std::cos(0.2 * y) + noise(rng);
    eligible[i] = i % 13 != 0;
  }
  std::vector<Index> seeds = allPointsInOrder(n);
  std::shuffle(seeds.begin(), seeds.end(), rng);
  const Segmentation seg = grownLikeTheReference(grid, seeds, eligible, NearSeedValue{value, 0.2});
  EXPECT_GT(seg.regions.size(), 20u);
  // Every eligible point is in a region (all are seeds); each region lies within the tolerance
  // of its seed, so within twice the tolerance of any of its points.
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seg.labels[i] >= 0, eligible[i] != 0) << i;
  for (const auto& region : seg.regions) {
    const auto [low, high] = std::minmax_element(
        region.begin(), region.end(), [&](Index a, Index b) { return value[a] < value[b]; });
    EXPECT_LE(value[*high] - value[*low], 0.4 + 1e-12);
  }
}

TEST(RegionGrower, MortonOrderedGraphGivesTheReferenceRegions) {
  // buildKnnGraph's graph has the Morton-ordered copy the grower walks; the result is the
  // reference's (which walks the input numbering), and the same again on a second run.
  const std::vector<Vec3> pts = testclouds::uniformCube(4000, 5);
  const KnnGraph graph = buildKnnGraph(pts, 8);
  ASSERT_EQ(graph.order.size(), pts.size());
  std::vector<double> value(pts.size());
  std::vector<std::uint8_t> eligible(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    value[i] = std::floor(4 * pts[i].x()) + 0.3 * pts[i].y();
    eligible[i] = i % 7 != 3;
  }
  const std::vector<Index> seeds =
      seedsByIncreasingKey(pts.size(), [&](Index i) { return pts[i].z(); });
  const NearSeedValue criterion{value, 0.1};
  const Segmentation seg = grownLikeTheReference(graph, seeds, eligible, criterion);
  EXPECT_GT(seg.regions.size(), 4u);
  const Segmentation again = growRegionsFromSeeds(graph, seeds, eligible, criterion);
  EXPECT_EQ(again.labels, seg.labels);
}

TEST(RegionGrower, SeedsByIncreasingKeyBreakTiesByIndexAndSkipNonFiniteKeys) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> key{2.0, -1.0, nan, 2.0, 0.0, inf, -0.5, 0.0};
  const std::vector<Index> seeds =
      seedsByIncreasingKey(key.size(), [&](Index i) { return key[i]; });
  EXPECT_EQ(seeds, (std::vector<Index>{1, 6, 4, 7, 0, 3}));
  EXPECT_TRUE(seedsByIncreasingKey(0, [](Index) { return 0.0; }).empty());
}

TEST(RegionGrower, RejectsMismatchedEligibilityAndSeedsOutOfRange) {
  const KnnGraph line = gridGraph(4, 1);
  const std::vector<double> value(4, 0.0);
  const NearSeedValue criterion{value, 0.0};
  EXPECT_THROW(growRegionsFromSeeds(line, {0}, std::vector<std::uint8_t>(3, 1), criterion),
               OptionError);
  EXPECT_THROW(growRegionsFromSeeds(line, {0, 4}, std::vector<std::uint8_t>(4, 1), criterion),
               OptionError);
  const Segmentation empty =
      growRegionsFromSeeds(KnnGraph{}, {}, std::vector<std::uint8_t>{}, criterion);
  EXPECT_TRUE(empty.labels.empty());
  EXPECT_TRUE(empty.regions.empty());
}
