#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/LasFormat.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

/// Minimum record length of each supported point data format (LAS 1.4 R15, Tables 7-15).
std::size_t lasRecordSize(int format) {
  switch (format) {
    case 0:
      return 20;
    case 1:
      return 28;
    case 2:
      return 26;
    case 3:
      return 34;
    case 6:
      return 30;
    case 7:
      return 36;
    case 8:
      return 38;
    default:
      return 0;
  }
}

// LAS 1.4 R15: a VLR header is 54 bytes (Sec. 2.5), an Extra Bytes descriptor 192 (Sec. 4.3).
constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::size_t kDescriptorSize = 192;

const char* const kNormalNames[3] = {"nx", "ny", "nz"};

/// One documented scalar of the extra bytes (data types 1-10) and where its value goes.
struct ExtraBytesField {
  std::string name;
  std::size_t descriptor = 0;  // index in the VLR
  std::size_t at = 0;          // offset inside the point record
  int dataType = 0;
  ScalarType stored = ScalarType::Float64;  // on file, for data types other than 7 and 8
  ScalarType type = ScalarType::Float64;    // of the column: Float64 when scaled or 64-bit
  double scale = 1.0, offset = 0.0;
  bool scaled = false;
  int normalAxis = -1;  // 0-2 for nx ny nz when they become the cloud's normals
  std::size_t column = 0;
};

struct ExtraBytesLayout {
  std::vector<ExtraBytesField> fields;
  std::size_t skipped = 0;  // descriptors of type 0, 11-30 (deprecated arrays) or 31-255
};

struct ExtraBytesScalar {
  std::size_t size;
  ScalarType type;
};

/// Size on file and column type of the scalar data types 1-10 (R15 Sec. 4.3, "Values for
/// data_type"); 64-bit integers (7, 8) have no ScalarType and are held as float64.
ExtraBytesScalar extraBytesScalar(int dataType) {
  static const ExtraBytesScalar kTypes[] = {{1, ScalarType::UInt8},   {1, ScalarType::Int8},
                                            {2, ScalarType::UInt16},  {2, ScalarType::Int16},
                                            {4, ScalarType::UInt32},  {4, ScalarType::Int32},
                                            {8, ScalarType::Float64}, {8, ScalarType::Float64},
                                            {4, ScalarType::Float32}, {8, ScalarType::Float64}};
  return kTypes[dataType - 1];
}

double decodeExtraBytes(const char* bytes, const ExtraBytesField& field) {
  double raw;
  if (field.dataType == 7 || field.dataType == 8) {
    std::uint64_t bits;
    std::memcpy(&bits, bytes, 8);
    raw = field.dataType == 7 ? double(bits) : double(std::int64_t(bits));
  } else {
    raw = decodeScalar(bytes, field.stored, false);
  }
  return field.scaled ? raw * field.scale + field.offset : raw;
}

struct VlrPayload {
  std::string_view bytes;
  std::size_t at = 0;  // byte offset in the file
};

/// The payload of the first Extra Bytes VLR (user "LASF_Spec", record 4); empty when none.
/// VLRs are walked in sequence (R15 Sec. 2.5) between the header and the point data; one that
/// runs past the offset to point data means the header's VLR count or a record length is wrong.
VlrPayload findExtraBytesVlr(std::string_view data, const std::string& file, std::size_t headerSize,
                             std::size_t pointOffset, std::uint32_t vlrCount) {
  ByteReader in(data.substr(0, pointOffset), file);
  in.seek(headerSize, "the first VLR");
  VlrPayload found;  // at == 0 until found (a payload follows the header)
  for (std::uint32_t v = 0; v < vlrCount; ++v) {
    const std::size_t start = in.offset();
    auto overrun = [&](const std::string& what) {
      return FileError(file, byteWhere(start),
                       "VLR " + std::to_string(v + 1) + " of " + std::to_string(vlrCount) + "'s " +
                           what + " runs past the offset to point data (" +
                           std::to_string(pointOffset) + ")",
                       "the header's number of VLRs or a VLR's record length is wrong");
    };
    if (in.remaining() < kVlrHeaderSize) throw overrun("54-byte header");
    in.skip(2, "a VLR's reserved field");
    const std::string_view user(in.take(16, "a VLR's user id"), 16);
    const std::uint16_t record = in.read<std::uint16_t>("a VLR's record id");
    const std::size_t length = in.read<std::uint16_t>("a VLR's record length");
    in.skip(32, "a VLR's description");
    if (length > in.remaining()) throw overrun("payload of " + std::to_string(length) + " bytes");
    const char* body = in.take(length, "a VLR's payload");
    if (found.at == 0 && user.substr(0, user.find('\0')) == "LASF_Spec" && record == 4)
      found = {std::string_view(body, length), start + kVlrHeaderSize};
  }
  return found;
}

