#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/LasFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

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
  void write(std::ostream& out) const { out.write(bytes_.data(), std::streamsize(bytes_.size())); }
  void clear() { std::fill(bytes_.begin(), bytes_.end(), 0); }

 private:
  std::vector<char> bytes_;
};

double columnValue(const AttributeColumn* column, std::size_t i, ScalarType type) {
  return column ? toStoredValue(column->values[i], type) : 0.0;
}

}  // namespace

void writeLas(const PointCloud& cloud, std::ostream& out, const std::string& file) {
  static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559);
  if (cloud.size() > std::numeric_limits<std::uint32_t>::max())
    throw FileError(file, "", "LAS 1.2 holds at most 4294967295 points",
                    "split the cloud or write PLY");
  const AttributeColumn* intensity = cloud.findAttribute("intensity");
  const AttributeColumn* classification = cloud.findAttribute("classification");
  const AttributeColumn* returnNumber = cloud.findAttribute("return_number");
  const AttributeColumn* returnCount = cloud.findAttribute("number_of_returns");
  const AttributeColumn* time = cloud.findAttribute("gps_time");
  const AttributeColumn* colour[3] = {cloud.findAttribute("red"), cloud.findAttribute("green"),
                                      cloud.findAttribute("blue")};
  const bool hasColour = colour[0] && colour[1] && colour[2];
  const int format = hasColour ? (time ? 3 : 2) : (time ? 1 : 0);
  const std::size_t recordLength = format == 0 ? 20 : format == 1 ? 28 : format == 2 ? 26 : 34;

  // Quantisation: 0.1 mm unless the extent around the origin needs a coarser step to fit int32.
  Vec3 lo, hi;
  cloud.bounds(lo, hi);
  if (!lo.allFinite() || !hi.allFinite())
    throw Error("writeLas: " + file + ": the cloud has non-finite coordinates");
  const double extent = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  double scale = 1e-4;
  while (extent / scale > 2.0e9) scale *= 10.0;

  std::uint32_t byReturn[5] = {0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r = returnNumber ? columnValue(returnNumber, i, ScalarType::UInt8) : 1.0;
    if (r >= 1 && r <= 5) ++byReturn[int(r) - 1];
  }

  LittleEndianBuffer header(227);
  header.putText(0, "LASF", 4);
  header.put<std::uint8_t>(24, 1);
  header.put<std::uint8_t>(25, 2);
  header.putText(26, "scalespace", 32);
  header.putText(58, "scalespace " SCALESPACE_VERSION, 32);
  header.put<std::uint16_t>(94, 227);
  header.put<std::uint32_t>(96, 227);
  header.put<std::uint32_t>(100, 0);
  header.put<std::uint8_t>(104, std::uint8_t(format));
  header.put<std::uint16_t>(105, std::uint16_t(recordLength));
  header.put<std::uint32_t>(107, std::uint32_t(cloud.size()));
  for (int r = 0; r < 5; ++r) header.put<std::uint32_t>(111 + 4 * std::size_t(r), byReturn[r]);
  for (int k = 0; k < 3; ++k) {
    header.put<double>(131 + 8 * std::size_t(k), scale);
    header.put<double>(155 + 8 * std::size_t(k), cloud.origin()[k]);
    header.put<double>(179 + 16 * std::size_t(k), cloud.size() ? hi[k] + cloud.origin()[k] : 0.0);
    header.put<double>(187 + 16 * std::size_t(k), cloud.size() ? lo[k] + cloud.origin()[k] : 0.0);
  }
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
    record.write(out);
  }
}

}  // namespace scalespace
