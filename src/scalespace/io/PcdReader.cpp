#include <cmath>
#include <cstring>
#include <optional>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/Lzf.hpp"
#include "scalespace/io/PcdFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

enum class PcdData { Ascii, Binary, BinaryCompressed };

struct PcdField {
  std::string name;
  std::size_t size = 4;
  char type = 'F';
  std::size_t count = 1;
  ScalarType scalar = ScalarType::Float32;
  std::size_t offset = 0;  // bytes from the start of a binary record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::size_t points = 0;
  std::size_t pointSize = 0;
  PcdData data = PcdData::Ascii;
  std::size_t dataOffset = 0;
  std::size_t dataLine = 0;
  std::optional<Vec3> viewpoint;  // VIEWPOINT's translation
};

std::optional<ScalarType> pcdScalarType(char type, std::size_t size) {
  if (type == 'F' && size == 4) return ScalarType::Float32;
  if (type == 'F' && size == 8) return ScalarType::Float64;
  if (type == 'I' && size == 1) return ScalarType::Int8;
  if (type == 'I' && size == 2) return ScalarType::Int16;
  if (type == 'I' && size == 4) return ScalarType::Int32;
  if (type == 'U' && size == 1) return ScalarType::UInt8;
  if (type == 'U' && size == 2) return ScalarType::UInt16;
  if (type == 'U' && size == 4) return ScalarType::UInt32;
  return std::nullopt;
}

PcdHeader parseHeader(std::string_view data, const std::string& file) {
  LineScanner lines(data);
  std::string_view line;
  std::vector<std::string_view> tokens;
  PcdHeader header;
  std::vector<std::string_view> names, sizes, types, counts;
  std::optional<unsigned long long> width, height, points;
  bool haveVersion = false;
  while (true) {
    if (!lines.next(line))
      throw FileError(file, lineWhere(std::max<std::size_t>(1, lines.lineNumber())),
                      lines.lineNumber() == 0 ? "empty file: expected a PCD header"
                                              : "the header has no DATA line",
                      "the file is truncated or not a PCD file");
    splitWhitespace(line, tokens);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    const std::string where = lineWhere(lines.lineNumber());
    const std::string_view key = tokens[0];
    std::vector<std::string_view> rest(tokens.begin() + 1, tokens.end());
    auto single = [&]() {
      const auto value = rest.size() == 1 ? parseUnsigned(rest[0]) : std::nullopt;
      if (!value) throw FileError(file, where, "expected '" + std::string(key) + " <integer>'");
      return value;
    };
    if (key == "VERSION")
      haveVersion = true;
    else if (!haveVersion)
      throw FileError(file, where, "expected the PCD header to start with VERSION",
                      "not a PCD file: check the file extension");
    else if (key == "FIELDS" || key == "COLUMNS")
      names = rest;
    else if (key == "SIZE")
      sizes = rest;
    else if (key == "TYPE")
      types = rest;
    else if (key == "COUNT")
      counts = rest;
    else if (key == "WIDTH")
      width = single();
    else if (key == "HEIGHT")
      height = single();
    else if (key == "POINTS")
      points = single();
    else if (key == "VIEWPOINT") {
      // tx ty tz qw qx qy qz: the acquisition viewpoint in the points' frame; its position is
      // what orients a scan's normals (PointCloud::viewpoint).
      std::vector<double> values;
      for (const std::string_view token : rest)
        if (const auto value = parseNumber(token); value && std::isfinite(*value))
          values.push_back(*value);
      if (rest.size() != 7 || values.size() != 7)
        throw FileError(file, where, "expected 'VIEWPOINT tx ty tz qw qx qy qz' (7 numbers)");
      header.viewpoint = Vec3(values[0], values[1], values[2]);
    } else if (key == "DATA") {
      if (rest.size() != 1)
        throw FileError(file, where, "expected 'DATA ascii|binary|binary_compressed'");
      if (rest[0] == "ascii")
        header.data = PcdData::Ascii;
      else if (rest[0] == "binary")
        header.data = PcdData::Binary;
      else if (rest[0] == "binary_compressed")
        header.data = PcdData::BinaryCompressed;
      else
        throw FileError(file, where, "unknown DATA encoding '" + std::string(rest[0]) + "'",
                        "expected ascii, binary or binary_compressed");
      break;
    } else {
      throw FileError(file, where, "unknown header keyword " + quoted(key));
    }
  }
  header.dataOffset = lines.offset();
  header.dataLine = lines.lineNumber();
  const std::string where = lineWhere(lines.lineNumber());
  if (names.empty() || sizes.size() != names.size() || types.size() != names.size() ||
      (!counts.empty() && counts.size() != names.size()))
    throw FileError(file, where,
                    "FIELDS, SIZE, TYPE (and COUNT) must list the same number of entries (" +
                        std::to_string(names.size()) + ", " + std::to_string(sizes.size()) + ", " +
                        std::to_string(types.size()) + ", " + std::to_string(counts.size()) + ")");
  if (!width) throw FileError(file, where, "the header has no WIDTH");
  const unsigned long long h = height ? *height : 1;
  unsigned long long total = 0;
  const std::string product =
      "WIDTH * HEIGHT (" + std::to_string(*width) + " * " + std::to_string(h) + ")";
  if (__builtin_mul_overflow(*width, h, &total))
    throw FileError(file, where, product + " overflows");
  if (points && *points != total)
    throw FileError(file, where,
                    product + " does not equal POINTS (" + std::to_string(*points) + ")");
  header.points = std::size_t(total);
  for (std::size_t f = 0; f < names.size(); ++f) {
    PcdField field;
    field.name = std::string(names[f]);
    const auto size = parseUnsigned(sizes[f]);
    const auto count =
        counts.empty() ? std::optional<unsigned long long>(1) : parseUnsigned(counts[f]);
    if (types[f].size() != 1 || !size || !count || *count == 0 || *count > 4096)
      throw FileError(file, where, "bad SIZE/TYPE/COUNT for field '" + field.name + "'");
    field.type = types[f][0];
    field.size = std::size_t(*size);
    field.count = std::size_t(*count);
    const auto scalar = pcdScalarType(field.type, field.size);
    if (!scalar)
      throw FileError(file, where,
                      "field '" + field.name + "' has unsupported TYPE " + field.type + " SIZE " +
                          std::to_string(field.size),
                      "supported: I1 I2 I4 U1 U2 U4 F4 F8");
    field.scalar = *scalar;
    field.offset = header.pointSize;
    header.pointSize += field.size * field.count;
    header.fields.push_back(field);
  }
  return header;
}

