#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

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

/// The little-endian value at `at`; throws std::out_of_range past the end.
template <class T>
T get(const std::string& bytes, std::size_t at) {
  if (at + sizeof(T) > bytes.size()) throw std::out_of_range("get: past the end");
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
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

/// A georeferenced cloud holding exactly the standard attributes of point format `format` (0-3),
/// positions on a 0.25 grid (exact after the writer's 0.1 mm quantisation).
PointCloud standardCloud(int format, std::size_t n = 30) {
  std::vector<Vec3> positions;
  for (std::size_t i = 0; i < n; ++i)
    positions.emplace_back(650000.25 + double(i), 5400000.5 - 0.25 * double(i),
                           120.75 + 0.5 * double(i % 3));
  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  // Add every column first: addAttribute may move the columns, invalidating references.
  for (const char* name : {"classification", "return_number", "number_of_returns"})
    cloud.addAttribute(name, ScalarType::UInt8);
  cloud.addAttribute("intensity", ScalarType::UInt16);
  for (std::size_t i = 0; i < n; ++i) {
    cloud.findAttribute("intensity")->values[i] = double(i * 2000);
    cloud.findAttribute("classification")->values[i] = double(i % 32);
    cloud.findAttribute("return_number")->values[i] = double(1 + i % 5);
    cloud.findAttribute("number_of_returns")->values[i] = 5;
  }
  if (format == 1 || format == 3) {
    auto& time = cloud.addAttribute("gps_time", ScalarType::Float64);
    for (std::size_t i = 0; i < n; ++i) time.values[i] = 1e9 + 0.001 * double(i);
  }
  if (format >= 2)
    for (const char* c : {"red", "green", "blue"}) {
      auto& column = cloud.addAttribute(c, ScalarType::UInt16);
      for (std::size_t i = 0; i < n; ++i) column.values[i] = double(i * 1000 + c[0]);
    }
  return cloud;
}

TEST(Las, WriteReadRoundTrip) {
  for (const int format : {0, 1, 2, 3}) {
    SCOPED_TRACE(format);
    const PointCloud cloud = standardCloud(format);
    test::ScratchDir dir;
    writeCloud(cloud, dir.file("r.las"));
    ReadReport report;
    const PointCloud back = readCloud(dir.file("r.las"), {}, &report);
    EXPECT_EQ(report.format, "las 1.2 format " + std::to_string(format));
    ASSERT_EQ(back.size(), 30u);
    for (std::size_t i = 0; i < 30; ++i)
      EXPECT_EQ(back.absolutePosition(i), cloud.absolutePosition(i));
    for (const auto& column : cloud.attributes()) {
      const AttributeColumn* read = back.findAttribute(column.name);
      ASSERT_NE(read, nullptr) << column.name;
      EXPECT_EQ(read->type, column.type) << column.name;
      EXPECT_EQ(read->values, column.values) << column.name;
    }
  }
}

/// FNV-1a of a written file with the generating-software field (bytes 58-89, which holds the
/// library's version) zeroed: a fingerprint that survives version bumps.
std::uint64_t fingerprint(std::string bytes) {
  std::fill(bytes.begin() + 58, bytes.begin() + 90, '\0');
  std::uint64_t hash = 14695981039346656037ull;
  for (const char c : bytes) hash = (hash ^ std::uint8_t(c)) * 1099511628211ull;
  return hash;
}

std::string writeLasToString(const PointCloud& cloud) {
  std::ostringstream out;
  writeLas(cloud, out, "mem.las");
  return out.str();
}

TEST(Las, WithoutExtrasTheOutputIsLas12AsBefore) {
  // Fingerprints of what the writer produced before extra bytes existed (commit 0c12356).
  const std::uint64_t before[4][2] = {{18362886975166493822ull, 13702835586363304131ull},
                                      {10135040018387025781ull, 18377907835617953668ull},
                                      {10985740020260623206ull, 13073384271656238215ull},
                                      {10350626805489769361ull, 2151592195820227092ull}};
  const std::size_t recordLength[4] = {20, 28, 26, 34};
  for (const int format : {0, 1, 2, 3})
    for (const std::size_t n : {0, 30}) {
      SCOPED_TRACE("format " + std::to_string(format) + ", " + std::to_string(n) + " points");
      const std::string bytes = writeLasToString(standardCloud(format, n));
      ASSERT_EQ(bytes.size(), 227 + n * recordLength[format]);
      EXPECT_EQ(bytes[24], 1);
      EXPECT_EQ(bytes[25], 2);
      EXPECT_EQ(get<std::uint16_t>(bytes, 94), 227);   // header size
      EXPECT_EQ(get<std::uint32_t>(bytes, 96), 227u);  // offset to point data
      EXPECT_EQ(get<std::uint32_t>(bytes, 100), 0u);   // no VLR
      EXPECT_EQ(bytes[104], format);
      EXPECT_EQ(get<std::uint16_t>(bytes, 105), recordLength[format]);
      EXPECT_EQ(fingerprint(bytes), before[format][n == 0 ? 0 : 1]);
    }
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

/// Every column of `expected` is in `actual` with the same type and the same bits, and `actual`
/// has no other column.
void expectSameColumns(const PointCloud& expected, const PointCloud& actual) {
  ASSERT_EQ(actual.attributes().size(), expected.attributes().size());
  for (const AttributeColumn& column : expected.attributes()) {
    const AttributeColumn* read = actual.findAttribute(column.name);
    ASSERT_NE(read, nullptr) << column.name;
    EXPECT_EQ(read->type, column.type) << column.name;
    ASSERT_EQ(read->values.size(), column.values.size());
    for (std::size_t i = 0; i < column.values.size(); ++i)
      EXPECT_TRUE(sameBits(read->values[i], column.values[i]))
          << column.name << " point " << i << ": " << read->values[i] << " vs " << column.values[i];
  }
}

TEST(Las, ExtraBytesRoundTripEveryTypeAndNormals) {
  // Standard fields of format 3, normals, a column of every ScalarType at the type's limits
  // (makeRichCloud), nir (no field in formats 0-3), NaN and infinities in the float columns.
  PointCloud cloud = standardCloud(3);
  const PointCloud rich = test::makeRichCloud(30, Vec3::Zero());
  cloud.setNormals(rich.normals());
  for (const AttributeColumn& column : rich.attributes())
    cloud.addAttribute(column.name, column.type).values = column.values;
  cloud.addAttribute("nir", ScalarType::UInt16).values[4] = 65535;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  cloud.findAttribute("a_float32")->values[2] = nan;
  cloud.findAttribute("a_float32")->values[3] = -inf;
  cloud.findAttribute("a_float64")->values[2] = nan;
  cloud.findAttribute("a_float64")->values[3] = inf;
  cloud.findAttribute("a_float64")->values[4] = std::numeric_limits<double>::denorm_min();

  test::ScratchDir dir;
  writeCloud(cloud, dir.file("x.las"));
  const std::string bytes = test::readText(dir.file("x.las"));
  // LAS 1.4 header (R15 Sec. 2.4), one VLR of 3 + 9 descriptors, format 3 stays format 3.
  EXPECT_EQ(bytes[25], 4);
  EXPECT_EQ(get<std::uint16_t>(bytes, 94), 375);
  EXPECT_EQ(get<std::uint32_t>(bytes, 96), 375u + 54 + 192 * 12);
  EXPECT_EQ(get<std::uint32_t>(bytes, 100), 1u);
  EXPECT_EQ(bytes[104], 3);
  const std::size_t extraLength = 3 * 4 + 1 + 1 + 2 + 2 + 4 + 4 + 4 + 8 + 2;
  EXPECT_EQ(get<std::uint16_t>(bytes, 105), 34 + extraLength);
  EXPECT_EQ(get<std::uint32_t>(bytes, 107), 30u);  // legacy count
  EXPECT_EQ(get<std::uint64_t>(bytes, 235), 0u);   // no EVLR
  EXPECT_EQ(get<std::uint32_t>(bytes, 243), 0u);
  EXPECT_EQ(get<std::uint64_t>(bytes, 247), 30u);
  for (int r = 0; r < 5; ++r) {
    EXPECT_EQ(get<std::uint64_t>(bytes, 255 + 8 * r), 6u);  // return numbers 1-5, 6 each
    EXPECT_EQ(get<std::uint32_t>(bytes, 111 + 4 * r), 6u);
  }
  EXPECT_EQ(bytes.substr(375 + 2, 10), std::string("LASF_Spec\0", 10));
  EXPECT_EQ(get<std::uint16_t>(bytes, 375 + 18), 4);
  EXPECT_EQ(get<std::uint16_t>(bytes, 375 + 20), 192 * 12);
  const std::size_t firstDescriptor = 375 + 54;
  EXPECT_EQ(bytes[firstDescriptor + 2], 9);  // nx: float
  EXPECT_EQ(bytes.substr(firstDescriptor + 4, 3), std::string("nx\0", 3));
  const int dataTypes[] = {9, 9, 9, 2, 1, 4, 3, 6, 5, 9, 10, 3};  // a_int8 ... a_float64, nir
  for (std::size_t j = 0; j < 12; ++j)
    EXPECT_EQ(bytes[firstDescriptor + 192 * j + 2], dataTypes[j]) << "descriptor " << j;

  ReadReport report;
  const PointCloud back = readCloud(dir.file("x.las"), {}, &report);
  EXPECT_EQ(report.format, "las 1.4 format 3");
  ASSERT_EQ(back.size(), 30u);
  for (std::size_t i = 0; i < 30; ++i)
    EXPECT_EQ(back.absolutePosition(i), cloud.absolutePosition(i));
  ASSERT_TRUE(back.hasNormals());  // stored as float, as PLY stores them
  for (std::size_t i = 0; i < 30; ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(sameBits(back.normals()[i][k], double(float(cloud.normals()[i][k]))));
  expectSameColumns(cloud, back);
}

TEST(Las, ComputedColumnsSurviveAsExtraBytes) {
  // What `curvature` writes: no normals but float nx ny nz columns (read back as the normals),
  // computed columns, an integer flag, and an incomplete colour (no colour field in format 0).
  PointCloud cloud = standardCloud(0, 5);
  for (const char* name : {"nx", "ny", "nz", "curv_mean"})
    cloud.addAttribute(name, ScalarType::Float32, 0.5);
  cloud.addAttribute("fit_valid", ScalarType::UInt8, 1).values[3] = 0;
  cloud.addAttribute("red", ScalarType::UInt16, 7);
  cloud.addAttribute("green", ScalarType::UInt16, 9);
  const std::string name31(31, 'q');
  cloud.addAttribute(name31, ScalarType::Int16, -1);
  ReadReport report;
  const PointCloud back = readLas(writeLasToString(cloud), "c.las", {}, &report);
  EXPECT_EQ(report.format, "las 1.4 format 0");
  ASSERT_TRUE(back.hasNormals());
  EXPECT_EQ(back.normals()[2], Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(back.findAttribute("nx"), nullptr);
  for (const char* name : {"curv_mean", "fit_valid", "red", "green", name31.c_str()}) {
    ASSERT_NE(back.findAttribute(name), nullptr) << name;
    EXPECT_EQ(back.findAttribute(name)->values, cloud.findAttribute(name)->values) << name;
    EXPECT_EQ(back.findAttribute(name)->type, cloud.findAttribute(name)->type) << name;
  }
  EXPECT_EQ(back.findAttribute("blue"), nullptr);
}

TEST(Las, WriterRejectsNamesThatDoNotFitADescriptor) {
  PointCloud cloud = standardCloud(0, 3);
  const std::string name32(32, 'q');
  cloud.addAttribute(name32, ScalarType::Float32);
  try {
    writeLasToString(cloud);
    FAIL() << "expected FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(name32), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at most 31"), std::string::npos) << e.what();
  }
  PointCloud wide = standardCloud(0, 1);
  for (int c = 0; c < 342; ++c) wide.addAttribute("c" + std::to_string(c), ScalarType::UInt8);
  EXPECT_THROW(writeLasToString(wide), FileError);  // the VLR holds 341 descriptors at most
  wide.removeAttribute("c341");
  EXPECT_EQ(readLas(writeLasToString(wide), "w.las").attributes().size(), 4u + 341);
  PointCloud clash = standardCloud(0, 3);
  clash.setNormals(std::vector<Vec3>(3, Vec3(0, 0, 1)));
  clash.addAttribute("nx", ScalarType::Float32);  // would be read back as the normal
  EXPECT_THROW(writeLasToString(clash), Error);
}

/// An Extra Bytes descriptor (LAS 1.4 R15 Sec. 4.3, 192 bytes).
std::string descriptor(int dataType, int options, const std::string& name, double scale = 0,
                       double offset = 0) {
  std::string d(192, '\0');
  d[2] = char(dataType);
  d[3] = char(options);
  d.replace(4, name.size(), name);
  put(d, 112, scale);
  put(d, 136, offset);
  d.resize(192);
  return d;
}

/// A VLR (R15 Sec. 2.5) holding `payload`.
std::string vlr(const std::string& user, std::uint16_t record, const std::string& payload) {
  std::string v(54, '\0');
  v.replace(2, user.size(), user);
  v.resize(54);
  put(v, 18, record);
  put<std::uint16_t>(v, 20, std::uint16_t(payload.size()));
  return v + payload;
}

/// makeLas with `vlrs` (`count` of them) between the header and the points.
std::string makeLasWithVlrs(int minor, int format, std::size_t recordLength,
                            const std::vector<LasPoint>& points, const std::string& vlrs,
                            std::uint32_t count) {
  const std::size_t headerSize = minor >= 4 ? 375 : 227;
  std::string b = makeLas(minor, format, recordLength, points, Vec3(0.01, 0.01, 0.01), Vec3::Zero(),
                          vlrs.size());
  b.replace(headerSize, vlrs.size(), vlrs);
  put(b, 100, count);
  return b;
}

/// The extra bytes of each record of a file made by makeLasWithVlrs.
template <class T>
void putExtra(std::string& las, std::size_t recordLength, std::size_t point, std::size_t at,
              T value) {
  put(las, get<std::uint32_t>(las, 96) + point * recordLength + at, value);
}

TEST(Las, ReadsExtraBytesByTheirDescriptors) {
  // Format 1 (28 bytes) + extra bytes at 28: 3 undocumented, ushort scaled, float, deprecated
  // array of 3 ulong (type 25), long long with a space in its name, char named like a standard
  // attribute, long with only the scale bit (its offset field is to be ignored), unnamed; then
  // double nx ny nz and 2 bytes no descriptor covers.
  const std::string descriptors =
      descriptor(0, 3, "padding") + descriptor(3, 0x18, "height", 0.01, 100) +
      descriptor(9, 0, "amplitude") + descriptor(25, 0, "old array") + descriptor(8, 0, "big id") +
      descriptor(2, 0, "intensity") + descriptor(6, 0x08, "", 0.5, 7) + descriptor(10, 0, "nx") +
      descriptor(10, 0, "ny") + descriptor(10, 0, "nz");
  const std::size_t length = 28 + 3 + 2 + 4 + 12 + 8 + 1 + 4 + 24 + 2;
  for (const int minor : {2, 4}) {  // the VLR is read in any version
    SCOPED_TRACE("LAS 1." + std::to_string(minor));
    std::string las = makeLasWithVlrs(
        minor, 1, length, kPoints,
        vlr("LASF_Projection", 34735, std::string(16, 'g')) + vlr("LASF_Spec", 4, descriptors), 2);
    for (std::size_t i = 0; i < 2; ++i) {
      putExtra<std::uint8_t>(las, length, i, 28, 0xEE);  // undocumented bytes
      putExtra<std::uint16_t>(las, length, i, 31, std::uint16_t(12345 + i));
      putExtra<float>(las, length, i, 33, -2.5f * float(i + 1));
      putExtra<std::uint32_t>(las, length, i, 37, 0xFFFFFFFFu);
      putExtra<std::int64_t>(las, length, i, 49, -(std::int64_t(1) << 40) - std::int64_t(i));
      putExtra<std::int8_t>(las, length, i, 57, std::int8_t(-5));
      putExtra<std::int32_t>(las, length, i, 58, -3);
      putExtra<double>(las, length, i, 62, 0.6);
      putExtra<double>(las, length, i, 70, -0.8 * double(i));
      putExtra<double>(las, length, i, 78, 1.0 / 3.0);
      putExtra<std::uint16_t>(las, length, i, 86, 0xBEEF);
    }
    ReadReport report;
    const PointCloud cloud = readLas(las, "e.las", {}, &report);
    EXPECT_EQ(report.format, "las 1." + std::to_string(minor) +
                                 " format 1, 2 extra bytes fields skipped (undocumented, "
                                 "deprecated array or reserved type)");
    ASSERT_EQ(cloud.size(), 2u);
    const std::pair<const char*, ScalarType> columns[] = {
        {"intensity", ScalarType::UInt16},    {"classification", ScalarType::UInt8},
        {"return_number", ScalarType::UInt8}, {"number_of_returns", ScalarType::UInt8},
        {"gps_time", ScalarType::Float64},    {"height", ScalarType::Float64},
        {"amplitude", ScalarType::Float32},   {"big_id", ScalarType::Float64},
        {"intensity_2", ScalarType::Int8},    {"extra_bytes_7", ScalarType::Float64}};
    ASSERT_EQ(cloud.attributes().size(), std::size(columns));
    for (std::size_t c = 0; c < std::size(columns); ++c) {
      EXPECT_EQ(cloud.attributes()[c].name, columns[c].first);
      EXPECT_EQ(cloud.attributes()[c].type, columns[c].second) << columns[c].first;
    }
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(cloud.findAttribute("gps_time")->values[i], kPoints[i].gpsTime);
      EXPECT_EQ(cloud.findAttribute("intensity")->values[i], kPoints[i].intensity);
      EXPECT_EQ(cloud.findAttribute("height")->values[i], double(12345 + i) * 0.01 + 100);
      EXPECT_EQ(cloud.findAttribute("amplitude")->values[i], -2.5 * double(i + 1));
      EXPECT_EQ(cloud.findAttribute("big_id")->values[i], -1099511627776.0 - double(i));
      EXPECT_EQ(cloud.findAttribute("intensity_2")->values[i], -5);
      EXPECT_EQ(cloud.findAttribute("extra_bytes_7")->values[i], -1.5);
      ASSERT_TRUE(cloud.hasNormals());
      EXPECT_EQ(cloud.normals()[i], Vec3(0.6, -0.8 * double(i), 1.0 / 3.0));
    }
  }
}

TEST(Las, ExtraBytesEdgeCases) {
  const auto read = [](const std::string& descriptors, std::size_t extra) {
    std::string las =
        makeLasWithVlrs(4, 0, 20 + extra, kPoints, vlr("LASF_Spec", 4, descriptors), 1);
    for (std::size_t i = 0; i < 2; ++i)
      for (std::size_t b = 0; b < extra; b += 2)
        putExtra<std::int16_t>(las, 20 + extra, i, 20 + b, std::int16_t(-16384));
    ReadReport report;
    PointCloud cloud = readLas(las, "e.las", {}, &report);
    return std::make_pair(std::move(cloud), report.format);
  };
  // A reserved type has no known size: it and the descriptors after it are skipped.
  const auto [reserved, reservedFormat] =
      read(descriptor(40, 0, "future") + descriptor(4, 0, "after"), 4);
  EXPECT_EQ(reserved.findAttribute("after"), nullptr);
  EXPECT_NE(reservedFormat.find("2 extra bytes fields skipped"), std::string::npos);
  // Integer nx ny nz are not normals; scaled ones are (float64 after scaling).
  const std::string shortNormals =
      descriptor(4, 0, "nx") + descriptor(4, 0, "ny") + descriptor(4, 0, "nz");
  const PointCloud integers = read(shortNormals, 6).first;
  EXPECT_FALSE(integers.hasNormals());
  ASSERT_NE(integers.findAttribute("ny"), nullptr);
  EXPECT_EQ(integers.findAttribute("ny")->values[1], -16384);
  const PointCloud scaled =
      read(descriptor(4, 0x08, "nx", 1.0 / 16384) + descriptor(4, 0x08, "ny", 1.0 / 16384) +
               descriptor(4, 0x08, "nz", 1.0 / 16384) + descriptor(4, 0, "nx"),
           8)
          .first;
  ASSERT_TRUE(scaled.hasNormals());
  EXPECT_EQ(scaled.normals()[0], Vec3(-1, -1, -1));
  ASSERT_NE(scaled.findAttribute("nx_2"), nullptr);  // the second nx is an attribute
  // Only two of the three: plain attributes.
  const PointCloud partial = read(descriptor(9, 0, "nx") + descriptor(9, 0, "ny"), 8).first;
  EXPECT_FALSE(partial.hasNormals());
  EXPECT_NE(partial.findAttribute("nx"), nullptr);
}

TEST(Las, MalformedExtraBytesVlrsThrow) {
  auto expectError = [](const std::string& bytes, const std::string& needle,
                        const std::string& where) {
    try {
      readLas(bytes, "bad.las");
      FAIL() << "expected FileError: " << needle;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.las: " + where + ":"), std::string::npos)
          << e.what();
    }
  };
  const std::string floatField = descriptor(9, 0, "f");
  // 375 header + 54 VLR header: the payload starts at byte 429.
  expectError(makeLasWithVlrs(4, 0, 24, kPoints, vlr("LASF_Spec", 4, floatField + "x"), 1),
              "not a whole number of 192-byte descriptors", "byte 429");
  expectError(makeLasWithVlrs(4, 0, 22, kPoints, vlr("LASF_Spec", 4, floatField), 1),
              "needs bytes 20-23 of a point record that is 22 bytes long", "byte 429");
  expectError(makeLasWithVlrs(4, 0, 24, kPoints,
                              vlr("LASF_Spec", 4, floatField + descriptor(0, 1, "u")), 1),
              "descriptor 2 ('u') needs bytes 24-24", "byte 621");
  // The VLR chain itself: one more VLR than there is room for, a payload longer than the room.
  const std::string ok = vlr("LASF_Spec", 4, floatField);
  expectError(makeLasWithVlrs(4, 0, 24, kPoints, ok, 2), "VLR 2 of 2's 54-byte header", "byte 621");
  std::string longPayload = makeLasWithVlrs(4, 0, 24, kPoints, ok, 1);
  put<std::uint16_t>(longPayload, 375 + 20, 193);
  expectError(longPayload, "VLR 1 of 1's payload of 193 bytes runs past", "byte 375");
}

}  // namespace
}  // namespace scalespace
