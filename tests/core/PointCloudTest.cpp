#include <gtest/gtest.h>

#include "scalespace/core/PointCloud.hpp"

using namespace scalespace;

TEST(PointCloud, RecentringIsExactForGeoreferencedCoordinates) {
  std::vector<Vec3> abs = {{652341.123456789, 5412345.987654321, 312.25},
                           {652342.5, 5412346.75, 313.125},
                           {652340.0000001, 5412344.0000003, 311.0}};
  PointCloud cloud;
  cloud.setAbsolutePositions(abs);
  EXPECT_GT(cloud.origin().norm(), 1e5);
  for (std::size_t i = 0; i < abs.size(); ++i) {
    EXPECT_LT(cloud.positions()[i].norm(), 10.0);
    EXPECT_EQ(cloud.absolutePosition(i), abs[i]);  // bit-exact
  }
}

TEST(PointCloud, AttributesFollowSubsetAndResize) {
  PointCloud cloud;
  cloud.setAbsolutePositions({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
  auto& c = cloud.addAttribute("intensity", ScalarType::UInt16);
  c.values = {10, 20, 30};
  cloud.setNormals({Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY()});
  PointCloud sub = cloud.subset({2, 0});
  ASSERT_EQ(sub.size(), 2u);
  EXPECT_EQ(sub.findAttribute("intensity")->values[0], 30);
  EXPECT_EQ(sub.findAttribute("intensity")->type, ScalarType::UInt16);
  EXPECT_EQ(sub.normals()[0], Vec3::UnitY());
  EXPECT_EQ(sub.positions()[1], Vec3(0, 0, 0));
  EXPECT_THROW(cloud.setNormals({Vec3::UnitZ()}), std::exception);
}

TEST(PointCloud, RecentringNearTheLargestDoubleStaysFinite) {
  // lo + hi overflows here; the origin must not (readers cap coordinates, the core must not rely
  // on it).
  const std::vector<Vec3> abs = {{1.5e308, -1.5e308, 0.0}, {1.6e308, -1.6e308, 1.0}};
  PointCloud cloud;
  cloud.setAbsolutePositions(abs);
  ASSERT_TRUE(cloud.origin().allFinite());
  for (std::size_t i = 0; i < abs.size(); ++i) {
    ASSERT_TRUE(cloud.positions()[i].allFinite());
    EXPECT_EQ(cloud.absolutePosition(i), abs[i]);
  }
}
