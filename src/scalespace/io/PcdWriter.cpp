#include <cstdio>
#include <vector>

#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/PcdFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WriteHelpers.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

const char* pcdType(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
    case ScalarType::Int16:
    case ScalarType::Int32:
      return "I";
    case ScalarType::UInt8:
    case ScalarType::UInt16:
    case ScalarType::UInt32:
      return "U";
    case ScalarType::Float32:
    case ScalarType::Float64:
      return "F";
  }
  return "F";
}

}  // namespace

void writePcd(const PointCloud& cloud, std::ostream& out, bool ascii) {
  // rgb/rgba would be read back as packed colour, "_" as padding.
  checkAttributeNames(cloud, "PCD", {"x", "y", "z", "rgb", "rgba", "_"},
                      {"normal_x", "normal_y", "normal_z"});
  const ScalarType positionType = positionTypeFor(cloud);
  const bool normals = cloud.hasNormals();
  std::vector<std::string> names = {"x", "y", "z"};
  std::vector<ScalarType> types(3, positionType);
  if (normals) {
    names.insert(names.end(), {"normal_x", "normal_y", "normal_z"});
    types.insert(types.end(), 3, ScalarType::Float32);
  }
  for (const auto& column : cloud.attributes()) {
    names.push_back(column.name);
    types.push_back(column.type);
  }
  out << "# .PCD v0.7 - Point Cloud Data file format (written by scalespace)\nVERSION 0.7\nFIELDS";
  for (const auto& n : names) out << ' ' << n;
  out << "\nSIZE";
  for (ScalarType t : types) out << ' ' << scalarTypeSize(t);
  out << "\nTYPE";
  for (ScalarType t : types) out << ' ' << pcdType(t);
  out << "\nCOUNT";
  for (std::size_t k = 0; k < types.size(); ++k) out << " 1";
  // The cloud's own viewpoint when it came with one, else PCL's default (the origin).
  const Vec3 viewpoint = cloud.viewpoint().value_or(Vec3::Zero());
  char position[96];
  std::snprintf(position, sizeof position, "%.17g %.17g %.17g", viewpoint.x(), viewpoint.y(),
                viewpoint.z());
  out << "\nWIDTH " << cloud.size() << "\nHEIGHT 1\nVIEWPOINT " << position << " 1 0 0 0\nPOINTS "
      << cloud.size() << "\nDATA " << (ascii ? "ascii" : "binary") << '\n';

  std::size_t rowSize = 0;
  for (ScalarType t : types) rowSize += scalarTypeSize(t);
  std::vector<char> row(rowSize);
  std::string line;
  std::vector<double> values(types.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.absolutePosition(i);
    std::size_t k = 0;
    for (int a = 0; a < 3; ++a) values[k++] = p[a];
    if (normals)
      for (int a = 0; a < 3; ++a) values[k++] = cloud.normals()[i][a];
    for (const auto& column : cloud.attributes()) values[k++] = column.values[i];
    if (ascii) {
      line.clear();
      for (std::size_t f = 0; f < types.size(); ++f) {
        line += formatScalar(values[f], types[f]);
        line += ' ';
      }
      line.back() = '\n';
      out << line;
    } else {
      char* at = row.data();
      for (std::size_t f = 0; f < types.size(); ++f) {
        encodeScalar(toStoredValue(values[f], types[f]), types[f], false, at);
        at += scalarTypeSize(types[f]);
      }
      out.write(row.data(), std::streamsize(row.size()));
    }
  }
}

}  // namespace scalespace
