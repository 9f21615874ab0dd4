#include "scalespace/io/WriteHelpers.hpp"

#include "scalespace/core/Error.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace::io_detail {

ScalarType positionTypeFor(const PointCloud& cloud) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.absolutePosition(i);
    for (int k = 0; k < 3; ++k) {
      const double v = p[k];
      // Range check first: converting an out-of-range double to float is undefined behaviour.
      if (!(v >= -3.4e38 && v <= 3.4e38) || double(float(v)) != v) return ScalarType::Float64;
    }
  }
  return ScalarType::Float32;
}

void checkAttributeNames(const PointCloud& cloud, const char* format,
                         std::initializer_list<const char*> reserved,
                         std::initializer_list<const char*> normalNames, bool caseInsensitive) {
  auto same = [&](const std::string& name, const char* r) {
    return caseInsensitive ? toLower(name) == r : name == r;
  };
  for (const auto& column : cloud.attributes()) {
    bool bad = column.name.empty();
    for (char c : column.name)
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',') bad = true;
    for (const char* r : reserved)
      if (same(column.name, r)) bad = true;
    for (const char* r : normalNames)
      if (same(column.name, r)) bad = bad || cloud.hasNormals();
    if (bad)
      throw Error(std::string("cannot write attribute '") + column.name + "' to " + format +
                  ": names must be non-empty, without spaces or commas, and not a position or "
                  "normal name (rename the attribute)");
    if (column.values.size() != cloud.size())
      throw Error("attribute '" + column.name + "' has " + std::to_string(column.values.size()) +
                  " values for " + std::to_string(cloud.size()) + " points");
  }
  // A cloud without normals may carry nx ny nz as ordinary columns after other attributes (the
  // curvature output does: the fitted normal follows the input's attributes). Readers recognise
  // them by name, so they are read back as the cloud's normals.
}

}  // namespace scalespace::io_detail
