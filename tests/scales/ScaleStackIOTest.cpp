#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "scales/ScalesTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/scales/ScaleStackIO.hpp"

namespace fs = std::filesystem;

namespace scalespace {
namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("scales_io_test_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

struct StackFixture : ::testing::Test {
  TempDir dir;
  PointCloud cloud = test::sphereCloud(600, 2.0);
  ScaleSpaceOptions options;
  ScaleStack stack;
  std::string path;
  void SetUp() override {
    options.series.count = 3;
    stack = computeScaleSpace(cloud, options);
    path = (dir.path / "sphere.stack").string();
    writeScaleStack(path, cloud, options, stack);
  }
};

TEST_F(StackFixture, RoundTripIsExactByScaleAndByPoint) {
  ScaleStackReader reader(path);
  ASSERT_EQ(reader.pointCount(), cloud.size());
  ASSERT_EQ(reader.scaleCount(), 3u);
  EXPECT_EQ(reader.info().scales, stack.summary.series.scales);
  EXPECT_EQ(reader.info().inputChecksum, stack.summary.inputChecksum);
  EXPECT_EQ(reader.info().stats[1].samples, stack.summary.stats[1].samples);
  for (std::size_t j = 0; j < 3; ++j) {
    const ScaleLayer L = reader.readScale(j);
    EXPECT_EQ(L.projection, stack.layers[j].projection);
    EXPECT_EQ(L.normal, stack.layers[j].normal);
    EXPECT_EQ(L.dirMin, stack.layers[j].dirMin);
    EXPECT_EQ(L.kMax, stack.layers[j].kMax);
    EXPECT_EQ(L.geometricVariation, stack.layers[j].geometricVariation);
    EXPECT_EQ(L.neighbors, stack.layers[j].neighbors);
    EXPECT_EQ(L.valid, stack.layers[j].valid);
  }
  for (std::size_t i : {std::size_t(0), std::size_t(17), cloud.size() - 1}) {
    const ScaleLayer S = reader.readPointSeries(i);
    ASSERT_EQ(S.size(), 3u);
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(S.kMin[j], stack.layers[j].kMin[i]);
      EXPECT_EQ(S.normal[3 * j + 2], stack.layers[j].normal[3 * i + 2]);
      EXPECT_EQ(S.neighbors[j], stack.layers[j].neighbors[i]);
    }
  }
  const auto xyz = reader.inputPositions();
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(xyz[i], cloud.absolutePosition(i));
  EXPECT_NO_THROW(reader.verifyChecksums());
  EXPECT_NO_THROW(reader.checkInput(cloud, "sphere"));
  EXPECT_THROW(reader.checkInput(test::sphereCloud(600, 2.5), "other"), FileError);
  EXPECT_THROW(reader.readScale(3), OptionError);
  EXPECT_THROW(reader.readPointSeries(cloud.size()), OptionError);
  EXPECT_TRUE(isScaleStack(path));
  // Nothing temporary is left beside the stack.
  std::size_t entries = 0;
  for (auto it = fs::directory_iterator(dir.path); it != fs::directory_iterator(); ++it) ++entries;
  EXPECT_EQ(entries, 1u);
}

TEST_F(StackFixture, StreamedStackEqualsInMemoryAndReplacesTheOldOne) {
  const ScaleSpaceSummary s = computeScaleStack(cloud, options, path);
  ScaleStackReader reader(path);
  EXPECT_EQ(reader.readScale(2).projection, stack.layers[2].projection);
  EXPECT_NO_THROW(reader.verifyChecksums());
  EXPECT_EQ(s.inputChecksum, stack.summary.inputChecksum);
}

TEST_F(StackFixture, HalfWrittenStackIsRejected) {
  fs::remove(fs::path(path) / "manifest.json");
  EXPECT_FALSE(isScaleStack(path));
  EXPECT_THROW(ScaleStackReader{path}, FileError);
  EXPECT_THROW(ScaleStackReader{(dir.path / "missing.stack").string()}, FileError);
}

TEST_F(StackFixture, TruncatedFileIsRejected) {
  const fs::path f = fs::path(path) / "curv_max.npy";
  fs::resize_file(f, fs::file_size(f) - 4);
  try {
    ScaleStackReader reader(path);
    FAIL() << "a truncated file was accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("curv_max.npy"), std::string::npos) << e.what();
  }
}

TEST_F(StackFixture, ModifiedDataFailsTheChecksum) {
  {
    std::fstream f(fs::path(path) / "normal.npy", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(200);
    f.put('\x55');
  }
  ScaleStackReader reader(path);  // sizes are fine
  EXPECT_THROW(reader.verifyChecksums(), FileError);
}

TEST_F(StackFixture, ManifestMismatchIsRejected) {
  const fs::path m = fs::path(path) / "manifest.json";
  std::ifstream in(m);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string needle = "\"point_count\": 600";
  const auto at = text.find(needle);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, needle.size(), "\"point_count\": 601");
  std::ofstream(m) << text;
  EXPECT_THROW(ScaleStackReader{path}, FileError);
}

TEST_F(StackFixture, PythonReaderLoadsTheStack) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no numpy (apt-get install python3-numpy)";
  const std::string script = std::string(SCALESPACE_SOURCE_DIR) + "/scripts/read_stack.py";
  const std::string out = (dir.path / "py.txt").string();
  const std::string cmd =
      "/usr/bin/python3 " + script + " " + path + " --scale 1 --point 17 > " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  char expected[64];
  std::snprintf(expected, sizeof expected, "curv_max[1, 17] = %.6g",
                double(stack.layers[1].kMax[17]));
  EXPECT_NE(text.find(expected), std::string::npos) << text;
}

}  // namespace
}  // namespace scalespace
