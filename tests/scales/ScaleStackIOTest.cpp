#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>

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
    stack = computeScaleStackInMemory(cloud, options);
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
  const ScaleSpaceSummary s = computeScaleStackToDisk(cloud, options, path, {}, float32());
  ScaleStackReader reader(path);
  EXPECT_EQ(reader.readScale(2).projection, stack.layers[2].projection);
  EXPECT_NO_THROW(reader.verifyChecksums());
  EXPECT_EQ(s.inputChecksum, stack.summary.inputChecksum);
}

/// The bytes of every file of a stack but the manifest (which records timings).
std::map<std::string, std::string> stackFiles(const std::string& path) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(path)) {
    if (e.path().filename() == "manifest.json") continue;
    std::ifstream in(e.path(), std::ios::binary);
    files[e.path().filename().string()] = {std::istreambuf_iterator<char>(in), {}};
  }
  return files;
}

TEST_F(StackFixture, LayersInProcessingOrderAreWrittenInInputOrder) {
  // The streaming writer is handed layers in processing order (LayerOrder::Processing); the files
  // must be byte for byte those written from input-order layers, in both encodings.
  ScaleSpaceOptions processing = options;
  processing.layerOrder = LayerOrder::Processing;
  const ScaleStack permuted = computeScaleStackInMemory(cloud, processing);
  ASSERT_FALSE(permuted.layers[0].inputIndex.empty());
  for (const StackWriteOptions& write : {StackWriteOptions{}, float32()}) {
    const std::string a = (dir.path / "input.stack").string();
    const std::string b = (dir.path / "processing.stack").string();
    writeScaleStack(a, cloud, options, stack, write);
    writeScaleStack(b, cloud, options, permuted, write);
    const auto fa = stackFiles(a), fb = stackFiles(b);
    EXPECT_GE(fa.size(), 10u);
    EXPECT_TRUE(fa == fb);
    // The streamed stack (computeScaleStackToDisk) too.
    computeScaleStackToDisk(cloud, options, b, {}, write);
    EXPECT_TRUE(stackFiles(b) == fa);
    // Input indices that are not a permutation are refused (the encoder writes at them), and the
    // stack already in place stays.
    ScaleStack bad = permuted;
    bad.layers[1].inputIndex[3] = bad.layers[1].inputIndex[4];
    EXPECT_THROW(writeScaleStack(b, cloud, options, bad, write), Error);
    bad.layers[1].inputIndex[3] = Index(cloud.size());
    EXPECT_THROW(writeScaleStack(b, cloud, options, bad, write), Error);
    EXPECT_TRUE(stackFiles(b) == fa);
  }
}

TEST_F(StackFixture, OnlyAStackIsEverReplaced) {
  // A file, a user's folder (even one with a manifest.json of its own): refused before anything is
  // written, and left as they were. A stack is replaced.
  const std::string file = (dir.path / "notes.txt").string();
  std::ofstream(file) << "keep";
  const fs::path mine = dir.path / "mine";
  fs::create_directories(mine);
  std::ofstream(mine / "manifest.json") << "{\"format\": \"not ours\"}";
  std::ofstream(mine / "data.bin") << "keep";
  for (const std::string& target : {file, mine.string()}) {
    EXPECT_FALSE(isScaleStack(target));
    EXPECT_THROW(writeScaleStack(target, cloud, options, stack, float32()), FileError) << target;
    EXPECT_THROW(computeScaleStackToDisk(cloud, options, target), FileError) << target;
  }
  EXPECT_TRUE(fs::is_regular_file(file));
  EXPECT_TRUE(fs::exists(mine / "data.bin"));
  std::size_t entries = 0;
  for (auto it = fs::directory_iterator(dir.path); it != fs::directory_iterator(); ++it) ++entries;
  EXPECT_EQ(entries, 3u);  // sphere.stack, notes.txt, mine: no temporary left
  EXPECT_TRUE(isScaleStack(path));
  writeScaleStack(path, cloud, options, stack);  // replaces the float32 stack by a compact one
  EXPECT_EQ(ScaleStackReader(path).info().encoding, StackEncoding::Compact);
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
  bad.replace(bad.find("\"format_version\": 2"), 19, "\"format_version\": 4");
  std::ofstream(fs::path(path) / "manifest.json") << bad;
  EXPECT_THROW(ScaleStackReader{path}, FileError);
}

