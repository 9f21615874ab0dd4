#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <limits>

#include "scalespace/core/Error.hpp"
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

TEST(PointCloud, ColumnReferencesSurviveAddingColumnsAndCopiesAreDeep) {
  PointCloud cloud;
  cloud.setAbsolutePositions({{0, 0, 0}, {1, 0, 0}});
  AttributeColumn& first = cloud.addAttribute("first", ScalarType::Int32);
  const double* data = first.values.data();
  for (int c = 0; c < 100; ++c) cloud.addAttribute("c" + std::to_string(c), ScalarType::Float32);
  first.values[1] = 7;  // would write freed memory if columns moved (ASan build)
  EXPECT_EQ(&first, cloud.findAttribute("first"));
  EXPECT_EQ(first.values.data(), data);
  EXPECT_EQ(cloud.attributes().size(), 101u);
  EXPECT_EQ(cloud.attributes().front().values[1], 7);
  PointCloud copy = cloud;
  copy.findAttribute("first")->values[1] = 8;
  EXPECT_EQ(first.values[1], 7);
  EXPECT_TRUE(cloud.removeAttribute("c50"));
  EXPECT_EQ(&first, cloud.findAttribute("first"));
  std::vector<std::string> names;
  for (const AttributeColumn& a : copy.attributes()) names.push_back(a.name);
  EXPECT_EQ(names.size(), 101u);
  EXPECT_EQ(names[1], "c0");
}

TEST(PointCloud, SetAttributesChecksSizesAndNames) {
  PointCloud cloud;
  cloud.setAbsolutePositions({{0, 0, 0}, {1, 0, 0}});
  EXPECT_THROW(cloud.setAttributes({AttributeColumn{"a", ScalarType::UInt8, {1}}}), Error);
  EXPECT_THROW(cloud.setAttributes({AttributeColumn{"a", ScalarType::UInt8, {1, 2}},
                                    AttributeColumn{"a", ScalarType::UInt8, {1, 2}}}),
               Error);
  cloud.setAttributes({AttributeColumn{"a", ScalarType::UInt8, {1, 2}}});
  EXPECT_EQ(cloud.findAttribute("a")->values[1], 2);
}

TEST(PointCloud, LargeInputsCopyInBlocksWithTheSameOriginForAnyThreadCount) {
  // Enough points for several parallel blocks; the extreme coordinates sit in the last block and
  // a non-finite point (which bounds skip) in the first, so a block-wise bound that lost either
  // would move the origin.
  const std::size_t n = 200000;
  std::vector<Vec3> abs(n), normals(n);
  for (std::size_t i = 0; i < n; ++i) {
    abs[i] = Vec3(5e5 + double(i % 1000), 4e6 + double(i / 1000), 10.0 + double(i % 7));
    normals[i] = Vec3(double(i % 3), 1.0, -double(i % 5)).normalized();
  }
  abs[n - 1] = Vec3(5e5 + 7777.25, 4e6 - 3333.5, -99.0);
  PointCloud reference;
  {
    tbb::task_arena one(1);
    one.execute([&] { reference.setAbsolutePositions(abs); });
  }
  abs[0] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  PointCloud cloud;
  cloud.setAbsolutePositions(abs);
  cloud.setNormals(normals.data(), normals.size());
  EXPECT_EQ(cloud.origin(), Vec3(503889.0, 3998433.0, -42.0));  // rounded bounding-box centre
  EXPECT_EQ(cloud.origin(), reference.origin());
  for (std::size_t i = 1; i < n; i += 997) {
    EXPECT_EQ(cloud.absolutePosition(i), abs[i]);
    EXPECT_EQ(cloud.normals()[i], normals[i]);
  }
  EXPECT_EQ(cloud.absolutePosition(n - 1), abs[n - 1]);
  EXPECT_THROW(cloud.setNormals(normals.data(), n - 1), Error);
}

TEST(PointCloud, StorageIsHandedOnWithoutItsContentsAndRefilledInPlace) {
  // The Python bindings hand one call's buffers to the next (python/InputPool.hpp): the next
  // cloud must start empty and fill the same memory, with the same result as a fresh cloud.
  const std::vector<Vec3> abs = {{652341.5, 5412345.25, 312.0}, {652342.5, 5412346.75, 313.0}};
  const std::vector<Vec3> normals = {Vec3::UnitZ(), Vec3::UnitX()};
  PointCloud first;
  first.setAbsolutePositions(std::vector<Vec3>(100, Vec3(1, 2, 3)));
  first.setNormals(std::vector<Vec3>(100, Vec3::UnitY()));
  first.addAttribute("a", ScalarType::Float64);
  PointCloud::Storage storage = first.releaseStorage();
  EXPECT_TRUE(first.empty());
  EXPECT_FALSE(first.hasNormals());
  EXPECT_TRUE(first.attributes().empty());
  EXPECT_TRUE(storage.positions.empty());
  EXPECT_TRUE(storage.normals.empty());
  EXPECT_EQ(storage.bytes(), 200 * sizeof(Vec3));
  const Vec3* positionsMemory = storage.positions.data();
  const Vec3* normalsMemory = storage.normals.data();

  PointCloud second(std::move(storage));
  EXPECT_TRUE(second.empty());
  EXPECT_FALSE(second.hasNormals());  // a buffer without contents is not normals
  second.setAbsolutePositions(abs.data(), abs.size());
  second.setNormals(normals.data(), normals.size());
  EXPECT_EQ(second.positions().data(), positionsMemory);  // filled in place
  EXPECT_EQ(second.normals().data(), normalsMemory);
  PointCloud fresh;
  fresh.setAbsolutePositions(abs.data(), abs.size());
  EXPECT_EQ(second.origin(), fresh.origin());
  EXPECT_EQ(second.positions(), fresh.positions());
  EXPECT_EQ(second.normals(), normals);
}

TEST(PointCloud, GivenBoundsGiveTheSameCloudAsTheScan) {
  // The Python bindings find the bounds while checking the points and pass them in.
  const std::vector<Vec3> abs = {{652341.5, 5412345.25, 312.0}, {652342.5, 5412349.75, 300.0}};
  PointCloud scanned, given;
  scanned.setAbsolutePositions(abs.data(), abs.size());
  given.setAbsolutePositions(abs.data(), abs.size(), abs[0].cwiseMin(abs[1]),
                             abs[0].cwiseMax(abs[1]));
  EXPECT_EQ(given.origin(), scanned.origin());
  EXPECT_EQ(given.origin(), Vec3(652342.0, 5412348.0, 306.0));
  EXPECT_EQ(given.positions(), scanned.positions());
  given.setAbsolutePositions(abs.data(), 0, Vec3::Constant(1e6), Vec3::Constant(1e6));
  EXPECT_TRUE(given.empty());
  EXPECT_EQ(given.origin(), Vec3::Zero());
}
