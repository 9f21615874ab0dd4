#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/LasFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WriteHelpers.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

class LittleEndianBuffer {
 public:
  explicit LittleEndianBuffer(std::size_t size) : bytes_(size, 0) {}
  template <class T>
  void put(std::size_t at, T value) {
    std::memcpy(bytes_.data() + at, &value, sizeof(T));  // x86/ARM hosts are little endian
  }
  void putText(std::size_t at, const std::string& text, std::size_t width) {
    std::memcpy(bytes_.data() + at, text.data(), std::min(width, text.size()));
  }
  char* at(std::size_t offset) { return bytes_.data() + offset; }
  void write(std::ostream& out) const { out.write(bytes_.data(), std::streamsize(bytes_.size())); }
  void clear() { std::fill(bytes_.begin(), bytes_.end(), 0); }

 private:
  std::vector<char> bytes_;
};

double columnValue(const AttributeColumn* column, std::size_t i, ScalarType type) {
  return column ? toStoredValue(column->values[i], type) : 0.0;
}

// Sizes of the LAS 1.4 structures the writer emits (LAS 1.4 R15): the public header block
// (Sec. 2.4), a VLR header (Sec. 2.5) and one Extra Bytes descriptor (Sec. 4.3).
constexpr std::size_t kHeader12Size = 227;
constexpr std::size_t kHeader14Size = 375;
constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::size_t kDescriptorSize = 192;
// The VLR's "record length after header" is an unsigned short.
constexpr std::size_t kMaxDescriptors = std::numeric_limits<std::uint16_t>::max() / kDescriptorSize;

/// The Extra Bytes data_type of each ScalarType (LAS 1.4 R15 Sec. 4.3, "Values for data_type").
std::uint8_t extraBytesDataType(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8:
      return 1;
    case ScalarType::Int8:
      return 2;
    case ScalarType::UInt16:
      return 3;
    case ScalarType::Int16:
      return 4;
    case ScalarType::UInt32:
      return 5;
    case ScalarType::Int32:
      return 6;
    case ScalarType::Float32:
      return 9;
    case ScalarType::Float64:
      return 10;
  }
  return 10;
}

const char* const kNormalNames[3] = {"nx", "ny", "nz"};

/// A value stored after the standard part of each point record as an "extra byte".
struct ExtraField {
  std::string name;
  ScalarType type;
  const AttributeColumn* column;  // null for the normal component `axis`
  int axis;
  double value(const PointCloud& cloud, std::size_t i) const {
    return column ? column->values[i] : cloud.normals()[i][axis];
  }
};

/// The normals (as float nx ny nz, as the PLY writer stores them) and every column that has no
/// field in the standard record: the colour triple only has one when it is complete, nir never in
/// formats 0-3. Throws when a name does not fit the descriptor's char[32] with its NUL.
std::vector<ExtraField> extraFields(const PointCloud& cloud, bool hasColour,
                                    const std::string& file) {
  std::vector<ExtraField> fields;
  if (cloud.hasNormals())
    for (int k = 0; k < 3; ++k)
      fields.push_back({kNormalNames[k], ScalarType::Float32, nullptr, k});
  for (const AttributeColumn& column : cloud.attributes()) {
    const std::string& name = column.name;
    const bool colour = name == "red" || name == "green" || name == "blue";
    if (name == "intensity" || name == "classification" || name == "return_number" ||
        name == "number_of_returns" || name == "gps_time" || (colour && hasColour))
      continue;
    if (name.size() > 31)
      throw FileError(file, "",
                      "attribute '" + name + "' has " + std::to_string(name.size()) +
                          " characters; a LAS extra bytes name holds at most 31",
                      "rename the attribute, or write PLY or PCD");
    fields.push_back({name, column.type, &column, 0});
  }
  if (fields.size() > kMaxDescriptors)
    throw FileError(file, "",
                    std::to_string(fields.size()) +
                        " columns need extra bytes; one LAS Extra "
                        "Bytes record describes at most " +
                        std::to_string(kMaxDescriptors),
                    "remove columns, or write PLY or PCD");
  return fields;
}