// The compact encodings: the decoded layer equals the float32 one within the tolerances of
// docs/STACK_FORMAT.md; invalid fits decode to zeros; out-of-range values are clamped and counted.
// Version 3 is written by default; version 2 (written on request) must still read.
struct CompactFixture : StackFixture {
  std::string compactPath, v2Path;
  ScaleStack edited;      // the stack with an invalid fit and out-of-range values
  std::vector<Vec3> rel;  // input positions relative to the origin
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
    edited.layers[1].kMax[7] = 1e12f;  // beyond float16
    edited.layers[2].neighbors[3] = 1000;
    // The sphere's anisotropy and nu are ~0 (code 0): every other point gets values spread over
    // the log codes' ranges and below them instead (nu < 1e4: within float16 for version 2).
    for (std::size_t j = 0; j < edited.layers.size(); ++j)
      for (std::size_t i = 0; i < cloud.size(); i += 2) {
        const double u = double((i * 7919 + j * 104729) % 1000) / 1000;
        edited.layers[j].anisotropy[i] = float(std::pow(10.0, -8 + 8 * u));
        edited.layers[j].geometricVariation[i] = float(std::pow(10.0, -11 + 15 * u));
      }
    // Beyond the version-3 ranges: an anisotropy below -1, a huge nu, an offset of 5000 t.
    L0.anisotropy[9] = -2.5f;
    edited.layers[1].geometricVariation[11] = 1e9f;
    for (std::size_t i = 0; i < cloud.size(); ++i)
      rel.push_back(cloud.absolutePosition(i) - cloud.origin());
    edited.layers[2].projection[3 * 13] = float(rel[13].x() + 5000 * scale(2));
    ASSERT_TRUE(L0.valid[9] && edited.layers[1].valid[11]);
    compactPath = (dir.path / "sphere_compact.stack").string();
    writeScaleStack(compactPath, cloud, options, edited);  // compact is the default
    v2Path = (dir.path / "sphere_v2.stack").string();
    StackWriteOptions v2;
    v2.compactVersion = 2;
    writeScaleStack(v2Path, cloud, options, edited, v2);
  }
  double scale(std::size_t j) const { return stack.summary.series.scales[j]; }
  bool clampedEntry(std::size_t j, std::size_t i) const {
    return (j == 1 && (i == 7 || i == 11)) || (j == 0 && i == 9) || (j == 2 && i == 13);
  }
  nlohmann::json manifest(const std::string& stackPath) const {
    std::ifstream in(fs::path(stackPath) / "manifest.json");
    return nlohmann::json::parse(in);
  }
  void writeManifest(const std::string& stackPath, const nlohmann::json& m) const {
    std::ofstream(fs::path(stackPath) / "manifest.json") << m.dump(1);
  }
  // Writes `good` edited as the compact stack's manifest: the reader must refuse it.
  void expectRefused(const nlohmann::json& good, const std::function<void(nlohmann::json&)>& edit,
                     const char* what) const {
    nlohmann::json m = good;
    edit(m);
    expectRefused(m.dump(1), what);
  }
  void expectRefused(const std::string& manifestText, const char* what) const {
    std::ofstream(fs::path(compactPath) / "manifest.json") << manifestText;
    try {
      ScaleStackReader reader(compactPath);
      ADD_FAILURE() << what << " was accepted";
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
    }
  }
  void checkDecoded(const std::string& stackPath, int version) const;
};