/// Parses the descriptors (R15 Sec. 4.3) against the extra bytes of each record, which start at
/// `standardLength`. Every descriptor advances the position by its size, so undocumented (type
/// 0, size in `options`) and deprecated array (11-30) bytes are skipped without shifting the
/// fields after them; a reserved type (31-255) has no known size, so it and the descriptors after
/// it are skipped. Descriptors that need more bytes than the record holds make the VLR invalid
/// (the spec's "extra bytes mismatch"): FileError.
ExtraBytesLayout parseExtraBytes(const VlrPayload& vlr, std::size_t standardLength,
                                 std::size_t recordLength, const std::string& file) {
  ExtraBytesLayout layout;
  if (vlr.bytes.size() % kDescriptorSize != 0)
    throw FileError(file, byteWhere(vlr.at),
                    "the Extra Bytes VLR holds " + std::to_string(vlr.bytes.size()) +
                        " bytes, not a whole number of 192-byte descriptors");
  const std::size_t count = vlr.bytes.size() / kDescriptorSize;
  std::size_t at = standardLength;
  for (std::size_t j = 0; j < count; ++j) {
    ByteReader in(vlr.bytes.substr(j * kDescriptorSize, kDescriptorSize), file);
    in.skip(2, "a descriptor's reserved field");
    const int dataType = in.read<std::uint8_t>("a descriptor's data type");
    const int options = in.read<std::uint8_t>("a descriptor's options");
    const std::string_view rawName(in.take(32, "a descriptor's name"), 32);
    ExtraBytesField field;
    field.name = std::string(rawName.substr(0, rawName.find('\0')));
    field.descriptor = j;
    field.dataType = dataType;
    std::size_t size;
    if (dataType == 0) {
      size = std::size_t(options);
    } else if (dataType <= 10) {
      size = extraBytesScalar(dataType).size;
      field.stored = field.type = extraBytesScalar(dataType).type;
    } else if (dataType <= 30) {
      // Deprecated arrays: 11-20 two, 21-30 three values of data type (t - 11) % 10 + 1.
      size = extraBytesScalar((dataType - 11) % 10 + 1).size * (dataType <= 20 ? 2 : 3);
    } else {
      layout.skipped += count - j;
      break;
    }
    if (size > recordLength - at)
      throw FileError(file, byteWhere(vlr.at + j * kDescriptorSize),
                      "Extra Bytes descriptor " + std::to_string(j + 1) + " ('" + field.name +
                          "') needs bytes " + std::to_string(at) + "-" +
                          std::to_string(at + size - 1) + " of a point record that is " +
                          std::to_string(recordLength) + " bytes long",
                      "the Extra Bytes VLR does not match the point record length");
    field.at = at;
    at += size;
    if (dataType == 0 || dataType > 10) {
      ++layout.skipped;
      continue;
    }
    // Bits 3 and 4 of `options`: multiply by `scale`, then add `offset` (fields at 112 and 136).
    if (options & 0x18) {
      in.seek(112, "a descriptor's scale");
      const double scale = in.read<double>("a descriptor's scale");
      in.seek(136, "a descriptor's offset");
      const double offset = in.read<double>("a descriptor's offset");
      field.scaled = true;
      field.scale = options & 0x08 ? scale : 1.0;
      field.offset = options & 0x10 ? offset : 0.0;
      field.type = ScalarType::Float64;
    }
    layout.fields.push_back(std::move(field));
  }
  return layout;
}

/// A descriptor name as a column name: bytes that are not printable ASCII, spaces and commas
/// become '_' (every writer rejects them), an empty name becomes extra_bytes_N, and a name already
/// taken (by a standard attribute, the normals or an earlier field) gets _2, _3, ...
std::string columnName(const std::string& raw, std::size_t index, std::vector<std::string>& taken) {
  std::string name = raw.empty() ? "extra_bytes_" + std::to_string(index + 1) : raw;
  for (char& c : name)
    if (std::uint8_t(c) <= ' ' || std::uint8_t(c) > '~' || c == ',') c = '_';
  std::string unique = name;
  for (int k = 2; std::find(taken.begin(), taken.end(), unique) != taken.end(); ++k)
    unique = name + "_" + std::to_string(k);
  taken.push_back(unique);
  return unique;
}

