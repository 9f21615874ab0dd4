#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "scales/ScalesTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/scales/ScaleStackIO.hpp"
#include "scalespace/scales/StackQuantization.hpp"

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
    writeScaleStack(path, cloud, options, stack, float32());
  }
  static StackWriteOptions float32() {
    StackWriteOptions w;
    w.encoding = StackEncoding::Float32;
    return w;
  }
  std::string manifestText() const {
    std::ifstream in(fs::path(path) / "manifest.json");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
};

TEST_F(StackFixture, RoundTripIsExactByScaleAndByPoint) {
  ScaleStackReader reader(path);
  ASSERT_EQ(reader.pointCount(), cloud.size());
  ASSERT_EQ(reader.scaleCount(), 3u);
  // Float32 stacks are written as format version 1, readable by older programs.
  EXPECT_EQ(reader.info().formatVersion, 1);
  EXPECT_EQ(reader.info().encoding, StackEncoding::Float32);
  EXPECT_DOUBLE_EQ(reader.info().bytesPerPointPerScale, 83.0);
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
  const ScaleSpaceSummary s = computeScaleStack(cloud, options, path, {}, float32());
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

TEST_F(StackFixture, OlderAndVersion2Float32ManifestsRead) {
  std::string text = manifestText();
  // A version 1 stack of an older program has no "encoding" key.
  const std::string key = "\"encoding\": \"float32\",";
  const auto at = text.find(key);
  ASSERT_NE(at, std::string::npos) << text;
  std::string old = text;
  old.erase(at, key.size());
  std::ofstream(fs::path(path) / "manifest.json") << old;
  EXPECT_EQ(ScaleStackReader(path).readScale(1).kMax, stack.layers[1].kMax);
  // Version 2 with "encoding": "float32" reads the same files.
  const std::string v1 = "\"format_version\": 1";
  ASSERT_NE(text.find(v1), std::string::npos);
  text.replace(text.find(v1), v1.size(), "\"format_version\": 2");
  std::ofstream(fs::path(path) / "manifest.json") << text;
  ScaleStackReader reader(path);
  EXPECT_EQ(reader.info().formatVersion, 2);
  EXPECT_EQ(reader.readScale(2).normal, stack.layers[2].normal);
  // An unknown encoding or a newer version is refused.
  const std::string enc = "\"encoding\": \"float32\"";
  std::string bad = text;
  bad.replace(bad.find(enc), enc.size(), "\"encoding\": \"float8\"");
  std::ofstream(fs::path(path) / "manifest.json") << bad;
  EXPECT_THROW(ScaleStackReader{path}, FileError);
  bad = text;
  bad.replace(bad.find("\"format_version\": 2"), 19, "\"format_version\": 3");
  std::ofstream(fs::path(path) / "manifest.json") << bad;
  EXPECT_THROW(ScaleStackReader{path}, FileError);
}

// The compact encoding: the decoded layer equals the float32 one within the tolerances of
// docs/STACK_FORMAT.md; invalid fits decode to zeros; overflows are clamped and counted.
struct CompactFixture : StackFixture {
  std::string compactPath;
  ScaleStack edited;  // the stack with an invalid fit and an overflowing curvature
  void SetUp() override {
    StackFixture::SetUp();
    edited = stack;
    ScaleLayer& L0 = edited.layers[0];
    L0.valid[5] = 0;
    for (auto* v : {&L0.normal, &L0.dirMax, &L0.dirMin})
      for (int c = 0; c < 3; ++c) (*v)[15 + c] = 0;
    for (auto* v : {&L0.meanCurvature, &L0.kMax, &L0.kMin, &L0.tau, &L0.kappa, &L0.fitness,
                    &L0.anisotropy, &L0.geometricVariation})
      (*v)[5] = 0;
    edited.layers[1].kMax[7] = 1e12f;
    edited.layers[2].neighbors[3] = 1000;
    compactPath = (dir.path / "sphere_compact.stack").string();
    writeScaleStack(compactPath, cloud, options, edited);  // compact is the default
  }
};

void expectDecodedClose(const ScaleLayer& D, const ScaleLayer& F, std::size_t i, std::size_t k,
                        double t) {
  // D: decoded compact entry k; F: float32 entry i.
  ASSERT_EQ(D.valid[k], F.valid[i]);
  const double h = std::ldexp(1.0, -11);    // float16 relative precision (half an ulp)
  const double sub = std::ldexp(1.0, -25);  // half the smallest float16 subnormal
  auto close = [&](double d, double f, double scale, const char* what) {
    // stored f * scale as float16, decoded / scale; + float32 rounding of the decoded value
    const double tol = (h * std::abs(f * scale) + sub) / scale + 1.2e-7 * std::abs(f) + 1e-30;
    EXPECT_LE(std::abs(d - f), tol) << what << " point " << i << ": " << d << " vs " << f;
  };
  for (int c = 0; c < 3; ++c) {
    // projection = input + offset t, offset = (projection - input) / t stored as float16
    EXPECT_LE(std::abs(double(D.projection[3 * k + c]) - double(F.projection[3 * i + c])),
              (h * 8 + sub) * t + 2.4e-7 * std::abs(F.projection[3 * i + c]))
        << "projection of point " << i;
  }
  EXPECT_EQ(D.neighbors[k], std::min<unsigned>(F.neighbors[i], 255u));
  if (!F.valid[i]) {
    for (const auto* v : {&D.normal, &D.dirMax, &D.dirMin})
      for (int c = 0; c < 3; ++c) EXPECT_EQ((*v)[3 * k + c], 0.0f);
    for (const auto* v : {&D.meanCurvature, &D.kMax, &D.kMin, &D.tau, &D.kappa, &D.fitness,
                          &D.anisotropy, &D.geometricVariation})
      EXPECT_EQ((*v)[k], 0.0f);
    return;
  }
  auto v3 = [](const std::vector<float>& a, std::size_t p) {
    return Vec3(a[3 * p], a[3 * p + 1], a[3 * p + 2]);
  };
  const Vec3 n = v3(F.normal, i).normalized();
  EXPECT_LE(quant::axisAngle(v3(D.normal, k), n), quant::kOctMaxAngle + 1e-6);
  EXPECT_GT(v3(D.normal, k).dot(n), 0);  // oriented, not an axis
  const double dirTol = quant::kAngleMaxError + 2 * quant::kOctMaxAngle + 1e-5;
  EXPECT_LE(quant::axisAngle(v3(D.dirMax, k), v3(F.dirMax, i)), dirTol) << i;
  EXPECT_LE(quant::axisAngle(v3(D.dirMin, k), v3(F.dirMin, i)), dirTol) << i;
  close(D.kMax[k], F.kMax[i], t, "kMax");
  close(D.kMin[k], F.kMin[i], t, "kMin");
  const double hm = 0.5 * (std::abs(F.kMax[i]) + std::abs(F.kMin[i]));
  EXPECT_LE(std::abs(double(D.meanCurvature[k]) - double(F.meanCurvature[i])),
            h * hm + sub / t + 2.4e-7 * hm + 1e-30);
  close(D.tau[k], F.tau[i], 1 / t, "tau");
  close(D.kappa[k], F.kappa[i], t, "kappa");
  close(D.anisotropy[k], F.anisotropy[i], 1, "anisotropy");
  close(D.geometricVariation[k], F.geometricVariation[i], 1, "geometricVariation");
  EXPECT_EQ(D.fitness[k], 0.0f);  // not stored
}

TEST_F(CompactFixture, DecodesWithinTheDocumentedTolerances) {
  ScaleStackReader reader(compactPath);
  EXPECT_EQ(reader.info().formatVersion, 2);
  EXPECT_EQ(reader.info().encoding, StackEncoding::Compact);
  EXPECT_DOUBLE_EQ(reader.info().bytesPerPointPerScale, 6 + 4 + 6 * 2 + 1 + 75.0 / 600);
  EXPECT_EQ(reader.info().clampedValues, 1u);  // kMax = 1e12
  EXPECT_NO_THROW(reader.verifyChecksums());
  EXPECT_NO_THROW(reader.checkInput(cloud, "sphere"));
  std::size_t invalid = 0;
  for (std::size_t j = 0; j < 3; ++j) {
    const double t = stack.summary.series.scales[j];
    const ScaleLayer D = reader.readScale(j);
    ASSERT_EQ(D.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (j == 1 && i == 7) continue;
      invalid += edited.layers[j].valid[i] ? 0 : 1;
      expectDecodedClose(D, edited.layers[j], i, i, t);
    }
    for (float v : D.kMax) ASSERT_TRUE(std::isfinite(v));
  }
  EXPECT_GE(invalid, 1u);
  // The overflow is clamped to 65504 / t, never inf.
  EXPECT_FLOAT_EQ(reader.readScale(1).kMax[7], float(65504.0 / stack.summary.series.scales[1]));
  EXPECT_EQ(reader.readScale(2).neighbors[3], 255);
  // By point: the same values as by scale.
  for (std::size_t i : {std::size_t(0), std::size_t(5), std::size_t(17), cloud.size() - 1}) {
    const ScaleLayer S = reader.readPointSeries(i);
    ASSERT_EQ(S.size(), 3u);
    for (std::size_t j = 0; j < 3; ++j) {
      const ScaleLayer D = reader.readScale(j);
      EXPECT_EQ(S.projection[3 * j + 1], D.projection[3 * i + 1]);
      EXPECT_EQ(S.normal[3 * j + 2], D.normal[3 * i + 2]);
      EXPECT_EQ(S.dirMin[3 * j], D.dirMin[3 * i]);
      EXPECT_EQ(S.kMin[j], D.kMin[i]);
      EXPECT_EQ(S.tau[j], D.tau[i]);
      EXPECT_EQ(S.valid[j], D.valid[i]);
      EXPECT_EQ(S.neighbors[j], D.neighbors[i]);
    }
  }
  // Streaming gives the same files as the in-memory writer.
  computeScaleStack(cloud, options, path);
  ScaleStackReader streamed(path);
  EXPECT_EQ(streamed.info().encoding, StackEncoding::Compact);
  EXPECT_EQ(streamed.readScale(2).kMax, ScaleStackReader(compactPath).readScale(2).kMax);
}

TEST_F(CompactFixture, WrongSizeFilesAreRejected) {
  for (const char* name : {"frame.npy", "fit_valid_bits.npy", "projection_offset.npy"}) {
    const fs::path f = fs::path(compactPath) / name;
    const auto size = fs::file_size(f);
    fs::resize_file(f, size - 1);
    try {
      ScaleStackReader reader(compactPath);
      ADD_FAILURE() << "a truncated " << name << " was accepted";
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    fs::resize_file(f, size + 2);
    EXPECT_THROW(ScaleStackReader{compactPath}, FileError) << name;
    fs::resize_file(f, size);
    {
      std::fstream io(f, std::ios::in | std::ios::out | std::ios::binary);
      io.seekp(std::streamoff(size - 1));
      io.put('\0');  // restores the size, not necessarily the byte: skip checksums here
    }
  }
  // A manifest whose shape disagrees with the file is refused too.
  std::ifstream in(fs::path(compactPath) / "manifest.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string needle = "\"point_count\": 600";
  ASSERT_NE(text.find(needle), std::string::npos);
  text.replace(text.find(needle), needle.size(), "\"point_count\": 599");
  std::ofstream(fs::path(compactPath) / "manifest.json") << text;
  EXPECT_THROW(ScaleStackReader{compactPath}, FileError);
}

TEST_F(CompactFixture, PythonReaderDecodesTheCompactStack) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no numpy (apt-get install python3-numpy)";
  const std::string script = std::string(SCALESPACE_SOURCE_DIR) + "/scripts/read_stack.py";
  const std::string out = (dir.path / "pyc.txt").string();
  const std::string cmd =
      "/usr/bin/python3 " + script + " " + compactPath + " --scale 1 --point 17 > " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const ScaleLayer D = ScaleStackReader(compactPath).readScale(1);
  auto value = [&](const std::string& key) {
    const auto at = text.find(key + " = ");
    EXPECT_NE(at, std::string::npos) << key << " in " << text;
    return at == std::string::npos ? 0.0 : std::stod(text.substr(at + key.size() + 3));
  };
  EXPECT_NEAR(value("curv_max[1, 17]"), D.kMax[17], 1e-5 * std::abs(D.kMax[17]));
  EXPECT_NEAR(value("gls_tau[1, 17]"), D.tau[17], 1e-5 * std::abs(D.tau[17]) + 1e-12);
  EXPECT_NEAR(value("normal_z[1, 17]"), D.normal[3 * 17 + 2], 1e-6);
  EXPECT_NEAR(value("dir_max_x[1, 17]"), D.dirMax[3 * 17], 1e-6);
  EXPECT_NEAR(value("dir_min_y[1, 17]"), D.dirMin[3 * 17 + 1], 1e-6);
  EXPECT_NEAR(value("projection_y[1, 17]"),
              double(D.projection[3 * 17 + 1]) + ScaleStackReader(compactPath).info().origin.y(),
              1e-6);
}

}  // namespace
}  // namespace scalespace
