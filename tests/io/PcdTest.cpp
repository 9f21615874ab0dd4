#include <gtest/gtest.h>

#include <cstring>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/PcdFormat.hpp"

namespace scalespace {
namespace {

TEST(Pcd, AsciiAndBinaryRoundTrip) {
  const PointCloud cloud = test::makeRichCloud(30, Vec3(400000.5, 6000000.25, 10));
  test::ScratchDir dir;
  for (const bool ascii : {true, false}) {
    WriteOptions options;
    options.ascii = ascii;
    writeCloud(cloud, dir.file("c.pcd"), options);
    ReadReport report;
    test::expectSameCloud(cloud, readCloud(dir.file("c.pcd"), {}, &report));
    EXPECT_EQ(report.format, ascii ? "pcd (ascii)" : "pcd (binary)");
  }
}

TEST(Pcd, AsciiWithPackedRgbCountAndPadding) {
  // rgb packed as a float: 0x00FF8001 -> red 255, green 128, blue 1.
  const std::uint32_t packed = 0x00FF8001u;
  float asFloat;
  std::memcpy(&asFloat, &packed, 4);
  std::ostringstream text;
  text.precision(9);
  text << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb hist _ normal_x normal_y normal_z\n"
          "SIZE 4 4 4 4 2 1 4 4 4\nTYPE F F F F U I F F F\nCOUNT 1 1 1 1 3 1 1 1 1\n"
          "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
       << "1 2 3 " << asFloat << " 10 20 30 -5 0 0 1\n"
       << "4 5 6 " << asFloat << " 0 0 65535 7 1 0 0\n";
  const PointCloud cloud = readPcd(text.str(), "c.pcd");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.absolutePosition(1), Vec3(4, 5, 6));
  ASSERT_TRUE(cloud.hasNormals());
  EXPECT_EQ(cloud.normals()[1], Vec3(1, 0, 0));
  ASSERT_NE(cloud.findAttribute("red"), nullptr);
  EXPECT_EQ(cloud.findAttribute("red")->values[0], 255);
  EXPECT_EQ(cloud.findAttribute("green")->values[0], 128);
  EXPECT_EQ(cloud.findAttribute("blue")->values[1], 1);
  EXPECT_EQ(cloud.findAttribute("blue")->type, ScalarType::UInt8);
  EXPECT_EQ(cloud.findAttribute("hist_2")->values, (std::vector<double>{30, 65535}));
  EXPECT_EQ(cloud.findAttribute("hist_0")->type, ScalarType::UInt16);
  EXPECT_EQ(cloud.findAttribute("_"), nullptr);
  EXPECT_EQ(cloud.attributes().size(), 6u);  // red green blue hist_0..2
}

/// Minimal LZF encoder for the test, written from the format description: runs of a repeated
/// byte become back references at distance 1, everything else literal runs of <= 32 bytes.
std::string lzfCompress(const std::string& in) {
  std::string out;
  std::size_t i = 0;
  std::string literal;
  auto flush = [&] {
    if (literal.empty()) return;
    out.push_back(char(literal.size() - 1));
    out += literal;
    literal.clear();
  };
  while (i < in.size()) {
    std::size_t run = 0;
    if (i > 0)
      while (i + run < in.size() && in[i + run] == in[i - 1] && run < 264) ++run;
    if (run >= 3) {
      flush();
      const std::size_t length = run - 2;
      if (length < 7) {
        out.push_back(char(length << 5));
      } else {
        out.push_back(char(7 << 5));
        out.push_back(char(length - 7));
      }
      out.push_back(char(0));  // distance - 1 = 0
      i += run;
      continue;
    }
    literal.push_back(in[i++]);
    if (literal.size() == 32) flush();
  }
  flush();
  return out;
}

TEST(Pcd, BinaryCompressedIsFieldMajorLzf) {
  const std::size_t n = 100;
  std::string soa;  // x for all points, then y, then z, then intensity (U2)
  for (int axis = 0; axis < 3; ++axis)
    for (std::size_t i = 0; i < n; ++i) {
      const float v = axis == 2 ? 0.0f : float(i) * (axis + 1);  // z: long zero run
      soa.append(reinterpret_cast<const char*>(&v), 4);
    }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t v = std::uint16_t(i < 50 ? 7 : i);
    soa.append(reinterpret_cast<const char*>(&v), 2);
  }
  const std::string compressed = lzfCompress(soa);
  ASSERT_LT(compressed.size(), soa.size());
  std::string file =
      "VERSION .7\nFIELDS x y z intensity\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 100\n"
      "HEIGHT 1\nPOINTS 100\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {std::uint32_t(compressed.size()), std::uint32_t(soa.size())};
  file.append(reinterpret_cast<const char*>(sizes), 8);
  file += compressed;
  ReadReport report;
  const PointCloud cloud = readPcd(file, "z.pcd", {}, &report);
  EXPECT_EQ(report.format, "pcd (binary_compressed)");
  ASSERT_EQ(cloud.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(cloud.absolutePosition(i), Vec3(double(i), 2.0 * double(i), 0.0));
    ASSERT_EQ(cloud.findAttribute("intensity")->values[i], i < 50 ? 7.0 : double(i));
  }
  // Corruptions: a back reference before the start, a lying uncompressed size, truncation.
  std::string corrupt = file;
  corrupt[corrupt.size() - compressed.size()] = char(0x20);  // first token: back reference
  EXPECT_THROW(readPcd(corrupt, "z.pcd"), FileError);
  std::string lying = file;
  const std::uint32_t wrong = 12345;
  std::memcpy(&lying[lying.size() - compressed.size() - 4], &wrong, 4);
  EXPECT_THROW(readPcd(lying, "z.pcd"), FileError);
  EXPECT_THROW(readPcd(file.substr(0, file.size() - 3), "z.pcd"), FileError);
}