/// Declares the extra bytes' columns after the standard ones (`taken`). Float fields named nx ny
/// nz (the first float field of each name, all three needed) become the normals, as in PLY.
void addExtraColumns(ExtraBytesLayout& extras, CloudBuilder& builder,
                     std::vector<std::string>& taken) {
  ExtraBytesField* normal[3] = {nullptr, nullptr, nullptr};
  for (ExtraBytesField& field : extras.fields)
    for (int k = 0; k < 3; ++k)
      if (!normal[k] && field.name == kNormalNames[k] && !isIntegerType(field.type))
        normal[k] = &field;
  if (normal[0] && normal[1] && normal[2]) {
    builder.enableNormals();
    for (int k = 0; k < 3; ++k) {
      normal[k]->normalAxis = k;
      taken.push_back(normal[k]->name);
    }
  }
  for (ExtraBytesField& field : extras.fields)
    if (field.normalAxis < 0)
      field.column = builder.addColumn(columnName(field.name, field.descriptor, taken), field.type);
}

const char* const kLazFix =
    "decompress it first, e.g. `laszip -i in.laz -o out.las` or `pdal translate in.laz out.las`";

}  // namespace

PointCloud readLas(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  ByteReader in(data, file);
  if (data.size() < 4 || data.substr(0, 4) != "LASF")
    throw FileError(file, "byte 0", "expected the LAS signature 'LASF'",
                    "not a LAS file: check the file extension");
  in.seek(24, "the version");
  const int major = in.read<std::uint8_t>("the version");
  const int minor = in.read<std::uint8_t>("the version");
  if (major != 1 || minor > 4)
    throw FileError(
        file, "byte 24",
        "unsupported LAS version " + std::to_string(major) + "." + std::to_string(minor),
        "versions 1.0 to 1.4 are supported");
  in.seek(94, "the header size");
  const std::size_t headerSize = in.read<std::uint16_t>("the header size");
  const std::size_t pointOffset = in.read<std::uint32_t>("the offset to point data");
  const std::uint32_t vlrCount = in.read<std::uint32_t>("the number of VLRs");
  const int formatByte = in.read<std::uint8_t>("the point data format");
  const std::size_t recordLength = in.read<std::uint16_t>("the point record length");
  const std::uint64_t legacyCount = in.read<std::uint32_t>("the number of points");

  // Bits 7 and 6 of the format byte mark LASzip-compressed points.
  if (formatByte & 0xC0)
    throw FileError(file, "byte 104",
                    "the points are LAZ-compressed, which is not supported "
                    "(no LAZ library is packaged in Debian)",
                    kLazFix);
  const int format = formatByte;
  if (lasRecordSize(format) == 0)
    throw FileError(file, "byte 104", "unsupported point data format " + std::to_string(format),
                    "formats 0-3 and 6-8 are supported (4, 5, 9 and 10 carry waveforms); convert "
                    "with `pdal translate in.las out.las --writers.las.dataformat_id=3`");
  if (format >= 6 && minor < 4)
    throw FileError(file, "byte 104",
                    "point data format " + std::to_string(format) +
                        " needs LAS 1.4, the header "
                        "says 1." +
                        std::to_string(minor));
  const std::size_t minimumHeader = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
  if (headerSize < minimumHeader || headerSize > data.size())
    throw FileError(file, "byte 94",
                    "header size " + std::to_string(headerSize) + " is not valid for LAS 1." +
                        std::to_string(minor) + " (at least " + std::to_string(minimumHeader) +
                        " bytes, within the file's " + std::to_string(data.size()) + ")",
                    "the file is truncated or not a LAS file");
  if (pointOffset < headerSize || pointOffset > data.size())
    throw FileError(file, "byte 96",
                    "offset to point data " + std::to_string(pointOffset) +
                        " is outside [header size " + std::to_string(headerSize) + ", file size " +
                        std::to_string(data.size()) + "]",
                    "the file is truncated or its header is corrupt");
  if (recordLength < lasRecordSize(format))
    throw FileError(file, "byte 105",
                    "point record length " + std::to_string(recordLength) +
                        " is shorter than format " + std::to_string(format) + "'s " +
                        std::to_string(lasRecordSize(format)) + " bytes");

  in.seek(131, "the scale factors");
  double scale[3], offset[3];
  for (double& s : scale) s = in.read<double>("a scale factor");
  for (double& o : offset) o = in.read<double>("an offset");
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(scale[k]) || scale[k] == 0 || !std::isfinite(offset[k]))
      throw FileError(file, byteWhere(131 + 8 * std::size_t(k)),
                      "scale factors must be finite and non-zero and offsets finite");

  std::uint64_t count = legacyCount;
  if (minor >= 4) {
    in.seek(247, "the 64-bit number of points");
    const std::uint64_t count64 = in.read<std::uint64_t>("the 64-bit number of points");
    if (legacyCount != 0 && count64 != legacyCount)
      throw FileError(file, "byte 247",
                      "the legacy point count " + std::to_string(legacyCount) +
                          " and the 64-bit count " + std::to_string(count64) + " disagree");
    count = count64;
  }
  const std::size_t available = (data.size() - pointOffset) / recordLength;
  if (count > available)
    throw FileError(file, "byte 107",
                    "the header declares " + std::to_string(count) + " points of " +
                        std::to_string(recordLength) + " bytes but the file holds only " +
                        std::to_string(available),
                    "the file is truncated or its point count is wrong");

  ExtraBytesLayout extras =
      parseExtraBytes(findExtraBytesVlr(data, file, headerSize, pointOffset, vlrCount),
                      lasRecordSize(format), recordLength, file);

  CloudBuilder builder(file, options);
  std::vector<std::string> taken;  // column names, for the extra bytes' names to avoid
  auto addStandard = [&](const char* name, ScalarType type) {
    taken.push_back(name);
    return builder.addColumn(name, type);
  };
  const bool hasTime = format == 1 || format == 3 || format >= 6;
  const bool hasColour = format == 2 || format == 3 || format == 7 || format == 8;
  const std::size_t intensity = addStandard("intensity", ScalarType::UInt16);
  const std::size_t classification = addStandard("classification", ScalarType::UInt8);
  const std::size_t returnNumber = addStandard("return_number", ScalarType::UInt8);
  const std::size_t returnCount = addStandard("number_of_returns", ScalarType::UInt8);
  const std::size_t time = hasTime ? addStandard("gps_time", ScalarType::Float64) : 0;
  const std::size_t red = hasColour ? addStandard("red", ScalarType::UInt16) : 0;
  if (hasColour) {
    addStandard("green", ScalarType::UInt16);
    addStandard("blue", ScalarType::UInt16);
  }
  const std::size_t nir = format == 8 ? addStandard("nir", ScalarType::UInt16) : 0;
  addExtraColumns(extras, builder, taken);
  builder.reserve(std::size_t(count));
  std::vector<double> values(builder.columnCount());

  // Offsets of the fields inside a record (Tables 7-15): the legacy formats 0-5 put the flags
  // at 14 and classification at 15, the 1.4 formats 6-10 widen the flags to two bytes.
  const std::size_t timeAt = format >= 6 ? 22 : 20;
  const std::size_t colourAt = format >= 6 ? 30 : format == 2 ? 20 : 28;
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t start = pointOffset + i * recordLength;
    in.seek(start, "a point record");
    ByteReader record(data.substr(start, recordLength), file);
    Vec3 position;
    for (int k = 0; k < 3; ++k)
      position[k] = double(record.read<std::int32_t>("a coordinate")) * scale[k] + offset[k];
    values[intensity] = record.read<std::uint16_t>("intensity");
    const std::uint8_t flags = record.read<std::uint8_t>("return flags");
    if (format < 6) {
      values[returnNumber] = flags & 0x07;
      values[returnCount] = (flags >> 3) & 0x07;
      values[classification] = record.read<std::uint8_t>("classification") & 0x1F;
    } else {
      values[returnNumber] = flags & 0x0F;
      values[returnCount] = (flags >> 4) & 0x0F;
      record.skip(1, "classification flags");
      values[classification] = record.read<std::uint8_t>("classification");
    }
    if (hasTime) {
      record.seek(timeAt, "gps time");
      values[time] = record.read<double>("gps time");
    }
    if (hasColour) {
      record.seek(colourAt, "colour");
      for (std::size_t c = 0; c < 3; ++c) values[red + c] = record.read<std::uint16_t>("colour");
      if (format == 8) values[nir] = record.read<std::uint16_t>("nir");
    }
    Vec3 normalValue = Vec3::Zero();
    for (const ExtraBytesField& field : extras.fields) {
      const double value = decodeExtraBytes(data.data() + start + field.at, field);
      if (field.normalAxis >= 0)
        normalValue[field.normalAxis] = value;
      else
        values[field.column] = value;
    }
    builder.addPoint(position, normalValue, values.data(), [&] { return byteWhere(start); });
  }
  std::string description = "las 1." + std::to_string(minor) + " format " + std::to_string(format);
  if (extras.skipped > 0)
    description += ", " + std::to_string(extras.skipped) +
                   " extra bytes fields skipped (undocumented, deprecated array or reserved type)";
  return builder.finish(report, description);
}

}  // namespace scalespace
