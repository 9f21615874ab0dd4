// RegionGraph: Jaccard links between consecutive levels (Eq. 2.1), chains and persistence
// (Sec. 2.3.2-2.3.3), on plain index lists.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/RegionGraph.hpp"

using namespace scalespace;

TEST(RegionGraph, ChainsJaccardAndPersistence) {
  EXPECT_DOUBLE_EQ(jaccardIndex({1, 2, 3, 4}, {3, 4, 5}), 2.0 / 5.0);
  EXPECT_DOUBLE_EQ(jaccardIndex({}, {}), 0.0);
  std::vector<RegionLevel> levels(4);
  for (int j = 0; j < 4; ++j) levels[std::size_t(j)].t = 0.1 * (j + 1);
  levels[0].regions = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  levels[1].regions = {{4, 5, 6}, {0, 1, 2, 3, 8}};  // J = 3/4 and 4/5
  levels[2].regions = {{0, 1, 2, 3, 4, 5, 6, 8}};    // J with {0,1,2,3,8}: 5/8 > 0.5
  levels[3].regions = {{0, 1, 2, 3}, {4, 5, 6, 8}};  // J = 4/8: not > 0.5
  const RegionGraph g = buildRegionGraph(levels, 9);
  EXPECT_EQ(g.successor[0], (std::vector<int>{1, 0}));
  EXPECT_EQ(g.successor[1], (std::vector<int>{-1, 0}));
  EXPECT_EQ(g.successor[2], (std::vector<int>{-1}));
  ASSERT_EQ(g.components.size(), 4u);
  EXPECT_EQ(g.components[0].birthLevel, 0);  // {0..3} -> {0..3,8} -> {0..6,8}
  EXPECT_EQ(g.components[0].deathLevel, 2);
  EXPECT_EQ(g.components[0].persistence(), 2);
  EXPECT_DOUBLE_EQ(g.components[0].deathScale, 0.3);
  EXPECT_EQ(g.components[1].persistence(), 1);  // {4..7} -> {4,5,6}
  EXPECT_EQ(g.components[2].birthLevel, 3);
  EXPECT_EQ(g.components[2].persistence(), 0);
  EXPECT_EQ(g.componentLabels(1), (std::vector<int>{0, 0, 0, 0, 1, 1, 1, -1, 0}));
  // Overlapping regions in one level are a caller bug.
  levels[3].regions.push_back({0});
  EXPECT_THROW(buildRegionGraph(levels, 9), OptionError);
  levels[3].regions.back() = {9};  // and so is a point past pointCount
  EXPECT_THROW(buildRegionGraph(levels, 9), OptionError);
}