TEST(Pcd, HeaderErrors) {
  auto expectError = [](const std::string& text, const std::string& needle) {
    try {
      readPcd(text, "h.pcd");
      FAIL() << "expected FileError: " << needle;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  expectError(head + "WIDTH 3\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n", "does not equal POINTS");
  expectError(head + "WIDTH 2\nPOINTS 2\nDATA ascii\n1 2 3\n", "h.pcd: line 9: unexpected end");
  expectError(head + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2\n", "expected 3 values, found 2");
  expectError(head + "WIDTH 100000000\nPOINTS 100000000\nDATA binary\n", "unexpected end of file");
  expectError(head + "WIDTH 1\nPOINTS 1\nDATA lzma\n", "unknown DATA");
  expectError(head + "WIDTH 1\nPOINTS 1\n", "no DATA line");
  expectError("VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 0\nDATA ascii\n", "x, y and z");
  expectError("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 8\nTYPE F F I\nWIDTH 0\nDATA ascii\n",
              "unsupported TYPE I SIZE 8");
  expectError("VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 0\nDATA ascii\n",
              "same number of entries");
  expectError("ply\n", "start with VERSION");
  expectError(head + "WIDTH 1\nDATA ascii\n1 nan 3\n", "ReadOptions::dropNonFinite");
}

TEST(Pcd, ViewpointIsReadAndWritten) {
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\n";
  const PointCloud cloud =
      readPcd(head + "VIEWPOINT 0.5 -2 3.25 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n", "v.pcd");
  ASSERT_TRUE(cloud.viewpoint());
  EXPECT_EQ(*cloud.viewpoint(), Vec3(0.5, -2, 3.25));
  EXPECT_FALSE(readPcd(head + "POINTS 1\nDATA ascii\n1 2 3\n", "v.pcd").viewpoint());
  test::ScratchDir dir;
  PointCloud moved = cloud;
  moved.setViewpoint(Vec3(400000.125, 6000000.5, -7));
  writeCloud(moved, dir.file("v.pcd"));
  EXPECT_EQ(*readCloud(dir.file("v.pcd")).viewpoint(), *moved.viewpoint());
  for (const char* bad :
       {"VIEWPOINT 0 0 0\n", "VIEWPOINT 0 0 nan 1 0 0 0\n", "VIEWPOINT 0 0 0 1 0 0 x\n"}) {
    try {
      readPcd(head + bad + "POINTS 1\nDATA ascii\n1 2 3\n", "v.pcd");
      FAIL() << bad;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find("VIEWPOINT tx ty tz qw qx qy qz"), std::string::npos);
    }
  }
}

TEST(Pcd, EmptyCloud) {
  test::ScratchDir dir;
  writeCloud(PointCloud(), dir.file("e.pcd"));
  EXPECT_TRUE(readCloud(dir.file("e.pcd")).empty());
}

}  // namespace
}  // namespace scalespace
