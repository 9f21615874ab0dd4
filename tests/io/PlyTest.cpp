#include <gtest/gtest.h>

#include <cstring>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/PlyFormat.hpp"

namespace scalespace {
namespace {

using test::ScratchDir;

class PlyRoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(PlyRoundTrip, EveryEncodingKeepsPositionsNormalsAndTypedAttributesBitExact) {
  const bool georeferenced = GetParam();
  const PointCloud cloud =
      test::makeRichCloud(50, georeferenced ? Vec3(654321.123, 5432109.87, 312.5) : Vec3::Zero());
  if (georeferenced) {
    ASSERT_NE(cloud.origin(), Vec3::Zero());
  }
  ScratchDir dir;
  for (const bool ascii : {false, true}) {
    const std::string path = dir.file(ascii ? "a.ply" : "b.PLY");
    WriteOptions options;
    options.ascii = ascii;
    writeCloud(cloud, path, options);
    ReadReport report;
    const PointCloud back = readCloud(path, {}, &report);
    EXPECT_EQ(report.format, ascii ? "ply (ascii)" : "ply (binary_little_endian)");
    test::expectSameCloud(cloud, back);
    EXPECT_EQ(back.origin(), cloud.origin());
  }
  // Big endian through the in-memory API.
  std::ostringstream out;
  writePly(cloud, out, PlyEncoding::BinaryBigEndian);
  test::expectSameCloud(cloud, readPly(out.str(), "big.ply"));
}

INSTANTIATE_TEST_SUITE_P(Origins, PlyRoundTrip, ::testing::Values(false, true));

TEST(Ply, PositionsAreWrittenAsFloatOnlyWhenThatIsExact) {
  PointCloud exact;
  exact.setAbsolutePositions({Vec3(0.5, 1.25, -3), Vec3(1, 2, 3)});
  std::ostringstream out;
  writePly(exact, out, PlyEncoding::Ascii);
  EXPECT_NE(out.str().find("property float x"), std::string::npos);
  PointCloud inexact;
  inexact.setAbsolutePositions({Vec3(0.1, 1.25, -3)});
  std::ostringstream out2;
  writePly(inexact, out2, PlyEncoding::Ascii);
  EXPECT_NE(out2.str().find("property double x"), std::string::npos);
  EXPECT_EQ(readPly(out2.str(), "t.ply").absolutePosition(0).x(), 0.1);
}

TEST(Ply, HeaderVariantsFacesListsCommentsAliasesAndCrlf) {
  const std::string text =
      "ply\r\n"
      "format ascii 1.0\r\n"
      "comment made by hand\r\n"
      "obj_info whatever\r\n"
      "element face 2\r\n"
      "property list uchar int vertex_indices\r\n"
      "element vertex 3\r\n"
      "property float32 x\r\n"
      "property float64 y\r\n"
      "property int16 z\r\n"
      "property list uint8 float32 extra\r\n"
      "property uint8 label\r\n"
      "property float nx\r\n"
      "end_header\r\n"
      "3 0 1 2\r\n"
      "4 0 1 2 0\r\n"
      "1 2 3 2 9 9 7 0.5\r\n"
      "4 5 6 0 255 -1\r\n"
      "\r\n"
      "7 8 9 1 1 0 0.25\r\n";
  const PointCloud cloud = readPly(text, "variants.ply");
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.absolutePosition(2), Vec3(7, 8, 9));
  EXPECT_FALSE(cloud.hasNormals());  // only nx: kept as an attribute
  ASSERT_EQ(cloud.attributes().size(), 2u);
  EXPECT_EQ(cloud.attributes()[0].name, "label");
  EXPECT_EQ(cloud.attributes()[0].type, ScalarType::UInt8);
  EXPECT_EQ(cloud.attributes()[0].values, (std::vector<double>{7, 255, 0}));
  EXPECT_EQ(cloud.attributes()[1].name, "nx");
  EXPECT_EQ(cloud.attributes()[1].values[2], 0.25);
  // Asked for, the faces (declared before the vertices here) come back as triangle fans.
  std::vector<std::array<Index, 3>> triangles;
  EXPECT_EQ(readPly(text, "variants.ply", {}, nullptr, nullptr, &triangles).size(), 3u);
  EXPECT_EQ(triangles, (std::vector<std::array<Index, 3>>{{0, 1, 2}, {0, 1, 2}, {0, 2, 0}}));
}

TEST(Ply, FacesAreCheckedAgainstTheVertices) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n0 0 0\n1 0 "
      "0\n0 1 0\n";
  std::vector<std::array<Index, 3>> triangles;
  readPly(head + "3 2 1 0\n", "f.ply", {}, nullptr, nullptr, &triangles);
  EXPECT_EQ(triangles, (std::vector<std::array<Index, 3>>{{2, 1, 0}}));
  auto expectError = [&](const std::string& text, const std::string& needle) {
    try {
      readPly(text, "f.ply", {}, nullptr, nullptr, &triangles);
      ADD_FAILURE() << text;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectError(head + "3 0 1 3\n", "f.ply: line 13: face 1: vertex index 3 is not in [0, 3)");
  expectError(head + "2 0 1\n", "face 1 has 2 vertices");
  // A dropped vertex takes its faces along; the others are renumbered.
  ReadOptions drop;
  drop.dropNonFinite = true;
  const std::string withNan =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 2\nproperty list uchar uint vertex_index\nend_header\n0 0 0\nnan 0 "
      "0\n1 0 0\n0 1 0\n3 0 1 2\n3 3 2 0\n";
  const PointCloud kept = readPly(withNan, "f.ply", drop, nullptr, nullptr, &triangles);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept.absolutePosition(1), Vec3(1, 0, 0));
  EXPECT_EQ(triangles, (std::vector<std::array<Index, 3>>{{2, 1, 0}}));
  // Without a face element, no triangles; without the list, an error naming what is missing.
  readPly(head.substr(0, head.find("element face")) + "end_header\n0 0 0\n1 0 0\n0 1 0\n", "f.ply",
          {}, nullptr, nullptr, &triangles);
  EXPECT_TRUE(triangles.empty());
  std::string noList = head;
  noList.replace(noList.find("list uchar uint vertex_index"), 28, "uchar flags");
  expectError(noList + "3\n", "no list property 'vertex_indices'");
}

TEST(Ply, HandWrittenBigEndianWithFacesAfterVertices) {
  std::string data =
      "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\nproperty double "
      "y\nproperty double z\nproperty short s\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n";
  auto putBig = [&](auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    for (int k = int(sizeof(value)) - 1; k >= 0; --k) data.push_back(bytes[k]);
  };
  putBig(1.5), putBig(-2.0), putBig(1e6 + 0.125), putBig(std::int16_t(-300));
  putBig(3.0), putBig(4.0), putBig(5.0), putBig(std::int16_t(12));
  putBig(std::uint8_t(3)), putBig(std::int32_t(0)), putBig(std::int32_t(1)),
      putBig(std::int32_t(1));
  const PointCloud cloud = readPly(data, "big.ply");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.absolutePosition(0), Vec3(1.5, -2.0, 1e6 + 0.125));
  EXPECT_EQ(cloud.findAttribute("s")->values, (std::vector<double>{-300, 12}));
  EXPECT_EQ(cloud.findAttribute("s")->type, ScalarType::Int16);
  // One byte less: the face list is truncated.
  EXPECT_THROW(readPly(data.substr(0, data.size() - 1), "big.ply"), FileError);
  std::vector<std::array<Index, 3>> triangles;
  readPly(data, "big.ply", {}, nullptr, nullptr, &triangles);
  EXPECT_EQ(triangles, (std::vector<std::array<Index, 3>>{{0, 1, 1}}));
  EXPECT_THROW(
      readPly(data.substr(0, data.size() - 1), "big.ply", {}, nullptr, nullptr, &triangles),
      FileError);
}

