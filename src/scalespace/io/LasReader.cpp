#include <cmath>

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
  in.skip(4, "the number of VLRs");
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

  CloudBuilder builder(file, options);
  const bool hasTime = format == 1 || format == 3 || format >= 6;
  const bool hasColour = format == 2 || format == 3 || format == 7 || format == 8;
  const std::size_t intensity = builder.addColumn("intensity", ScalarType::UInt16);
  const std::size_t classification = builder.addColumn("classification", ScalarType::UInt8);
  const std::size_t returnNumber = builder.addColumn("return_number", ScalarType::UInt8);
  const std::size_t returnCount = builder.addColumn("number_of_returns", ScalarType::UInt8);
  const std::size_t time = hasTime ? builder.addColumn("gps_time", ScalarType::Float64) : 0;
  const std::size_t red = hasColour ? builder.addColumn("red", ScalarType::UInt16) : 0;
  if (hasColour) {
    builder.addColumn("green", ScalarType::UInt16);
    builder.addColumn("blue", ScalarType::UInt16);
  }
  const std::size_t nir = format == 8 ? builder.addColumn("nir", ScalarType::UInt16) : 0;
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
    builder.addPoint(position, Vec3::Zero(), values.data(), [&] { return byteWhere(start); });
  }
  return builder.finish(report,
                        "las 1." + std::to_string(minor) + " format " + std::to_string(format));
}

}  // namespace scalespace
