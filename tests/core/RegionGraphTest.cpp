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
  const RegionGraph g = buildRegionGraph(levels, 8, 0.5, nullptr, 2);
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
  EXPECT_EQ(buildRegionGraph(levels, 8, 0.5, nullptr, 3).components.size(), 3u);
  // The caller's test refuses a bridge (the tubes of both ends differ): no bridge is made.
  const BridgeTest never = [](int, int, int, int) { return false; };
  EXPECT_EQ(buildRegionGraph(levels, 8, 0.5, nullptr, 3, never).components.size(), 5u);
  EXPECT_THROW(buildRegionGraph(levels, 8, 0.5, nullptr, -1), OptionError);
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
  const RegionGraph g = buildRegionGraph(levels, 6, 0.5, &kinds);
  ASSERT_EQ(g.components.size(), 2u);
  EXPECT_EQ(g.components[0].deathLevel, 1);
  EXPECT_EQ(g.components[1].birthLevel, 2);
  const std::vector<std::vector<std::uint8_t>> wrongSize{{1}, {1}};
  EXPECT_THROW(buildRegionGraph(levels, 6, 0.5, &wrongSize), OptionError);
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
