#include <gtest/gtest.h>

#include <cstring>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/LasFormat.hpp"

namespace scalespace {
namespace {

struct LasPoint {
  std::int32_t X, Y, Z;
  std::uint16_t intensity;
  int returnNumber, returnCount, classification;
  double gpsTime;
  std::uint16_t rgb[3];
  std::uint16_t nir;
};

/// Writes `value` little endian at `at`, growing `bytes` when needed.
template <class T>
void put(std::string& bytes, std::size_t at, T value) {
  if (bytes.size() < at + sizeof(T)) bytes.resize(at + sizeof(T), '\0');
  std::memcpy(&bytes[at], &value, sizeof(T));
}

/// A LAS file built byte by byte from the specification (LAS 1.4 R15 tables), independent of the
/// reader: header of the version's size, `vlrBytes` of padding (as if VLRs), then the records.
std::string makeLas(int minor, int format, std::size_t recordLength,
                    const std::vector<LasPoint>& points, const Vec3& scale, const Vec3& offset,
                    std::size_t vlrBytes = 0) {
  const std::size_t headerSize = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
  std::string b(headerSize, '\0');
  std::memcpy(&b[0], "LASF", 4);
  put<std::uint8_t>(b, 24, 1);
  put<std::uint8_t>(b, 25, std::uint8_t(minor));
  put<std::uint16_t>(b, 94, std::uint16_t(headerSize));
  put<std::uint32_t>(b, 96, std::uint32_t(headerSize + vlrBytes));
  put<std::uint8_t>(b, 104, std::uint8_t(format));
  put<std::uint16_t>(b, 105, std::uint16_t(recordLength));
  put<std::uint32_t>(b, 107, format >= 6 ? 0u : std::uint32_t(points.size()));
  for (int k = 0; k < 3; ++k) {
    put<double>(b, 131 + 8 * k, scale[k]);
    put<double>(b, 155 + 8 * k, offset[k]);
  }
  if (minor >= 4) put<std::uint64_t>(b, 247, points.size());
  b.append(vlrBytes, 'v');
  for (const LasPoint& p : points) {
    std::string r(recordLength, '\0');
    put(r, 0, p.X), put(r, 4, p.Y), put(r, 8, p.Z), put(r, 12, p.intensity);
    if (format < 6) {
      put<std::uint8_t>(r, 14, std::uint8_t(p.returnNumber | (p.returnCount << 3)));
      put<std::uint8_t>(r, 15, std::uint8_t(p.classification | 0x80));  // withheld bit set
      if (format == 1 || format == 3) put(r, 20, p.gpsTime);
      if (format == 2 || format == 3)
        for (int c = 0; c < 3; ++c) put(r, (format == 2 ? 20 : 28) + 2 * c, p.rgb[c]);
    } else {
      put<std::uint8_t>(r, 14, std::uint8_t(p.returnNumber | (p.returnCount << 4)));
      put<std::uint8_t>(r, 15, 0xFF);  // classification flags, channel, scan direction, edge
      put<std::uint8_t>(r, 16, std::uint8_t(p.classification));
      put<std::int16_t>(r, 18, -1234);  // scan angle
      put(r, 22, p.gpsTime);
      if (format >= 7)
        for (int c = 0; c < 3; ++c) put(r, 30 + 2 * c, p.rgb[c]);
      if (format == 8) put(r, 36, p.nir);
    }
    b += r;
  }
  return b;
}

const std::vector<LasPoint> kPoints = {
    {123456, -7, 2147483647, 65535, 1, 2, 6, 123456.789, {65535, 0, 1000}, 42},
    {-2147483647 - 1, 0, 5, 7, 2, 2, 2, -1.5, {1, 2, 3}, 65535},
};

TEST(Las, EveryFormatAndVersionDecodesScaleOffsetAndAttributes) {
  const Vec3 scale(0.01, 0.001, 0.0001), offset(500000, 4000000, -100);
  const std::pair<int, int> cases[] = {{2, 0}, {2, 1}, {2, 2}, {2, 3}, {3, 3},
                                       {4, 1}, {4, 6}, {4, 7}, {4, 8}};
  const std::size_t sizes[] = {20, 28, 26, 34, 0, 0, 30, 36, 38};
  for (const auto& [minor, format] : cases) {
    SCOPED_TRACE("LAS 1." + std::to_string(minor) + " format " + std::to_string(format));
    const std::size_t length = sizes[format] + 3;  // extra bytes are skipped
    ReadReport report;
    const PointCloud cloud =
        readLas(makeLas(minor, format, length, kPoints, scale, offset, 17), "t.las", {}, &report);
    EXPECT_EQ(report.format,
              "las 1." + std::to_string(minor) + " format " + std::to_string(format));
    ASSERT_EQ(cloud.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
      const LasPoint& p = kPoints[i];
      const Vec3 expected(p.X * scale[0] + offset[0], p.Y * scale[1] + offset[1],
                          p.Z * scale[2] + offset[2]);
      // The extreme raw values span 2e7 m, so recentring costs a few ulps of the extent here;
      // the georeferenced test below checks bit-exactness on a realistic extent.
      EXPECT_NEAR((cloud.absolutePosition(i) - expected).norm(), 0.0, 1e-8);
      EXPECT_EQ(cloud.findAttribute("intensity")->values[i], p.intensity);
      EXPECT_EQ(cloud.findAttribute("classification")->values[i], p.classification);
      EXPECT_EQ(cloud.findAttribute("return_number")->values[i], p.returnNumber);
      EXPECT_EQ(cloud.findAttribute("number_of_returns")->values[i], p.returnCount);
      const bool time = format == 1 || format == 3 || format >= 6;
      ASSERT_EQ(cloud.findAttribute("gps_time") != nullptr, time);
      if (time) {
        EXPECT_EQ(cloud.findAttribute("gps_time")->values[i], p.gpsTime);
      }
      const bool colour = format == 2 || format == 3 || format >= 7;
      ASSERT_EQ(cloud.findAttribute("green") != nullptr, colour);
      if (colour) {
        EXPECT_EQ(cloud.findAttribute("red")->values[i], p.rgb[0]);
        EXPECT_EQ(cloud.findAttribute("green")->values[i], p.rgb[1]);
        EXPECT_EQ(cloud.findAttribute("blue")->values[i], p.rgb[2]);
        EXPECT_EQ(cloud.findAttribute("blue")->type, ScalarType::UInt16);
      }
      ASSERT_EQ(cloud.findAttribute("nir") != nullptr, format == 8);
      if (format == 8) {
        EXPECT_EQ(cloud.findAttribute("nir")->values[i], p.nir);
      }
    }
    EXPECT_EQ(cloud.findAttribute("intensity")->type, ScalarType::UInt16);
    EXPECT_EQ(cloud.findAttribute("classification")->type, ScalarType::UInt8);
  }
}

TEST(Las, GeoreferencedCoordinatesAreBitExact) {
  const Vec3 scale(0.001, 0.001, 0.001), offset(650000, 5400000, 0);
  std::vector<LasPoint> points;
  for (int i = 0; i < 20; ++i)
    points.push_back({12345 + 1001 * i, -5000 + 77 * i, 120000 + 3 * i, 0, 1, 1, 2, 0, {}, 0});
  const PointCloud cloud = readLas(makeLas(4, 6, 30, points, scale, offset), "g.las");
  ASSERT_EQ(cloud.size(), 20u);
  EXPECT_NE(cloud.origin(), Vec3::Zero());
  for (std::size_t i = 0; i < 20; ++i) {
    const Vec3 expected(points[i].X * 0.001 + 650000, points[i].Y * 0.001 + 5400000,
                        points[i].Z * 0.001);
    EXPECT_EQ(cloud.absolutePosition(i), expected);
  }
}

TEST(Las, HeaderValidation) {
  const Vec3 scale(0.01, 0.01, 0.01), offset(0, 0, 0);
  const std::string good = makeLas(2, 0, 20, kPoints, scale, offset);
  EXPECT_EQ(readLas(good, "g.las").size(), 2u);
  auto expectError = [](const std::string& bytes, const std::string& needle) {
    try {
      readLas(bytes, "bad.las");
      FAIL() << "expected FileError: " << needle;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.las"), std::string::npos);
    }
  };
  expectError(good.substr(0, good.size() - 1), "holds only 1");  // truncated record
  std::string lying = good;
  put<std::uint32_t>(lying, 107, 4000000000u);
  expectError(lying, "declares 4000000000 points");
  std::string laz = good;
  put<std::uint8_t>(laz, 104, 0x80 | 3);
  expectError(laz, "LAZ");
  std::string waveform = good;
  put<std::uint8_t>(waveform, 104, 4);
  expectError(waveform, "unsupported point data format 4");
  std::string shortRecord = good;
  put<std::uint16_t>(shortRecord, 105, 19);
  expectError(shortRecord, "point record length 19");
  std::string offsetPastEnd = good;
  put<std::uint32_t>(offsetPastEnd, 96, 1000000);
  expectError(offsetPastEnd, "offset to point data");
  std::string zeroScale = good;
  put<double>(zeroScale, 139, 0.0);
  expectError(zeroScale, "scale factors");
  std::string version = good;
  put<std::uint8_t>(version, 25, 9);
  expectError(version, "unsupported LAS version 1.9");
  expectError("LASX", "signature");
  expectError(good.substr(0, 100), "unexpected end of file");
  std::string format6in12 = makeLas(4, 6, 30, kPoints, scale, offset);
  put<std::uint8_t>(format6in12, 25, 2);
  expectError(format6in12, "needs LAS 1.4");
  std::string counts = makeLas(4, 6, 30, kPoints, scale, offset);
  put<std::uint32_t>(counts, 107, 3);
  expectError(counts, "disagree");
}

TEST(Las, WriteReadRoundTrip) {
  // Positions on a 0.25 grid (exact after 0.1 mm quantisation), georeferenced.
  std::vector<Vec3> positions;
  for (int i = 0; i < 30; ++i)
    positions.emplace_back(650000.25 + i, 5400000.5 - 0.25 * i, 120.75 + 0.5 * (i % 3));
  for (const int format : {0, 1, 2, 3}) {
    SCOPED_TRACE(format);
    PointCloud cloud;
    cloud.setAbsolutePositions(positions);
    // Add every column first: addAttribute may move the columns, invalidating references.
    for (const char* name : {"classification", "return_number", "number_of_returns"})
      cloud.addAttribute(name, ScalarType::UInt8);
    cloud.addAttribute("intensity", ScalarType::UInt16);
    for (std::size_t i = 0; i < 30; ++i) {
      cloud.findAttribute("intensity")->values[i] = double(i * 2000);
      cloud.findAttribute("classification")->values[i] = double(i % 32);
      cloud.findAttribute("return_number")->values[i] = double(1 + i % 5);
      cloud.findAttribute("number_of_returns")->values[i] = 5;
    }
    if (format == 1 || format == 3) {
      auto& time = cloud.addAttribute("gps_time", ScalarType::Float64);
      for (std::size_t i = 0; i < 30; ++i) time.values[i] = 1e9 + 0.001 * double(i);
    }
    if (format >= 2)
      for (const char* c : {"red", "green", "blue"}) {
        auto& column = cloud.addAttribute(c, ScalarType::UInt16);
        for (std::size_t i = 0; i < 30; ++i) column.values[i] = double(i * 1000 + c[0]);
      }
    test::ScratchDir dir;
    writeCloud(cloud, dir.file("r.las"));
    ReadReport report;
    const PointCloud back = readCloud(dir.file("r.las"), {}, &report);
    EXPECT_EQ(report.format, "las 1.2 format " + std::to_string(format));
    ASSERT_EQ(back.size(), 30u);
    for (std::size_t i = 0; i < 30; ++i) EXPECT_EQ(back.absolutePosition(i), positions[i]);
    for (const auto& column : cloud.attributes()) {
      const AttributeColumn* read = back.findAttribute(column.name);
      ASSERT_NE(read, nullptr) << column.name;
      EXPECT_EQ(read->type, column.type) << column.name;
      EXPECT_EQ(read->values, column.values) << column.name;
    }
  }
}

}  // namespace
}  // namespace scalespace