// D: decoded compact entry k; F: float32 entry i (input position relative to the origin: r).
void expectDecodedClose(const ScaleLayer& D, const ScaleLayer& F, std::size_t i, std::size_t k,
                        double t, const Vec3& r, int version) {
  ASSERT_EQ(D.valid[k], F.valid[i]);
  const double h = std::ldexp(1.0, -11);    // float16 relative precision (half an ulp)
  const double sub = std::ldexp(1.0, -25);  // half the smallest float16 subnormal
  const double f32 = 1.2e-7;                // float32 rounding of a decoded value (relative)
  auto close = [&](double d, double f, double scale, const char* what) {
    // stored f * scale as float16, decoded / scale; + float32 rounding of the decoded value
    const double tol = (h * std::abs(f * scale) + sub) / scale + f32 * std::abs(f) + 1e-30;
    EXPECT_LE(std::abs(d - f), tol) << what << " point " << i << ": " << d << " vs " << f;
  };
  // projection = input + offset t, offset = (projection - input) / t as float16 (version 2) or
  // with a shared exponent (version 3: error <= max|offset| / 255.5 + 2^-28 per coordinate).
  Vec3 offset;
  for (int c = 0; c < 3; ++c) offset[c] = (double(F.projection[3 * i + c]) - r[c]) / t;
  for (int c = 0; c < 3; ++c) {
    const double coded = version >= 3
                             ? std::max(quant::kOffsetRelativeError * offset.cwiseAbs().maxCoeff(),
                                        quant::kOffsetAbsoluteFloor)
                             : h * std::abs(offset[c]) + sub;
    EXPECT_LE(std::abs(double(D.projection[3 * k + c]) - double(F.projection[3 * i + c])),
              coded * t + 2 * f32 * std::abs(F.projection[3 * i + c]))
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
  if (version >= 3) {
    // 8-bit log codes: relative error <= sqrt(r) - 1 in [lo, hi], absolute lo sqrt(r) / 2 below;
    // the anisotropy is signed (the fits give a few negative values), negative nu decodes as 0.
    static const quant::Log8Code aniso(quant::kAnisotropyLogMin, quant::kAnisotropyLogMax, true);
    static const quant::Log8Code nu(quant::kVariationLogMin, quant::kVariationLogMax);
    auto logClose = [&](double d, double f, const quant::Log8Code& code, const char* what) {
      if (f < 0 && !code.isSigned()) {
        EXPECT_EQ(d, 0.0) << what << " point " << i;
        return;
      }
      const double tol =
          code.maxRelativeError() * std::abs(f) + code.absoluteFloor() + f32 * std::abs(f);
      EXPECT_LE(std::abs(d - f), tol) << what << " point " << i << ": " << d << " vs " << f;
    };
    logClose(D.anisotropy[k], F.anisotropy[i], aniso, "anisotropy");
    logClose(D.geometricVariation[k], F.geometricVariation[i], nu, "nu");
  } else {
    close(D.anisotropy[k], F.anisotropy[i], 1, "anisotropy");
    close(D.geometricVariation[k], F.geometricVariation[i], 1, "geometricVariation");
  }
  EXPECT_EQ(D.fitness[k], 0.0f);  // not stored
}

void CompactFixture::checkDecoded(const std::string& stackPath, int version) const {
  ScaleStackReader reader(stackPath);
  EXPECT_EQ(reader.info().formatVersion, version);
  EXPECT_EQ(reader.info().encoding, StackEncoding::Compact);
  // Version 3: offset 4 + frame 4 + 4 float16 + anisotropy, nu, neighbors 1 each + 1/8.
  EXPECT_DOUBLE_EQ(reader.info().bytesPerPointPerScale,
                   version >= 3 ? 4 + 4 + 4 * 2 + 3 + 75.0 / 600 : 6 + 4 + 6 * 2 + 1 + 75.0 / 600);
  EXPECT_NO_THROW(reader.verifyChecksums());
  EXPECT_NO_THROW(reader.checkInput(cloud, "sphere"));
  std::size_t invalid = 0;
  for (std::size_t j = 0; j < 3; ++j) {
    const ScaleLayer D = reader.readScale(j);
    ASSERT_EQ(D.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      invalid += edited.layers[j].valid[i] ? 0 : 1;
      if (clampedEntry(j, i)) continue;
      expectDecodedClose(D, edited.layers[j], i, i, scale(j), rel[i], version);
    }
    for (const auto* v : {&D.projection, &D.kMax, &D.anisotropy, &D.geometricVariation})
      for (float x : *v) ASSERT_TRUE(std::isfinite(x));
  }
  EXPECT_GE(invalid, 1u);
  // Overflows are clamped, never inf: float16 to 65504 / t.
  EXPECT_FLOAT_EQ(reader.readScale(1).kMax[7], float(65504.0 / scale(1)));
  EXPECT_EQ(reader.readScale(2).neighbors[3], 255);
  if (version >= 3) {
    // The offset to 255 2^(31 - 27) = 4080 t, the anisotropy -2.5 to the top negative code, nu
    // to the top code.
    EXPECT_FLOAT_EQ(reader.readScale(2).projection[3 * 13], float(rel[13].x() + 4080 * scale(2)));
    const quant::Log8Code aniso(quant::kAnisotropyLogMin, quant::kAnisotropyLogMax, true);
    EXPECT_FLOAT_EQ(reader.readScale(0).anisotropy[9], float(aniso.decode(0x80 | 127)));
    const quant::Log8Code nu(quant::kVariationLogMin, quant::kVariationLogMax);
    EXPECT_FLOAT_EQ(reader.readScale(1).geometricVariation[11], float(nu.decode(255)));
    // Every clamp is counted: kMax, the offset, the anisotropy beyond +-1 and the huge nu.
    std::size_t logClamps = 0;
    for (const ScaleLayer& L : edited.layers)
      for (std::size_t i = 0; i < L.size(); ++i)
        if (L.valid[i])
          logClamps += (std::abs(L.anisotropy[i]) > quant::kAnisotropyLogMax) +
                       (L.geometricVariation[i] > quant::kVariationLogMax);
    EXPECT_GE(logClamps, 2u);
    EXPECT_EQ(reader.info().clampedValues, 2 + logClamps);
    const nlohmann::json m = manifest(stackPath);
    EXPECT_EQ(m["quantities"]["projection_offset"]["clamped"], 1);
    EXPECT_EQ(m["quantities"]["curv_max_t"]["clamped"], 1);
    EXPECT_GE(m["quantities"]["anisotropy"]["clamped"].get<int>(), 1);
    EXPECT_GE(m["quantities"]["geometric_variation"]["clamped"].get<int>(), 1);
  } else {
    EXPECT_NEAR(reader.readScale(2).projection[3 * 13], rel[13].x() + 5000 * scale(2),
                5000 * scale(2) * std::ldexp(1.0, -11) + 1e-5);
    EXPECT_FLOAT_EQ(reader.readScale(0).anisotropy[9], -2.5f);
    EXPECT_EQ(reader.info().clampedValues, 2u);  // kMax = 1e12, nu = 1e9
  }
  // By point: the same values as by scale.
  for (std::size_t i : {std::size_t(0), std::size_t(5), std::size_t(13), cloud.size() - 1}) {
    const ScaleLayer S = reader.readPointSeries(i);
    ASSERT_EQ(S.size(), 3u);
    for (std::size_t j = 0; j < 3; ++j) {
      const ScaleLayer D = reader.readScale(j);
      EXPECT_EQ(S.projection[3 * j], D.projection[3 * i]);
      EXPECT_EQ(S.projection[3 * j + 1], D.projection[3 * i + 1]);
      EXPECT_EQ(S.normal[3 * j + 2], D.normal[3 * i + 2]);
      EXPECT_EQ(S.dirMin[3 * j], D.dirMin[3 * i]);
      EXPECT_EQ(S.kMin[j], D.kMin[i]);
      EXPECT_EQ(S.tau[j], D.tau[i]);
      EXPECT_EQ(S.anisotropy[j], D.anisotropy[i]);
      EXPECT_EQ(S.geometricVariation[j], D.geometricVariation[i]);
      EXPECT_EQ(S.valid[j], D.valid[i]);
      EXPECT_EQ(S.neighbors[j], D.neighbors[i]);
    }
  }
}

TEST_F(CompactFixture, Version3DecodesWithinTheDocumentedTolerances) {
  checkDecoded(compactPath, 3);
  // The manifest names each codec and its parameters (numpy needs nothing else).
  const nlohmann::json q = manifest(compactPath)["quantities"];
  EXPECT_EQ(q["projection_offset"]["dtype"], "<u4");
  EXPECT_EQ(q["projection_offset"]["codec"], "shared_exponent");
  EXPECT_EQ(q["projection_offset"]["bias"], quant::kOffsetBias);
  EXPECT_EQ(q["anisotropy"]["codec"], "slog8");
  EXPECT_EQ(q["geometric_variation"]["codec"], "log8");
  EXPECT_EQ(q["anisotropy"]["log_min"], quant::kAnisotropyLogMin);
  EXPECT_EQ(q["geometric_variation"]["log_max"], quant::kVariationLogMax);
  EXPECT_EQ(q["curv_max_t"]["codec"], "float16");
  // Streaming gives the same files as the in-memory writer.
  computeScaleStackToDisk(cloud, options, path);
  ScaleStackReader streamed(path);
  EXPECT_EQ(streamed.info().formatVersion, 3);
  EXPECT_EQ(streamed.readScale(2).kMax, ScaleStackReader(compactPath).readScale(2).kMax);
  const std::string plain = (dir.path / "plain.stack").string();
  writeScaleStack(plain, cloud, options, stack);
  EXPECT_EQ(streamed.readScale(1).anisotropy, ScaleStackReader(plain).readScale(1).anisotropy);
  EXPECT_EQ(streamed.readScale(2).projection, ScaleStackReader(plain).readScale(2).projection);
}

TEST_F(CompactFixture, Version2StacksStillRead) {
  checkDecoded(v2Path, 2);
  EXPECT_FALSE(manifest(v2Path)["quantities"]["projection_offset"].contains("codec"));
  StackWriteOptions bad;
  bad.compactVersion = 4;
  EXPECT_THROW(writeScaleStack(path, cloud, options, stack, bad), OptionError);
}

TEST_F(CompactFixture, Version3ManifestCodecsAreValidated) {
  const nlohmann::json good = manifest(compactPath);
  auto refused = [&](const std::function<void(nlohmann::json&)>& edit, const char* what) {
    expectRefused(good, edit, what);
  };
  refused([](nlohmann::json& m) { m["quantities"]["projection_offset"]["bias"] = 99; }, "bias 99");
  refused([](nlohmann::json& m) { m["quantities"]["projection_offset"].erase("bias"); }, "no bias");
  refused([](nlohmann::json& m) { m["quantities"]["anisotropy"]["log_min"] = 0.0; }, "log_min 0");
  refused([](nlohmann::json& m) { m["quantities"]["geometric_variation"]["log_max"] = 1e-12; },
          "log_max < log_min");
  refused([](nlohmann::json& m) { m["quantities"]["anisotropy"]["codec"] = "float16"; },
          "a wrong codec");
  refused([](nlohmann::json& m) { m["quantities"]["projection_offset"]["scaling"] = "none"; },
          "a wrong scaling");
  refused([](nlohmann::json& m) { m["format_version"] = 4; }, "format version 4");
  // A different (valid) range is used as written: the decoders read the manifest.
  nlohmann::json m = good;
  m["quantities"]["anisotropy"]["log_max"] = 10.0;
  writeManifest(compactPath, m);
  const ScaleLayer D = ScaleStackReader(compactPath).readScale(0);
  EXPECT_LT(D.anisotropy[9], -1.0f);  // the top negative code of a range up to 10
  writeManifest(compactPath, good);
  const ScaleLayer G = ScaleStackReader(compactPath).readScale(0);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) differ += D.anisotropy[i] != G.anisotropy[i];
  EXPECT_GT(differ, cloud.size() / 4);  // the half with spread values, but the smallest
  // Each log code has one codec: an unsigned anisotropy or a signed nu is refused.
  for (const auto& [name, codec] :
       {std::pair{"anisotropy", "log8"}, std::pair{"geometric_variation", "slog8"}}) {
    m = good;
    m["quantities"][name]["codec"] = codec;
    writeManifest(compactPath, m);
    EXPECT_THROW(ScaleStackReader{compactPath}, FileError) << name << " " << codec;
  }
  writeManifest(compactPath, good);
}

