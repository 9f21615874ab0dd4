#include <gtest/gtest.h>

#include <cmath>

#include "core/CoreTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/OccupancyGrid.hpp"

using namespace scalespace;

TEST(OccupancyGrid, RaysLeaveAClosedSphereOutwardAndAreStoppedInward) {
  const Vec3 centre(0.3, -0.2, 0.1);
  const auto points = testclouds::sphere(20000, 1.0, 7, centre);
  const OccupancyGrid grid(points, 0.05, std::size_t(1) << 24);
  EXPECT_DOUBLE_EQ(grid.cellSize(), 0.05);
  EXPECT_TRUE(grid.occupied(points[0]));
  EXPECT_FALSE(grid.occupied(centre));
  EXPECT_FALSE(grid.occupied(Vec3(9, 9, 9)));  // outside the grid
  std::size_t out = 0, in = 0;
  for (std::size_t i = 0; i < points.size(); i += 20) {
    const Vec3 radial = (points[i] - centre).normalized();
    out += grid.escapes(points[i], radial, 3) ? 1 : 0;
    in += grid.escapes(points[i], -radial, 3) ? 1 : 0;
  }
  EXPECT_EQ(out, 1000u);
  EXPECT_LT(in, 20u);  // a few slip through the gaps between samples
  // A ray along the surface stays in occupied cells: blocked once past `surfaceCells`.
  EXPECT_FALSE(grid.escapes(centre + Vec3(0, 0, 1), Vec3(1, 0, 0), 3));
}

// Five rays a side: a closed sphere's points see out on their outer side only, a flat sheet's
// on both.
TEST(OccupancyGrid, ASheetSeesOutOnBothSidesAClosedSurfaceOnOne) {
  const Vec3 centre(0.3, -0.2, 0.1);
  const auto sphere = testclouds::sphere(20000, 1.0, 7, centre);
  const OccupancyGrid closed(sphere, 0.05, std::size_t(1) << 24);
  std::size_t outward = 0, both = 0;
  for (std::size_t i = 0; i < sphere.size(); i += 20) {
    const Vec3 radial = (sphere[i] - centre).normalized();
    outward += closed.escapingRays(sphere[i], radial) >= 3 ? 1 : 0;
    both += closed.seesOutBothSides(sphere[i], radial) ? 1 : 0;
  }
  EXPECT_GT(outward, 990u);
  EXPECT_LT(both, 10u);
  std::vector<Vec3> sheet;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j) sheet.emplace_back(0.01 * i, 0.01 * j, 0.0);
  const OccupancyGrid open(sheet, 0.02, std::size_t(1) << 24);
  EXPECT_TRUE(open.seesOutBothSides(Vec3(0.5, 0.5, 0), Vec3::UnitZ()));
  EXPECT_EQ(open.escapingRays(Vec3(0.5, 0.5, 0), -Vec3::UnitZ()), 5);
}

TEST(OccupancyGrid, CellsGrowToStayWithinTheLimitAndBadInputIsRefused) {
  const auto points = testclouds::sphere(2000, 1.0, 8);
  const OccupancyGrid grid(points, 0.001, 1000);
  EXPECT_GT(grid.cellSize(), 0.001);
  const double side = 2.0 / grid.cellSize() + 3;
  EXPECT_LE(std::floor(side) * std::floor(side) * std::floor(side), 1000 * 1.2);
  EXPECT_THROW(OccupancyGrid(points, 0.0, 1000), OptionError);
  EXPECT_THROW(OccupancyGrid(points, std::nan(""), 1000), OptionError);
  const OccupancyGrid empty(std::vector<Vec3>{Vec3(std::nan(""), 0, 0)}, 1.0, 1000);
  EXPECT_FALSE(empty.occupied(Vec3::Zero()));
  EXPECT_TRUE(empty.escapes(Vec3::Zero(), Vec3::UnitX(), 3));
  // One point (a zero-size box): its grid is the padded cell around it.
  const OccupancyGrid single(std::vector<Vec3>{Vec3(1, 2, 3)}, 0.5, 1000);
  EXPECT_TRUE(single.occupied(Vec3(1, 2, 3)));
  EXPECT_TRUE(single.escapes(Vec3(1, 2, 3), Vec3::UnitZ(), 3));
}