TEST(Ply, NonFiniteCoordinatesAreRejectedOrDropped) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nproperty float q\nend_header\n0 0 0 nan\n1 nan 1 1\n2 2 inf 2\n";
  try {
    readPly(text, "bad.ply");
    FAIL() << "expected FileError";
  } catch (const FileError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("bad.ply: line 10"), std::string::npos) << message;
    EXPECT_NE(message.find("ReadOptions::dropNonFinite"), std::string::npos) << message;
  }
  ReadOptions options;
  options.dropNonFinite = true;
  ReadReport report;
  const PointCloud cloud = readPly(text, "bad.ply", options, &report);
  EXPECT_EQ(report.droppedNonFinite, 2u);
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_TRUE(std::isnan(cloud.findAttribute("q")->values[0]));  // NaN attributes are allowed
}

TEST(Ply, EmptyCloudIsValid) {
  PointCloud empty;
  ScratchDir dir;
  for (const bool ascii : {false, true}) {
    WriteOptions options;
    options.ascii = ascii;
    writeCloud(empty, dir.file("empty.ply"), options);
    EXPECT_TRUE(readCloud(dir.file("empty.ply")).empty());
  }
}

TEST(Ply, UnwritableAttributeNameThrowsAndLeavesNoFile) {
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(1, 2, 3)});
  cloud.addAttribute("bad name", ScalarType::Float32);
  ScratchDir dir;
  EXPECT_THROW(writeCloud(cloud, dir.file("x.ply")), Error);
  EXPECT_EQ(dir.entryCount(), 0u);
}

TEST(Ply, IntegerAttributesAreSaturatedOnWrite) {
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(1, 2, 3), Vec3(4, 5, 6)});
  auto& column = cloud.addAttribute("label", ScalarType::UInt8);
  column.values = {300.0, std::nan("")};
  std::ostringstream out;
  writePly(cloud, out, PlyEncoding::BinaryLittleEndian);
  EXPECT_EQ(readPly(out.str(), "s.ply").findAttribute("label")->values,
            (std::vector<double>{255, 0}));
}

}  // namespace
}  // namespace scalespace

namespace scalespace {
namespace {

TEST(Ply, AbsurdlyLargeCoordinatesAreTreatedAsInvalid) {
  // Found by fuzz_las: a coordinate near DBL_MAX made recentring overflow to infinity.
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty "
      "double z\nend_header\n1 2 3\n1.7e308 0 0\n";
  EXPECT_THROW(readPly(text, "big.ply"), FileError);
  ReadOptions options;
  options.dropNonFinite = true;
  ReadReport report;
  const PointCloud cloud = readPly(text, "big.ply", options, &report);
  EXPECT_EQ(cloud.size(), 1u);
  EXPECT_EQ(report.droppedNonFinite, 1u);
  EXPECT_TRUE(cloud.positions()[0].allFinite());
}

}  // namespace
}  // namespace scalespace
