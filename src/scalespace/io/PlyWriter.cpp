#include <vector>

#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WriteHelpers.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

/// PLY's canonical type names (read by every PLY tool; the int8.. aliases are not).
const char* plyTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return "char";
    case ScalarType::UInt8:
      return "uchar";
    case ScalarType::Int16:
      return "short";
    case ScalarType::UInt16:
      return "ushort";
    case ScalarType::Int32:
      return "int";
    case ScalarType::UInt32:
      return "uint";
    case ScalarType::Float32:
      return "float";
    case ScalarType::Float64:
      return "double";
  }
  return "double";
}

}  // namespace

void writePly(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding) {
  checkAttributeNames(cloud, "PLY", {"x", "y", "z"}, {"nx", "ny", "nz"});
  const ScalarType positionType = positionTypeFor(cloud);
  const bool normals = cloud.hasNormals();

  out << "ply\nformat "
      << (encoding == PlyEncoding::Ascii                ? "ascii"
          : encoding == PlyEncoding::BinaryLittleEndian ? "binary_little_endian"
                                                        : "binary_big_endian")
      << " 1.0\ncomment written by scalespace " SCALESPACE_VERSION "\n";
  out << "element vertex " << cloud.size() << '\n';
  for (const char* name : {"x", "y", "z"})
    out << "property " << plyTypeName(positionType) << ' ' << name << '\n';
  if (normals)
    for (const char* name : {"nx", "ny", "nz"}) out << "property float " << name << '\n';
  for (const auto& column : cloud.attributes())
    out << "property " << plyTypeName(column.type) << ' ' << column.name << '\n';
  out << "end_header\n";

  if (encoding == PlyEncoding::Ascii) {
    std::string line;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      line.clear();
      const Vec3 p = cloud.absolutePosition(i);
      for (int k = 0; k < 3; ++k) {
        line += formatScalar(p[k], positionType);
        line += ' ';
      }
      if (normals)
        for (int k = 0; k < 3; ++k) {
          line += formatScalar(cloud.normals()[i][k], ScalarType::Float32);
          line += ' ';
        }
      for (const auto& column : cloud.attributes()) {
        line += formatScalar(column.values[i], column.type);
        line += ' ';
      }
      line.back() = '\n';
      out << line;
    }
    return;
  }

  const bool big = encoding == PlyEncoding::BinaryBigEndian;
  std::size_t rowSize = 3 * scalarTypeSize(positionType) + (normals ? 12 : 0);
  for (const auto& column : cloud.attributes()) rowSize += scalarTypeSize(column.type);
  std::vector<char> row(rowSize);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    char* at = row.data();
    auto put = [&](double value, ScalarType type) {
      encodeScalar(toStoredValue(value, type), type, big, at);
      at += scalarTypeSize(type);
    };
    const Vec3 p = cloud.absolutePosition(i);
    for (int k = 0; k < 3; ++k) put(p[k], positionType);
    if (normals)
      for (int k = 0; k < 3; ++k) put(cloud.normals()[i][k], ScalarType::Float32);
    for (const auto& column : cloud.attributes()) put(column.values[i], column.type);
    out.write(row.data(), std::streamsize(row.size()));
  }
}

}  // namespace scalespace
