// RegionGraph: Jaccard links between consecutive levels (Eq. 2.1), chains and persistence
// (Sec. 2.3.2-2.3.3), on plain index lists.
#include <gtest/gtest.h>

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
