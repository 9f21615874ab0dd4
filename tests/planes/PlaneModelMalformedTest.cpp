// Saved plane results that fuzz_planes (fuzz/fuzz_planes.cpp) found a crash with, reduced to a
// two-point, two-scale model: readPlaneModel must reject each with a FileError naming the file
// (before, the queries or `segment` read out of bounds).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/planes/PlaneExport.hpp"

using namespace scalespace;

namespace {

// One component on 2 points, alive at both scales.
std::string componentsJson(const std::string& component) {
  return R"({"input": "in.ply", "point_count": 2, "scales": [0.1, 0.2], "components": [)" +
         component + "]}";
}
const std::string kComponent =
    R"({"id": 0, "birth_level": 0, "birth_scale": 0.1, "death_level": 1, "death_scale": 0.2,
        "persistence": 1, "representative_level": 0, "point_count": 2, "normal": [0, 0, 1],
        "offset": 0, "rms": 0, "area": 1})";

// "SSPM", uint64 points, uint32 levels, int32 ids level-major.
std::string membership(std::uint64_t points, std::uint32_t levels, const std::vector<int>& ids) {
  std::string b = "SSPM";
  b.append(reinterpret_cast<const char*>(&points), 8);
  b.append(reinterpret_cast<const char*>(&levels), 4);
  b.append(reinterpret_cast<const char*>(ids.data()), ids.size() * 4);
  return b;
}
const std::string kMembership = membership(2, 2, {0, 0, 0, -1});

struct Files {
  // One folder per process: ctest runs the tests of this file in parallel processes.
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("scalespace_planes_malformed_" + std::to_string(::getpid()));
  Files(const std::string& json, const std::string& bin) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "components.json", std::ios::binary) << json;
    std::ofstream(dir / "membership.bin", std::ios::binary) << bin;
  }
  ~Files() { std::filesystem::remove_all(dir); }
};

void expectRejected(const std::string& json, const std::string& bin, const std::string& file) {
  const Files files(json, bin);
  try {
    readPlaneModel(files.dir.string());
    ADD_FAILURE() << "read without an error";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

std::string withKey(const std::string& key, const std::string& value) {
  std::string c = kComponent;
  const std::size_t at = c.find('"' + key + '"');
  const std::size_t from = c.find(':', at) + 2, to = c.find_first_of(",}", from);
  return c.replace(from, to - from, value);
}

}  // namespace

TEST(PlaneModelMalformed, TheValidModelIsRead) {
  const Files files(componentsJson(kComponent), kMembership);
  const PlaneModel model = readPlaneModel(files.dir.string());
  EXPECT_EQ(model.components.size(), 1u);
  EXPECT_EQ(model.membership.ids, (std::vector<int>{0, 0, 0, -1}));
}

TEST(PlaneModelMalformed, LevelsOutsideTheScalesAreRejected) {
  // fuzz_planes: representative_level 60 of 6 scales, read by `segment --brush / --similar`.
  expectRejected(componentsJson(withKey("representative_level", "60")), kMembership,
                 "components.json: component 0");
  expectRejected(componentsJson(withKey("representative_level", "-1")), kMembership,
                 "components.json");
  expectRejected(componentsJson(withKey("death_level", "2")), kMembership, "components.json");
  expectRejected(componentsJson(withKey("birth_level", "-2147483648")), kMembership,
                 "components.json");
  expectRejected(componentsJson(withKey("persistence", "5")), kMembership, "components.json");
}

TEST(PlaneModelMalformed, MembershipCountsThatWrapAreRejected) {
  // 16 + 4 n levels wraps to 16 for n = 2^62 (then: vector::resize(2^62), std::length_error).
  const std::string json = componentsJson(kComponent);
  expectRejected(json, membership(std::uint64_t(1) << 62, 2, {}), "membership.bin: byte 4");
  expectRejected(json, membership(std::uint64_t(1) << 61, 2, {}), "membership.bin: byte 4");
  // Points without levels: the queries would allocate a label per point.
  const std::string none =
      R"({"input": "in.ply", "point_count": 5, "scales": [], "components": []})";
  expectRejected(none, membership(std::uint64_t(1) << 60, 0, {}), "membership.bin: byte 4");
  expectRejected(json, kMembership.substr(0, 18), "membership.bin");  // 2 bytes of ids
}

TEST(PlaneModelMalformed, NonIntegerNumbersAreRejected) {
  // get<int>() of 1e300 was undefined behaviour (a float cast out of range; UBSan).
  expectRejected(componentsJson(withKey("birth_level", "1e300")), kMembership,
                 "components.json: component 0");
  expectRejected(componentsJson(withKey("point_count", "-1.5")), kMembership, "components.json");
  expectRejected(componentsJson(withKey("id", "0.5")), kMembership, "components.json");
  // The message names what is not a number by its type (dump() would recurse 100000 deep).
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  expectRejected(componentsJson(withKey("id", deep)), kMembership, "components.json");
  // An integral float is an integer.
  const Files files(componentsJson(withKey("death_level", "1.0")), kMembership);
  EXPECT_EQ(readPlaneModel(files.dir.string()).components.at(0).deathLevel, 1);
}