// nlohmann's get<int>() / get<std::size_t>() cast a float with static_cast, undefined out of range
// (UBSan in fuzz_stack): integers are read with jsonInteger, and anything else is refused.
TEST_F(CompactFixture, NonIntegerCountsInTheManifestAreRefused) {
  const nlohmann::json good = manifest(compactPath);
  expectRefused(
      good, [](nlohmann::json& m) { m["point_count"] = 1e300; }, "point_count 1e300");
  expectRefused(
      good, [](nlohmann::json& m) { m["point_count"] = -1.5; }, "point_count -1.5");
  expectRefused(
      good, [](nlohmann::json& m) { m["format_version"] = 3e10; }, "version 3e10");
  expectRefused(
      good, [](nlohmann::json& m) { m["scale_count"] = 3.5; }, "scale_count 3.5");
  expectRefused(
      good, [](nlohmann::json& m) { m["stats"][0]["samples"] = -1e30; }, "samples");
  expectRefused(
      good, [](nlohmann::json& m) { m["clamped_values"] = 1e20; }, "clamped 1e20");
  expectRefused(
      good, [](nlohmann::json& m) { m["quantities"]["projection_offset"]["bias"] = 1e300; },
      "bias 1e300");
  expectRefused(
      good, [](nlohmann::json& m) { m["quantities"]["frame"]["shape"][1] = 1e300; }, "shape 1e300");
  // An integral float is an integer (as a hand-edited or another program's manifest may say).
  nlohmann::json m = good;
  m["point_count"] = double(cloud.size());
  writeManifest(compactPath, m);
  EXPECT_EQ(ScaleStackReader(compactPath).pointCount(), cloud.size());
  writeManifest(compactPath, good);
}

