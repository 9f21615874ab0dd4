#pragma once
// Helpers for the io tests: a scratch folder removed at the end of each test, file I/O, and a
// cloud with every attribute type for round trips.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::test {

class ScratchDir {
 public:
  ScratchDir() {
    std::random_device device;
    path_ = std::filesystem::temp_directory_path() /
            ("scalespace-io-test-" + std::to_string(device()) + std::to_string(device()));
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }
  std::size_t entryCount() const {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(path_)) ++n;
    return n;
  }

 private:
  std::filesystem::path path_;
};

inline void writeText(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
}

inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// `n` points around `centre` with normals and one column of every ScalarType holding values at
/// the edges of the type's range.
inline PointCloud makeRichCloud(std::size_t n, const Vec3& centre, bool withAllTypes = true) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec3> positions(n), normals(n);
  for (std::size_t i = 0; i < n; ++i) {
    positions[i] = centre + Vec3(u(rng), u(rng), u(rng));
    normals[i] = Vec3(float(u(rng)), float(u(rng)), float(u(rng))).normalized();
    normals[i] = normals[i].cast<float>().cast<double>();
  }
  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  cloud.setNormals(normals);
  if (!withAllTypes) return cloud;
  const std::pair<const char*, ScalarType> columns[] = {
      {"a_int8", ScalarType::Int8},       {"a_uint8", ScalarType::UInt8},
      {"a_int16", ScalarType::Int16},     {"a_uint16", ScalarType::UInt16},
      {"a_int32", ScalarType::Int32},     {"a_uint32", ScalarType::UInt32},
      {"a_float32", ScalarType::Float32}, {"a_float64", ScalarType::Float64}};
  const double extremes[][2] = {
      {-128, 127},       {0, 255},       {-32768, 32767}, {0, 65535}, {-2147483648.0, 2147483647.0},
      {0, 4294967295.0}, {-3.5f, 1e30f}, {-1e300, 0.1}};
  for (std::size_t c = 0; c < 8; ++c) {
    AttributeColumn& column = cloud.addAttribute(columns[c].first, columns[c].second);
    for (std::size_t i = 0; i < n; ++i)
      column.values[i] = i == 0                             ? extremes[c][0]
                         : i == 1                           ? extremes[c][1]
                         : isIntegerType(columns[c].second) ? double(i % 100)
                                                            : double(float(u(rng)));
  }
  cloud.findAttribute("a_float64")->values[n - 1] = 0.1 + 1e-17 * 3;  // not a float
  return cloud;
}

/// Bit-exact comparison of absolute positions, normals (as floats) and attributes.
inline void expectSameCloud(const PointCloud& expected, const PointCloud& actual,
                            bool compareTypes = true) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(expected.absolutePosition(i)[k], actual.absolutePosition(i)[k]) << "point " << i;
    }
  }
  ASSERT_EQ(expected.hasNormals(), actual.hasNormals());
  if (expected.hasNormals()) {
    for (std::size_t i = 0; i < expected.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(float(expected.normals()[i][k]), float(actual.normals()[i][k]));
      }
    }
  }
  ASSERT_EQ(expected.attributes().size(), actual.attributes().size());
  for (std::size_t c = 0; c < expected.attributes().size(); ++c) {
    const auto& a = expected.attributes()[c];
    const auto& b = actual.attributes()[c];
    EXPECT_EQ(a.name, b.name);
    if (compareTypes) {
      EXPECT_EQ(a.type, b.type) << a.name;
    }
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      ASSERT_EQ(a.values[i], b.values[i]) << a.name << " point " << i;
    }
  }
}

}  // namespace scalespace::test
