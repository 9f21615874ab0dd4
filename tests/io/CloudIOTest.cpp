#include <gtest/gtest.h>

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

}  // namespace
}  // namespace scalespace
