#include <gtest/gtest.h>

#include <limits>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace scalespace {
namespace {

TEST(CloudIO, FormatFromExtensionIsCaseInsensitive) {
  EXPECT_EQ(formatFromPath("a/b.PLY"), CloudFormat::Ply);
  EXPECT_EQ(formatFromPath("x.Xyz"), CloudFormat::Xyz);
  EXPECT_EQ(formatFromPath("x.txt"), CloudFormat::Xyz);
  EXPECT_EQ(formatFromPath("x.CSV"), CloudFormat::Xyz);
  EXPECT_EQ(formatFromPath("x.pts"), CloudFormat::Xyz);
  EXPECT_EQ(formatFromPath("x.PWN"), CloudFormat::Xyz);
  EXPECT_EQ(formatFromPath("x.off"), CloudFormat::Off);
  EXPECT_EQ(formatFromPath("x.OBJ"), CloudFormat::Obj);
  EXPECT_EQ(formatFromPath("x.las"), CloudFormat::Las);
  EXPECT_EQ(formatFromPath("x.pcd"), CloudFormat::Pcd);
}

TEST(CloudIO, UnknownExtensionListsTheSupportedOnes) {
  try {
    formatFromPath("cloud.e57");
    FAIL();
  } catch (const OptionError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cloud.e57"), std::string::npos);
    for (const char* ext : {".ply", ".xyz", ".csv", ".off", ".obj", ".las", ".pcd"})
      EXPECT_NE(message.find(ext), std::string::npos) << ext;
  }
}

TEST(CloudIO, LazIsRejectedWithAConversionHint) {
  try {
    formatFromPath("scan.LAZ");
    FAIL();
  } catch (const FileError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("scan.LAZ"), std::string::npos);
    EXPECT_NE(message.find("laszip"), std::string::npos);
    EXPECT_NE(message.find("pdal translate"), std::string::npos);
  }
}

// libcgal-demo's blobby.xyz: six columns, every normal 0 0 0, a writer's placeholder.
TEST(CloudIO, NormalsThatAreAllZeroOrNonFiniteAreDropped) {
  test::ScratchDir dir;
  const auto read = [&](const std::string& name, const std::string& text, ReadReport& report) {
    test::writeText(dir.file(name), text);
    report = {};
    return readCloud(dir.file(name), {}, &report);
  };
  ReadReport report;
  PointCloud zeros = read("zeros.xyz", "0 0 0 0 0 0\n1 0 0 0 0 0\n0 1 0 0 0 0\n", report);
  EXPECT_EQ(zeros.size(), 3u);
  EXPECT_FALSE(zeros.hasNormals());
  EXPECT_TRUE(report.unusableNormalsDropped);
  PointCloud nan = read("nan.xyz", "0 0 0 nan 0 0\n1 0 0 0 0 0\n0 1 0 0 inf 0\n", report);
  EXPECT_FALSE(nan.hasNormals());
  EXPECT_TRUE(report.unusableNormalsDropped);
  // One usable normal: the file has normals, the others are its "no value" (fits say so).
  PointCloud one = read("one.xyz", "0 0 0 0 0 0\n1 0 0 0 0 1\n0 1 0 0 0 0\n", report);
  ASSERT_TRUE(one.hasNormals());
  EXPECT_EQ(one.normals()[1], Vec3(0, 0, 1));
  EXPECT_FALSE(report.unusableNormalsDropped);
  PointCloud none = read("none.xyz", "0 0 0\n1 0 0\n", report);
  EXPECT_FALSE(none.hasNormals());
  EXPECT_FALSE(report.unusableNormalsDropped);
}

TEST(CloudIO, MissingFileAndFolderAreFileErrors) {
  test::ScratchDir dir;
  EXPECT_THROW(readCloud(dir.file("missing.ply")), FileError);
  std::filesystem::create_directories(dir.file("folder.ply"));
  EXPECT_THROW(readCloud(dir.file("folder.ply")), FileError);
}

TEST(CloudIO, MeshFormatsCannotBeWritten) {
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(1, 2, 3)});
  test::ScratchDir dir;
  EXPECT_THROW(writeCloud(cloud, dir.file("x.off")), OptionError);
  EXPECT_THROW(writeCloud(cloud, dir.file("x.obj")), OptionError);
  EXPECT_EQ(dir.entryCount(), 0u);
}

TEST(CloudIO, FailedWriteKeepsThePreviousFile) {
  test::ScratchDir dir;
  const std::string path = dir.file("keep.ply");
  PointCloud good;
  good.setAbsolutePositions({Vec3(1, 2, 3)});
  writeCloud(good, path);
  PointCloud bad = good;
  bad.addAttribute("x", ScalarType::Float32);  // clashes with the position property
  EXPECT_THROW(writeCloud(bad, path), Error);
  EXPECT_EQ(readCloud(path).size(), 1u);
  EXPECT_EQ(dir.entryCount(), 1u);
}

// CGAL's points with normals (libcgal-demo's oni.pwn, sphere926.pwn): six headerless columns,
// read as positions and normals; written the same way, without the attributes, and only for a
// cloud that has normals.
TEST(CloudIO, PwnIsPointsWithNormals) {
  test::ScratchDir dir;
  const std::string path = dir.file("oni.pwn");
  test::writeText(path,
                  "-0.120621 -0.048544 -0.228788 -0.518633 -0.562817 -0.643628\n"
                  "2.81733 0 -9.59493 0.281727 4.34882e-019 -0.959495\n");
  const PointCloud read = readCloud(path);
  ASSERT_EQ(read.size(), 2u);
  ASSERT_TRUE(read.hasNormals());
  EXPECT_TRUE(read.attributes().empty());
  EXPECT_EQ(read.absolutePosition(1), Vec3(2.81733, 0, -9.59493));
  EXPECT_EQ(read.normals()[0], Vec3(-0.518633, -0.562817, -0.643628));

  PointCloud withAttribute = read;
  withAttribute.addAttribute("curve_id", ScalarType::Int32);
  const std::string out = dir.file("out.pwn");
  writeCloud(withAttribute, out);
  const std::string text = test::readText(out);
  EXPECT_EQ(text.rfind("-0.120621 -0.048544 -0.228788 -0.518633 -0.562817 -0.643628\n", 0), 0u)
      << text;  // no header line
  const PointCloud back = readCloud(out);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.absolutePosition(1), read.absolutePosition(1));
  EXPECT_EQ(back.normals(), read.normals());
  EXPECT_TRUE(back.attributes().empty());

  PointCloud bare;
  bare.setAbsolutePositions({Vec3(1, 2, 3)});
  try {
    writeCloud(bare, dir.file("bare.pwn"));
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("normals"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writeCloud(bare, dir.file("new/folder/bare.pwn")), OptionError);
  PointCloud nanNormal = read;
  nanNormal.normals()[1].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(writeCloud(nanNormal, dir.file("nan.pwn")), OptionError);
  EXPECT_EQ(dir.entryCount(), 2u);  // oni.pwn and out.pwn: no file nor folder of the refused
}

}  // namespace
}  // namespace scalespace