/// Where each (field, component) goes: position/normal axis, column, packed colour, or nothing.
struct Target {
  enum Kind { Skip, Position, Normal, Column, PackedColour } kind = Skip;
  std::size_t index = 0;  // axis, column, or first colour column
};

}  // namespace

PointCloud readPcd(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  const PcdHeader header = parseHeader(data, file);
  CloudBuilder builder(file, options);
  std::vector<std::vector<Target>> targets(header.fields.size());
  int positions = 0, normals = 0;
  static const char* positionNames[3] = {"x", "y", "z"};
  static const char* normalNames[3] = {"normal_x", "normal_y", "normal_z"};
  for (const auto& field : header.fields)
    for (int k = 0; k < 3; ++k) {
      if (field.name == normalNames[k] && field.count == 1) ++normals;
      if (field.name == positionNames[k] && field.count == 1) ++positions;
    }
  if (positions != 3)
    throw FileError(file, lineWhere(header.dataLine),
                    "the fields must include x, y and z (COUNT 1)");
  if (normals == 3) builder.enableNormals();
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    const PcdField& field = header.fields[f];
    targets[f].resize(field.count);
    if (field.name == "_") continue;
    bool done = false;
    for (int k = 0; k < 3 && field.count == 1; ++k) {
      if (field.name == positionNames[k])
        targets[f][0] = {Target::Position, std::size_t(k)}, done = true;
      if (normals == 3 && field.name == normalNames[k])
        targets[f][0] = {Target::Normal, std::size_t(k)}, done = true;
    }
    if (done) continue;
    if ((field.name == "rgb" || field.name == "rgba") && field.count == 1 && field.size == 4) {
      targets[f][0] = {Target::PackedColour, builder.addColumn("red", ScalarType::UInt8)};
      builder.addColumn("green", ScalarType::UInt8);
      builder.addColumn("blue", ScalarType::UInt8);
      if (field.name == "rgba") builder.addColumn("alpha", ScalarType::UInt8);
      continue;
    }
    for (std::size_t c = 0; c < field.count; ++c)
      targets[f][c] = {
          Target::Column,
          builder.addColumn(field.count == 1 ? field.name : field.name + "_" + std::to_string(c),
                            field.scalar)};
  }
  std::vector<double> values(builder.columnCount());
  Vec3 position = Vec3::Zero(), normal = Vec3::Zero();
  auto store = [&](const Target& target, double value, std::uint32_t packed, bool rgba) {
    switch (target.kind) {
      case Target::Skip:
        break;
      case Target::Position:
        position[int(target.index)] = value;
        break;
      case Target::Normal:
        normal[int(target.index)] = value;
        break;
      case Target::Column:
        values[target.index] = value;
        break;
      case Target::PackedColour:
        // PCL packs colour as 0xAARRGGBB in a 32-bit word (stored as float or uint).
        values[target.index] = (packed >> 16) & 0xFF;
        values[target.index + 1] = (packed >> 8) & 0xFF;
        values[target.index + 2] = packed & 0xFF;
        if (rgba) values[target.index + 3] = (packed >> 24) & 0xFF;
        break;
    }
  };

  if (header.data == PcdData::Ascii) {
    LineScanner lines(data.substr(header.dataOffset));
    if (header.points > lines.remainingBytes() / 2 + 1)
      throw FileError(file, lineWhere(header.dataLine),
                      "the header declares " + std::to_string(header.points) + " points but only " +
                          std::to_string(lines.remainingBytes()) + " bytes follow",
                      "the file is truncated or POINTS is wrong");
    builder.reserve(header.points);
    std::size_t expected = 0;
    for (const auto& field : header.fields) expected += field.count;
    std::string_view line;
    std::vector<std::string_view> tokens;
    for (std::size_t i = 0; i < header.points; ++i) {
      do {
        if (!lines.next(line))
          throw FileError(file, lineWhere(header.dataLine + lines.lineNumber() + 1),
                          "unexpected end of file: " + std::to_string(header.points) +
                              " points declared, " + std::to_string(i) + " found",
                          "the file is truncated or POINTS is wrong");
        splitWhitespace(line, tokens);
      } while (tokens.empty());
      const std::size_t lineNumber = header.dataLine + lines.lineNumber();
      if (tokens.size() != expected)
        throw FileError(file, lineWhere(lineNumber),
                        "expected " + std::to_string(expected) + " values, found " +
                            std::to_string(tokens.size()));
      std::size_t t = 0;
      for (std::size_t f = 0; f < header.fields.size(); ++f) {
        const PcdField& field = header.fields[f];
        for (std::size_t c = 0; c < field.count; ++c, ++t) {
          const auto value = parseNumber(tokens[t]);
          if (!value || !fitsScalarType(*value, field.scalar))
            throw FileError(file, lineWhere(lineNumber),
                            quoted(tokens[t]) + " is not a valid " + scalarTypeName(field.scalar) +
                                " for field '" + field.name + "'");
          std::uint32_t packed = 0;
          if (targets[f][c].kind == Target::PackedColour) {
            if (field.type == 'F') {
              const float asFloat = float(*value);
              std::memcpy(&packed, &asFloat, 4);
            } else {
              packed = std::uint32_t(std::int64_t(*value));
            }
          }
          store(targets[f][c], toStoredValue(*value, field.scalar), packed, field.name == "rgba");
        }
      }
      builder.addPoint(position, normal, values.data(), [&] { return lineWhere(lineNumber); });
    }
    PointCloud cloud = builder.finish(report, "pcd (ascii)");
    cloud.setViewpoint(header.viewpoint);
    return cloud;
  }

  // Binary: records of pointSize bytes (point-major); binary_compressed: the LZF-compressed
  // data is field-major (all x, then all y, ...).
  std::size_t bytes = 0;
  if (!multiplyChecked(header.points, header.pointSize, bytes))
    throw FileError(file, lineWhere(header.dataLine), "POINTS * point size overflows");
  ByteReader in(data, file);
  in.seek(header.dataOffset, "the end of the header");
  std::string_view body;
  std::vector<unsigned char> decompressed;
  if (header.data == PcdData::Binary) {
    body = std::string_view(in.take(bytes, "the point data"), bytes);
  } else {
    const std::size_t compressedSize = in.read<std::uint32_t>("the compressed size");
    const std::size_t uncompressedSize = in.read<std::uint32_t>("the uncompressed size");
    const std::size_t at = in.offset();
    if (uncompressedSize != bytes)
      throw FileError(file, byteWhere(at - 4),
                      "uncompressed size " + std::to_string(uncompressedSize) +
                          " does not match POINTS * point size = " + std::to_string(bytes));
    const char* compressed = in.take(compressedSize, "the compressed point data");
    if (bytes / kLzfMaxRatio > compressedSize)
      throw FileError(file, byteWhere(at), "the compressed data is too small to hold the points",
                      "the file is corrupt");
    decompressed.resize(bytes);
    if (!lzfDecompress(reinterpret_cast<const unsigned char*>(compressed), compressedSize,
                       decompressed.data(), bytes))
      throw FileError(file, byteWhere(at), "corrupt LZF-compressed data",
                      "the file is damaged; re-export it as binary or ascii");
    body = std::string_view(reinterpret_cast<const char*>(decompressed.data()), bytes);
  }
  const bool fieldMajor = header.data == PcdData::BinaryCompressed;
  builder.reserve(header.points);
  for (std::size_t i = 0; i < header.points; ++i) {
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
      const PcdField& field = header.fields[f];
      for (std::size_t c = 0; c < field.count; ++c) {
        const std::size_t at =
            fieldMajor ? header.points * field.offset + (i * field.count + c) * field.size
                       : i * header.pointSize + field.offset + c * field.size;
        const char* p = body.data() + at;
        std::uint32_t packed = 0;
        if (field.size == 4) std::memcpy(&packed, p, 4);
        store(targets[f][c], decodeScalar(p, field.scalar, false), packed, field.name == "rgba");
      }
    }
    const std::size_t where = header.dataOffset + (fieldMajor ? 8 : i * header.pointSize);
    builder.addPoint(position, normal, values.data(), [&] { return byteWhere(where); });
  }
  PointCloud cloud =
      builder.finish(report, fieldMajor ? "pcd (binary_compressed)" : "pcd (binary)");
  cloud.setViewpoint(header.viewpoint);
  return cloud;
}

}  // namespace scalespace