/// The Extra Bytes VLR (user "LASF_Spec", record 4) with one descriptor per field, in record
/// order (LAS 1.4 R15 Sec. 2.5 for the VLR header, Sec. 4.3 for the descriptors). Options stay 0:
/// no scale, offset, no_data, min or max, so readers take the stored values as they are.
void putExtraBytesVlr(LittleEndianBuffer& header, std::size_t at,
                      const std::vector<ExtraField>& fields) {
  header.putText(at + 2, "LASF_Spec", 16);
  header.put<std::uint16_t>(at + 18, 4);
  header.put<std::uint16_t>(at + 20, std::uint16_t(kDescriptorSize * fields.size()));
  header.putText(at + 22, "Extra Bytes", 32);
  for (std::size_t j = 0; j < fields.size(); ++j) {
    const std::size_t descriptor = at + kVlrHeaderSize + kDescriptorSize * j;
    header.put<std::uint8_t>(descriptor + 2, extraBytesDataType(fields[j].type));
    header.putText(descriptor + 4, fields[j].name, 31);  // the 32nd byte stays NUL
  }
}

}  // namespace

void writeLas(const PointCloud& cloud, std::ostream& out, const std::string& file) {
  static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559);
  // Names become descriptor names: no spaces or commas (the other writers' rule too), and no
  // nx/ny/nz beside the cloud's own normals (they would read back as the normals).
  checkAttributeNames(cloud, "LAS", {}, {"nx", "ny", "nz"});
  const AttributeColumn* intensity = cloud.findAttribute("intensity");
  const AttributeColumn* classification = cloud.findAttribute("classification");
  const AttributeColumn* returnNumber = cloud.findAttribute("return_number");
  const AttributeColumn* returnCount = cloud.findAttribute("number_of_returns");
  const AttributeColumn* time = cloud.findAttribute("gps_time");
  const AttributeColumn* colour[3] = {cloud.findAttribute("red"), cloud.findAttribute("green"),
                                      cloud.findAttribute("blue")};
  const bool hasColour = colour[0] && colour[1] && colour[2];
  const int format = hasColour ? (time ? 3 : 2) : (time ? 1 : 0);
  const std::size_t standardLength = format == 0 ? 20 : format == 1 ? 28 : format == 2 ? 26 : 34;
  const std::vector<ExtraField> extras = extraFields(cloud, hasColour, file);
  std::vector<std::size_t> extraAt;
  std::size_t recordLength = standardLength;
  for (const ExtraField& field : extras) {
    extraAt.push_back(recordLength);
    recordLength += scalarTypeSize(field.type);
  }

  // LAS 1.2 as before when the standard record holds everything; LAS 1.4 otherwise: it defines
  // the Extra Bytes VLR (R15 Sec. 4.3) that PDAL, LAStools and CloudCompare read, and 64-bit
  // point counts. Point formats 0-3 stay legal in 1.4 (R15 Sec. 2.6).
  constexpr std::uint64_t kMax32 = std::numeric_limits<std::uint32_t>::max();
  const bool las14 = !extras.empty() || cloud.size() > kMax32;
  const std::size_t headerSize = las14 ? kHeader14Size : kHeader12Size;
  const std::size_t pointOffset =
      headerSize + (extras.empty() ? 0 : kVlrHeaderSize + kDescriptorSize * extras.size());

  // Quantisation: 0.1 mm unless the extent around the origin needs a coarser step to fit int32.
  Vec3 lo, hi;
  cloud.bounds(lo, hi);
  if (!lo.allFinite() || !hi.allFinite())
    throw Error("writeLas: " + file + ": the cloud has non-finite coordinates");
  const double extent = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  double scale = 1e-4;
  while (extent / scale > 2.0e9) scale *= 10.0;

  // Points by return as the records store them (3 bits in formats 0-3, larger values clamped).
  std::uint64_t byReturn[15] = {};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r = returnNumber ? columnValue(returnNumber, i, ScalarType::UInt8) : 1.0;
    if (r >= 1) ++byReturn[int(std::min(7.0, r)) - 1];
  }

  // Public header block (R15 Sec. 2.4); the 1.2 header is its first 227 bytes.
  LittleEndianBuffer header(pointOffset);
  header.putText(0, "LASF", 4);
  header.put<std::uint8_t>(24, 1);
  header.put<std::uint8_t>(25, las14 ? 4 : 2);
  header.putText(26, "scalespace", 32);
  header.putText(58, "scalespace " SCALESPACE_VERSION, 32);
  header.put<std::uint16_t>(94, std::uint16_t(headerSize));
  header.put<std::uint32_t>(96, std::uint32_t(pointOffset));
  header.put<std::uint32_t>(100, extras.empty() ? 0 : 1);
  header.put<std::uint8_t>(104, std::uint8_t(format));
  header.put<std::uint16_t>(105, std::uint16_t(recordLength));
  // The legacy 32-bit counts are 0 when the total does not fit (R15 Sec. 2.4).
  const bool legacyFits = cloud.size() <= kMax32;
  header.put<std::uint32_t>(107, legacyFits ? std::uint32_t(cloud.size()) : 0);
  for (int r = 0; r < 5; ++r)
    header.put<std::uint32_t>(111 + 4 * std::size_t(r),
                              legacyFits ? std::uint32_t(byReturn[r]) : 0);
  for (int k = 0; k < 3; ++k) {
    header.put<double>(131 + 8 * std::size_t(k), scale);
    header.put<double>(155 + 8 * std::size_t(k), cloud.origin()[k]);
    header.put<double>(179 + 16 * std::size_t(k), cloud.size() ? hi[k] + cloud.origin()[k] : 0.0);
    header.put<double>(187 + 16 * std::size_t(k), cloud.size() ? lo[k] + cloud.origin()[k] : 0.0);
  }
  if (las14) {
    // 227: start of waveform data, 235: start of the first EVLR, 243: number of EVLRs, all 0.
    header.put<std::uint64_t>(247, cloud.size());
    for (int r = 0; r < 15; ++r) header.put<std::uint64_t>(255 + 8 * std::size_t(r), byReturn[r]);
  }
  if (!extras.empty()) putExtraBytesVlr(header, headerSize, extras);
  header.write(out);

  LittleEndianBuffer record(recordLength);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    record.clear();
    // Relative positions are exact offsets from the integer origin (the header's offset).
    for (int k = 0; k < 3; ++k)
      record.put<std::int32_t>(4 * std::size_t(k),
                               std::int32_t(std::llround(cloud.positions()[i][k] / scale)));
    record.put<std::uint16_t>(12, std::uint16_t(columnValue(intensity, i, ScalarType::UInt16)));
    // 3-bit return fields and the 5-bit class of formats 0-3: larger values are clamped.
    const int r = int(std::min(7.0, columnValue(returnNumber, i, ScalarType::UInt8)));
    const int n = int(std::min(7.0, columnValue(returnCount, i, ScalarType::UInt8)));
    record.put<std::uint8_t>(14, std::uint8_t(r | (n << 3)));
    record.put<std::uint8_t>(
        15, std::uint8_t(std::min(31.0, columnValue(classification, i, ScalarType::UInt8))));
    if (time) record.put<double>(20, time->values[i]);
    if (hasColour)
      for (std::size_t c = 0; c < 3; ++c)
        record.put<std::uint16_t>((format == 2 ? 20 : 28) + 2 * c,
                                  std::uint16_t(columnValue(colour[c], i, ScalarType::UInt16)));
    for (std::size_t j = 0; j < extras.size(); ++j)
      encodeScalar(toStoredValue(extras[j].value(cloud, i), extras[j].type), extras[j].type, false,
                   record.at(extraAt[j]));
    record.write(out);
  }
}

}  // namespace scalespace