TEST_F(CompactFixture, DeeplyNestedManifestIsRefused) {
  // 100000 nested arrays as "parameters": dump() (StackInfo::parametersJson) overflowed the stack.
  std::string text = manifest(compactPath).dump();
  const std::string key = "\"parameters\":";
  ASSERT_NE(text.find(key), std::string::npos);
  text.insert(text.find(key) + key.size(),
              std::string(100000, '[') + std::string(100000, ']') + ",\"old_parameters\":");
  expectRefused(text, "100000 nested arrays");
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

TEST_F(CompactFixture, PythonReaderDecodesLikeTheReader) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no numpy (apt-get install python3-numpy)";
  // One Python process (importing numpy dominates the time) decodes both stacks, every scale and
  // one point's series, with read_stack.py's functions, and runs its command line on version 3.
  const fs::path py = dir.path / "decode.py";
  const std::string columns =
      "[d['projection'], d['anisotropy'], d['geometric_variation'], d['curv_max'], d['gls_tau'], "
      "d['normal'], d['dir_min'], d['fit_valid']]";
  std::ofstream(py) << "import sys, numpy as np\n"
                    << "sys.dont_write_bytecode = True  # nothing written into the source tree\n"
                    << "sys.path.insert(0, '" << SCALESPACE_SOURCE_DIR << "/scripts')\n"
                    << "import read_stack as r\n"
                    << "for path in ('" << compactPath << "', '" << v2Path << "'):\n"
                    << "    m, a, x = r.load_stack(path)\n"
                    << "    rows = []\n"
                    << "    for j in range(m['scale_count']):\n"
                    << "        d = r.decode_scale(m, a, x, j)\n"
                    << "        rows.append(np.column_stack(" << columns << "))\n"
                    << "    d = r.decode_point(m, a, x, 13)\n"
                    << "    rows.append(np.column_stack(" << columns << "))\n"
                    << "    np.savetxt(path + '.txt', np.vstack(rows), fmt='%.17g')\n"
                    << "sys.argv = ['read_stack.py', '" << compactPath << "', '--scale', '1', "
                    << "'--point', '17']\n"
                    << "sys.stdout = open('" << (dir.path / "main.txt").string() << "', 'w')\n"
                    << "r.main()\n";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + py.string()).c_str()), 0);
  for (const std::string& stackPath : {compactPath, v2Path}) {
    SCOPED_TRACE(stackPath);
    ScaleStackReader reader(stackPath);
    const std::size_t n = cloud.size(), m = reader.scaleCount();
    std::ifstream in(stackPath + ".txt");
    std::vector<std::array<double, 14>> rows;
    for (std::array<double, 14> row; in >> row[0];) {
      for (std::size_t c = 1; c < 14; ++c) in >> row[c];
      rows.push_back(row);
    }
    ASSERT_EQ(rows.size(), m * n + m);
    const ScaleLayer S = reader.readPointSeries(13);
    for (std::size_t j = 0; j < m; ++j) {
      const ScaleLayer D = reader.readScale(j);
      for (std::size_t r = 0; r <= n; ++r) {
        // Row r < n: point r of scale j; row n: scale j of point 13's series.
        const auto& row = r < n ? rows[j * n + r] : rows[m * n + j];
        const ScaleLayer& L = r < n ? D : S;
        const std::size_t i = r < n ? r : j;
        // The offsets decode to the same doubles (integer operations and ldexp), so the
        // projections are equal as float32; so are the float16 quantities.
        for (int c = 0; c < 3; ++c) ASSERT_EQ(float(row[std::size_t(c)]), L.projection[3 * i + c]);
        ASSERT_EQ(float(row[5]), L.kMax[i]);
        ASSERT_EQ(float(row[6]), L.tau[i]);
        ASSERT_EQ(row[13], double(L.valid[i]));
        // Log codes: lo (hi / lo)^x through each side's pow: equal up to pow's last bit.
        ASSERT_NEAR(row[3], L.anisotropy[i], 2.4e-7 * std::abs(row[3]));
        ASSERT_NEAR(row[4], L.geometricVariation[i], 2.4e-7 * std::abs(row[4]));
        for (int c = 0; c < 3; ++c) {
          ASSERT_NEAR(row[7 + std::size_t(c)], L.normal[3 * i + c], 1e-6);
          ASSERT_NEAR(row[10 + std::size_t(c)], L.dirMin[3 * i + c], 1e-6);
        }
      }
    }
  }
  // The command line of the script prints the same values.
  std::ifstream in(dir.path / "main.txt");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const ScaleLayer D = ScaleStackReader(compactPath).readScale(1);
  auto value = [&](const std::string& key) {
    const auto at = text.find(key + " = ");
    EXPECT_NE(at, std::string::npos) << key << " in " << text;
    return at == std::string::npos ? 0.0 : std::stod(text.substr(at + key.size() + 3));
  };
  EXPECT_NEAR(value("curv_max[1, 17]"), D.kMax[17], 1e-5 * std::abs(D.kMax[17]));
  EXPECT_NEAR(value("anisotropy[1, 17]"), D.anisotropy[17], 1e-5 * std::abs(D.anisotropy[17]));
  EXPECT_NEAR(value("geometric_variation[1, 17]"), D.geometricVariation[17],
              1e-5 * std::abs(D.geometricVariation[17]));
  EXPECT_NEAR(value("dir_max_x[1, 17]"), D.dirMax[3 * 17], 1e-6);
  EXPECT_NEAR(value("projection_y[1, 17]"),
              double(D.projection[3 * 17 + 1]) + ScaleStackReader(compactPath).info().origin.y(),
              1e-6);
}

}  // namespace
}  // namespace scalespace