TEST(RegionGraph, LabelQueriesOnAMembership) {
  // 3 points, 2 levels: component 0 (persistence 1) holds point 0 at level 0, component 1
  // (persistence 0) holds points 0 and 1 at level 1, point 2 is never held.
  PointMembership m;
  m.pointCount = 3;
  m.levelCount = 2;
  m.ids = {0, -1, -1, /* level 1 */ 1, 1, -1};
  const std::vector<int> persistence{1, 0};
  EXPECT_EQ(labelsByPersistence(m, persistence, 0), (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(labelsByPersistence(m, persistence, 1), (std::vector<int>{0, -1, -1}));
  EXPECT_EQ(labelsAtLevel(m, persistence, 1), (std::vector<int>{1, 1, -1}));
  EXPECT_EQ(labelsAtLevel(m, persistence, 1, 1), (std::vector<int>{-1, -1, -1}));
  EXPECT_THROW(labelsAtLevel(m, persistence, 2), OptionError);
  // Equal persistence: the lower id wins.
  EXPECT_EQ(labelsByPersistence(m, {0, 0}, 0), (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(nearestScaleIndex({0.1, 0.2, 0.4}, 0.27), 1);
  EXPECT_EQ(nearestScaleIndex({0.1, 0.2, 0.4}, 0.3), 2);  // log midpoint of 0.2, 0.4 is 0.283
  EXPECT_EQ(nearestScaleIndex({0.1, 0.2, 0.4}, 1e-9), 0);
  EXPECT_THROW(nearestScaleIndex({}, 1), OptionError);
  EXPECT_THROW(nearestScaleIndex({0.1}, -1), OptionError);
}

// A chain may bridge levels where its region was not found (maxGap): it then holds no region
// there, and only the levels where it was found count in its persistence.
TEST(RegionGraph, BridgesGapsWhenAsked) {
  std::vector<RegionLevel> levels(5);
  for (int j = 0; j < 5; ++j) levels[std::size_t(j)].t = 0.1 * (j + 1);
  levels[0].regions = {{0, 1, 2, 3}, {6, 7}};
  levels[1].regions = {{0, 1, 2, 3, 4}};
  levels[2].regions = {{5}};              // the first chain is not found here
  levels[3].regions = {{0, 1, 2, 3, 5}};  // J with level 1's {0..4}: 4/6
  levels[4].regions = {{6, 7}, {0, 1, 2, 3}};
  // Without bridges: {0..3} at 0-1, {6,7} at 0, {5} at 2, {0..3,5} at 3-4, {6,7} at 4.
  EXPECT_EQ(buildRegionGraph(levels, 8).components.size(), 5u);
  RegionLinkOptions bridging;
  bridging.maxGap = 2;
  const RegionGraph g = buildRegionGraph(levels, 8, bridging);
  ASSERT_EQ(g.components.size(), 4u);
  const GraphComponent& tube = g.components[0];
  EXPECT_EQ(tube.birthLevel, 0);
  EXPECT_EQ(tube.deathLevel, 4);
  EXPECT_EQ(tube.gapLevels, 1);
  EXPECT_EQ(tube.persistence(), 3);
  EXPECT_EQ(tube.regionAt, (std::vector<int>{0, 0, -1, 0, 1}));
  EXPECT_EQ(g.bridge[1][0], (std::pair<int, int>{3, 0}));
  // {6, 7} comes back after three missing levels: a gap of 3 > 2, so it is two components.
  EXPECT_EQ(g.components[1].persistence(), 0);
  EXPECT_EQ(g.componentLabels(2), (std::vector<int>{-1, -1, -1, -1, -1, 2, -1, -1}));
  EXPECT_EQ(g.components[3].birthLevel, 4);
  bridging.maxGap = 3;
  EXPECT_EQ(buildRegionGraph(levels, 8, bridging).components.size(), 3u);
  // The caller's test refuses a bridge (the tubes of both ends differ): no bridge is made.
  bridging.bridgeAllowed = [](const std::vector<RegionLevel>&, int, int, int, int) {
    return false;
  };
  EXPECT_EQ(buildRegionGraph(levels, 8, bridging).components.size(), 5u);
  bridging.maxGap = -1;
  EXPECT_THROW(buildRegionGraph(levels, 8, bridging), OptionError);
}

// Regions of different kinds are never linked, whatever their Jaccard index: the chain splits.
TEST(RegionGraph, KindsKeepChainsApart) {
  std::vector<RegionLevel> levels(3);
  for (int j = 0; j < 3; ++j) levels[std::size_t(j)].t = 0.1 * (j + 1);
  levels[0].regions = {{0, 1, 2, 3}};
  levels[1].regions = {{0, 1, 2, 3, 4}};
  levels[2].regions = {{0, 1, 2, 3, 4, 5}};
  EXPECT_EQ(buildRegionGraph(levels, 6).components.size(), 1u);
  const std::vector<std::vector<std::uint8_t>> kinds{{1}, {1}, {0}};
  RegionLinkOptions byKind;
  byKind.kinds = &kinds;
  const RegionGraph g = buildRegionGraph(levels, 6, byKind);
  ASSERT_EQ(g.components.size(), 2u);
  EXPECT_EQ(g.components[0].deathLevel, 1);
  EXPECT_EQ(g.components[1].birthLevel, 2);
  const std::vector<std::vector<std::uint8_t>> wrongSize{{1}, {1}};
  byKind.kinds = &wrongSize;
  EXPECT_THROW(buildRegionGraph(levels, 6, byKind), OptionError);
}

// A preferred component wins over a more persistent one; among preferred ones (or with no
// preference) the persistence decides.
TEST(RegionGraph, PreferredComponentsWinThePersistenceLabels) {
  PointMembership m;
  m.pointCount = 3;
  m.levelCount = 2;
  m.ids = {0, 0, -1, /* level 1 */ 1, 2, 2};
  const std::vector<int> persistence{1, 5, 3};
  EXPECT_EQ(labelsByPersistence(m, persistence, 0), (std::vector<int>{1, 2, 2}));
  const std::vector<std::uint8_t> preferred{1, 0, 1};
  EXPECT_EQ(labelsByPersistence(m, persistence, 0, &preferred), (std::vector<int>{0, 2, 2}));
  EXPECT_EQ(labelsByPersistence(m, persistence, 2, &preferred), (std::vector<int>{1, 2, 2}));
  const std::vector<std::uint8_t> short_{1};
  EXPECT_THROW(labelsByPersistence(m, persistence, 0, &short_), OptionError);
}

// Not in the thesis (RegionLinkOptions::nestedAllowed): a region holding more than half of a
// smaller one's points links to it where J does not when the caller's test agrees, the largest
// overlap first, between consecutive levels and across a gap.
TEST(RegionGraph, NestedRegionsLinkWhenTheCallerAgrees) {
  std::vector<RegionLevel> levels(4);
  for (int j = 0; j < 4; ++j) levels[std::size_t(j)].t = 0.1 * (j + 1);
  levels[0].regions = {{0, 1, 2}, {3, 4, 5, 6}};  // two pieces of level 1's first region
  levels[1].regions = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, {20, 21, 22}};  // J 3/10 and 4/10
  levels[2].regions = {{30}};                              // the second chain is missing here
  levels[3].regions = {{20, 21, 22, 23, 24, 25, 26, 27}};  // J with {20, 21, 22}: 3/8
  EXPECT_EQ(buildRegionGraph(levels, 31).components.size(), 6u);

  RegionLinkOptions nested;
  nested.maxGap = 1;
  nested.nestedAllowed = [](const std::vector<RegionLevel>&, int, int, int, int) { return true; };
  RegionGraph g = buildRegionGraph(levels, 31, nested);
  ASSERT_EQ(g.components.size(), 4u);
  EXPECT_EQ(g.successor[0], (std::vector<int>{-1, 0}));  // 4 shared points beat 3
  EXPECT_EQ(g.components[1].persistence(), 1);
  EXPECT_EQ(g.bridge[1][1], (std::pair<int, int>{3, 0}));
  EXPECT_EQ(g.components[2].regionAt, (std::vector<int>{1, -1, 0}));
  EXPECT_EQ(g.components[2].persistence(), 1);

  // The test sees the levels: refusing the piece of 4 points lets the piece of 3 link.
  nested.nestedAllowed = [](const std::vector<RegionLevel>& l, int j, int r, int, int) {
    return l[std::size_t(j)].regions[std::size_t(r)].size() != 4;
  };
  g = buildRegionGraph(levels, 31, nested);
  EXPECT_EQ(g.successor[0], (std::vector<int>{0, -1}));
  // Without gaps allowed, no nested bridge either.
  nested.maxGap = 0;
  EXPECT_EQ(buildRegionGraph(levels, 31, nested).components.size(), 5u);
  // A piece under a quarter of the larger region does not link, unless the ratio allows it.
  levels[0].regions = {{0, 1}};
  EXPECT_EQ(buildRegionGraph(levels, 31, nested).successor[0], (std::vector<int>{-1}));
  nested.nestedMinSizeRatio = 0.2;
  EXPECT_EQ(buildRegionGraph(levels, 31, nested).successor[0], (std::vector<int>{0}));
  nested.nestedMinSizeRatio = 0;
  EXPECT_THROW(buildRegionGraph(levels, 31, nested), OptionError);
  nested.nestedMinSizeRatio = 0.25;
  // An overlap of half the smaller region is not more than half: no link.
  levels[0].regions = {{0, 1, 20, 21}};
  levels[1].regions = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, {30, 31}};
  levels[2].regions.clear();
  levels[3].regions.clear();
  EXPECT_EQ(buildRegionGraph(levels, 32, nested).successor[0], (std::vector<int>{-1}));
}
