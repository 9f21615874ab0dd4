#include <gtest/gtest.h>

#include <cmath>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/XyzFormat.hpp"

namespace scalespace {
namespace {

using test::ScratchDir;

TEST(Xyz, RoundTripSpaceAndCommaSeparatedKeepsValuesExactly) {
  const PointCloud cloud = test::makeRichCloud(40, Vec3(712345.5, 4123456.25, 88.0));
  ScratchDir dir;
  for (const char* name : {"c.xyz", "c.csv", "c.TXT"}) {
    const std::string path = dir.file(name);
    writeCloud(cloud, path);
    const PointCloud back = readCloud(path);
    test::expectSameCloud(cloud, back, /*compareTypes=*/false);  // text keeps no type
    for (const auto& column : back.attributes()) EXPECT_EQ(column.type, ScalarType::Float64);
  }
  EXPECT_EQ(test::readText(dir.file("c.csv")).substr(0, 15), "x,y,z,nx,ny,nz,");
}

TEST(Xyz, HeaderNamesColumnsInAnyOrderCaseInsensitive) {
  const PointCloud cloud = readXyz(
      "# exported\n"
      "//Intensity, Z , NX,ny,nz,X,Y\n"
      "\n"
      "5, 3, 0, 0, 1, 1, 2\n"
      "6,-3,1,0,0,+1e1,2.5\n",
      "h.csv");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.absolutePosition(0), Vec3(1, 2, 3));
  EXPECT_EQ(cloud.absolutePosition(1), Vec3(10, 2.5, -3));
  ASSERT_TRUE(cloud.hasNormals());
  EXPECT_EQ(cloud.normals()[1], Vec3(1, 0, 0));
  ASSERT_EQ(cloud.attributes().size(), 1u);
  EXPECT_EQ(cloud.attributes()[0].name, "Intensity");
  EXPECT_EQ(cloud.attributes()[0].values, (std::vector<double>{5, 6}));
}

TEST(Xyz, ColumnCountDecidesWithoutHeader) {
  EXPECT_FALSE(readXyz("1 2 3\n4 5 6\n", "a.xyz").hasNormals());
  const PointCloud six = readXyz("1 2 3 0 0 1\n", "b.xyz");
  EXPECT_TRUE(six.hasNormals());
  EXPECT_TRUE(six.attributes().empty());
  const PointCloud four = readXyz("1\t2\t3\t7.5\n", "c.xyz");
  EXPECT_FALSE(four.hasNormals());
  ASSERT_EQ(four.attributes().size(), 1u);
  EXPECT_EQ(four.attributes()[0].name, "scalar_1");
  const PointCloud seven = readXyz("1 2 3 255 128 0 9\n", "d.xyz");
  EXPECT_FALSE(seven.hasNormals());  // ambiguous: no guessing
  ASSERT_EQ(seven.attributes().size(), 4u);
  EXPECT_EQ(seven.attributes()[3].name, "scalar_4");
  EXPECT_EQ(seven.attributes()[3].values[0], 9);
}

TEST(Xyz, ErrorsNameFileAndLine) {
  auto expectError = [](const std::string& text, const std::string& needle) {
    try {
      readXyz(text, "e.xyz");
      FAIL() << "expected FileError for " << text;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectError("1 2 3\n4 5\n", "e.xyz: line 2: expected 3 fields, found 2");
  expectError("1 2 3\n4 5 abc\n", "e.xyz: line 2");
  expectError("1 2\n", "at least 3 columns");
  expectError("a b c\n1 2 3\n", "names no 'x'");
  expectError("x y z\n1 nan 3\n", "ReadOptions::dropNonFinite");
  expectError("1,,3\n", "is not a number");
}

TEST(Xyz, DropNonFiniteCountsSkippedPoints) {
  ReadOptions options;
  options.dropNonFinite = true;
  ReadReport report;
  const PointCloud cloud = readXyz("1 2 3\ninf 0 0\n4 5 6\n0 -nan 0\n", "d.xyz", options, &report);
  EXPECT_EQ(cloud.size(), 2u);
  EXPECT_EQ(report.droppedNonFinite, 2u);
}

TEST(Xyz, EmptyAndCommentOnlyFilesGiveEmptyClouds) {
  EXPECT_TRUE(readXyz("", "e.xyz").empty());
  EXPECT_TRUE(readXyz("# nothing\n\n", "e.xyz").empty());
  EXPECT_TRUE(readXyz("x y z\n", "e.xyz").empty());
}

}  // namespace
}  // namespace scalespace

namespace scalespace {
namespace {

TEST(Xyz, OutOfRangeNumbersOverflowToInfinityAndUnderflowToZero) {
  const PointCloud cloud = readXyz("x y z s\n1e-999 -1E-400 2 1e999\n", "r.xyz");
  EXPECT_EQ(cloud.absolutePosition(0), Vec3(0, 0, 2));
  EXPECT_EQ(cloud.attributes()[0].values[0], std::numeric_limits<double>::infinity());
  EXPECT_THROW(readXyz("1 2 -1e999\n", "r.xyz"), FileError);
}

}  // namespace
}  // namespace scalespace

namespace scalespace {
namespace {

TEST(Xyz, PtsCountLineIsSkipped) {
  const PointCloud cloud = readXyz("2\n1 2 3 10 255 0 0\n4 5 6 20 0 255 0\n", "scan.pts");
  EXPECT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.attributes().size(), 4u);
}

TEST(Xyz, NormalNamesAsAttributes) {
  // A partial normal stays an attribute and survives a round trip ...
  PointCloud cloud = readXyz("x y z nx\n1 2 3 0.5\n", "p.xyz");
  ASSERT_FALSE(cloud.hasNormals());
  std::ostringstream out;
  writeXyz(cloud, out);
  EXPECT_EQ(readXyz(out.str(), "p.xyz").findAttribute("nx")->values[0], 0.5);
  // ... and three normal-named columns of a cloud without normals are written as they are and
  // read back as its normals (how the curvature output places the fitted normal last).
  cloud.addAttribute("ny", ScalarType::Float32).values[0] = 0.0;
  cloud.addAttribute("nz", ScalarType::Float32).values[0] = std::sqrt(0.75);
  std::ostringstream out2;
  writeXyz(cloud, out2);
  const PointCloud back = readXyz(out2.str(), "p.xyz");
  ASSERT_TRUE(back.hasNormals());
  EXPECT_NEAR(back.normals()[0].x(), 0.5, 1e-12);
  // A cloud that has normals cannot also carry normal-named columns.
  cloud.setNormals({Vec3::UnitZ()});
  std::ostringstream out3;
  EXPECT_THROW(writeXyz(cloud, out3), Error);
}

}  // namespace
}  // namespace scalespace
