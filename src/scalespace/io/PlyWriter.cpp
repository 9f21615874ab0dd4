#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "scalespace/core/Error.hpp"
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

/// A column as written: its PLY type and a factor applied to its values.
struct PlyColumn {
  const AttributeColumn* column;
  ScalarType type;
  double factor;
};

/// The attribute columns as written. 16-bit red/green/blue (LAS colours) become 8-bit: viewers
/// (CloudCompare, MeshLab) read PLY colours as uchar and show ushort ones as black. Values that
/// already fit in 8 bits (LAS files written by 8-bit software) are kept; others are scaled by
/// 255/65535, which drops the low byte.
std::vector<PlyColumn> plyColumns(const PointCloud& cloud) {
  const AttributeColumn* rgb[3] = {cloud.findAttribute("red"), cloud.findAttribute("green"),
                                   cloud.findAttribute("blue")};
  bool sixteenBit = true, fitsInEightBits = true;
  for (const AttributeColumn* c : rgb) {
    sixteenBit = sixteenBit && c && c->type == ScalarType::UInt16;
    if (c)
      for (double v : c->values) fitsInEightBits = fitsInEightBits && v <= 255;
  }
  std::vector<PlyColumn> out;
  for (const AttributeColumn& column : cloud.attributes()) {
    const bool colour = sixteenBit && (&column == rgb[0] || &column == rgb[1] || &column == rgb[2]);
    out.push_back(
        colour ? PlyColumn{&column, ScalarType::UInt8, fitsInEightBits ? 1.0 : 255.0 / 65535.0}
               : PlyColumn{&column, column.type, 1.0});
  }
  return out;
}

/// The edge element's rows, after the vertices: two int32 per edge.
void writeEdges(const std::vector<PlyEdge>& edges, std::ostream& out, PlyEncoding encoding) {
  if (encoding == PlyEncoding::Ascii) {
    std::string line;
    for (const PlyEdge& e : edges) {
      line = std::to_string(e[0]);
      line += ' ';
      line += std::to_string(e[1]);
      line += '\n';
      out << line;
    }
    return;
  }
  const bool big = encoding == PlyEncoding::BinaryBigEndian;
  std::vector<char> rows(8 * std::min<std::size_t>(edges.size(), 4096));
  for (std::size_t first = 0; first < edges.size(); first += 4096) {
    const std::size_t count = std::min<std::size_t>(edges.size() - first, 4096);
    for (std::size_t k = 0; k < count; ++k)
      for (int end = 0; end < 2; ++end)
        encodeScalar(double(edges[first + k][std::size_t(end)]), ScalarType::Int32, big,
                     rows.data() + 8 * k + 4 * end);
    out.write(rows.data(), std::streamsize(8 * count));
  }
}

}  // namespace

void writePly(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding,
              const std::vector<PlyEdge>* edges) {
  checkAttributeNames(cloud, "PLY", {"x", "y", "z"}, {"nx", "ny", "nz"});
  if (edges) {
    // vertex1 and vertex2 are `int`, the type every viewer reads.
    if (cloud.size() > std::size_t(std::numeric_limits<std::int32_t>::max()))
      throw Error("cannot write edges to PLY: " + std::to_string(cloud.size()) +
                  " vertices do not fit the int vertex indices");
    for (const PlyEdge& e : *edges)
      if (e[0] >= cloud.size() || e[1] >= cloud.size())
        throw Error("cannot write an edge to vertex " + std::to_string(std::max(e[0], e[1])) +
                    ": there are " + std::to_string(cloud.size()) + " vertices");
  }
  const ScalarType positionType = positionTypeFor(cloud);
  const bool normals = cloud.hasNormals();
  const std::vector<PlyColumn> columns = plyColumns(cloud);

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
  for (const PlyColumn& c : columns)
    out << "property " << plyTypeName(c.type) << ' ' << c.column->name << '\n';
  if (edges)
    out << "element edge " << edges->size() << "\nproperty int vertex1\nproperty int vertex2\n";
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
      for (const PlyColumn& c : columns) {
        line += formatScalar(c.column->values[i] * c.factor, c.type);
        line += ' ';
      }
      line.back() = '\n';
      out << line;
    }
    if (edges) writeEdges(*edges, out, encoding);
    return;
  }

  const bool big = encoding == PlyEncoding::BinaryBigEndian;
  std::size_t rowSize = 3 * scalarTypeSize(positionType) + (normals ? 12 : 0);
  for (const PlyColumn& c : columns) rowSize += scalarTypeSize(c.type);
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
    for (const PlyColumn& c : columns) put(c.column->values[i] * c.factor, c.type);
    out.write(row.data(), std::streamsize(row.size()));
  }
  if (edges) writeEdges(*edges, out, encoding);
}

}  // namespace scalespace
