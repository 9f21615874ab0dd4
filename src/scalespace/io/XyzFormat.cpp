#include "scalespace/io/XyzFormat.hpp"

#include <array>
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WriteHelpers.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

void splitFields(std::string_view line, std::vector<std::string_view>& fields) {
  if (line.find(',') != std::string_view::npos)
    splitOn(line, ',', fields);
  else
    splitWhitespace(line, fields);
}

bool isComment(std::string_view line) {
  line = trim(line);
  return line.empty() || line.front() == '#';
}

/// Column roles: 0..2 position, 3..5 normal, -1 attribute.
struct XyzLayout {
  std::vector<int> role;
  std::vector<std::string> names;  // attribute names, in column order
};

XyzLayout layoutFromHeader(const std::vector<std::string_view>& fields, const std::string& file,
                           std::size_t line) {
  static const std::array<std::array<const char*, 2>, 6> known = {{{"x", ""},
                                                                   {"y", ""},
                                                                   {"z", ""},
                                                                   {"nx", "normal_x"},
                                                                   {"ny", "normal_y"},
                                                                   {"nz", "normal_z"}}};
  XyzLayout layout;
  std::array<int, 6> seen{-1, -1, -1, -1, -1, -1};
  for (std::size_t c = 0; c < fields.size(); ++c) {
    std::string_view raw = fields[c];
    if (c == 0 && raw.substr(0, 2) == "//") raw.remove_prefix(2);
    const std::string name = toLower(trim(raw));
    if (name.empty())
      throw FileError(file, lineWhere(line),
                      "header column " + std::to_string(c + 1) + " has no name");
    int role = -1;
    for (int k = 0; k < 6; ++k)
      if (name == known[k][0] || (known[k][1][0] && name == known[k][1])) role = k;
    if (role >= 0) {
      if (seen[role] >= 0)
        throw FileError(file, lineWhere(line), "header names column '" + name + "' twice");
      seen[role] = int(c);
    }
    layout.role.push_back(role);
    std::string kept(trim(raw));
    for (char& ch : kept)
      if (isSpace(ch)) ch = '_';  // "Scalar field" -> "Scalar_field": names stay writable
    layout.names.push_back(kept);
  }
  for (int k = 0; k < 3; ++k)
    if (seen[k] < 0)
      throw FileError(file, lineWhere(line),
                      std::string("the header line names no '") + known[k][0] + "' column",
                      "the first line is read as a header because it holds non-numbers; name the "
                      "columns x y z ... or remove it");
  if (seen[3] < 0 || seen[4] < 0 || seen[5] < 0)  // partial normals stay attributes
    for (int k = 3; k < 6; ++k)
      if (seen[k] >= 0) layout.role[std::size_t(seen[k])] = -1;
  return layout;
}

XyzLayout layoutFromCount(std::size_t count) {
  XyzLayout layout;
  for (std::size_t c = 0; c < count; ++c) {
    const bool normal = count == 6 && c >= 3;
    layout.role.push_back(c < 3 ? int(c) : normal ? int(c) : -1);
    layout.names.push_back(c < 3 || normal ? "" : "scalar_" + std::to_string(c - 2));
  }
  return layout;
}

}  // namespace

PointCloud readXyz(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  LineScanner lines(data);
  std::string_view line;
  std::vector<std::string_view> fields;
  CloudBuilder builder(file, options);
  XyzLayout layout;
  std::vector<double> values;
  bool started = false;
  while (lines.next(line)) {
    if (isComment(line)) continue;
    const std::size_t lineNumber = lines.lineNumber();
    splitFields(line, fields);
    if (!started) {
      // Leica PTS files start with a line holding only the point count: skip it.
      if (fields.size() == 1 && parseUnsigned(fields[0])) continue;
      started = true;
      bool header = false;
      for (auto f : fields) header = header || (!f.empty() && !parseNumber(f));
      layout = header ? layoutFromHeader(fields, file, lineNumber) : layoutFromCount(fields.size());
      if (layout.role.size() < 3)
        throw FileError(
            file, lineWhere(lineNumber),
            "expected at least 3 columns (x y z), found " + std::to_string(layout.role.size()));
      bool normals = false;
      for (std::size_t c = 0; c < layout.role.size(); ++c) {
        if (layout.role[c] >= 3) normals = true;
        if (layout.role[c] < 0) builder.addColumn(layout.names[c], ScalarType::Float64);
      }
      if (normals) builder.enableNormals();
      values.resize(builder.columnCount());
      if (header) continue;
    }
    if (fields.size() != layout.role.size())
      throw FileError(file, lineWhere(lineNumber),
                      "expected " + std::to_string(layout.role.size()) + " fields, found " +
                          std::to_string(fields.size()),
                      "every line must have as many fields as the first one");
    Vec3 position = Vec3::Zero(), normal = Vec3::Zero();
    std::size_t column = 0;
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const auto value = parseNumber(fields[c]);
      if (!value)
        throw FileError(
            file, lineWhere(lineNumber),
            "field " + std::to_string(c + 1) + " " + quoted(fields[c]) + " is not a number");
      const int role = layout.role[c];
      if (role < 0)
        values[column++] = *value;
      else if (role < 3)
        position[role] = *value;
      else
        normal[role - 3] = *value;
    }
    builder.addPoint(position, normal, values.data(), [&] { return lineWhere(lineNumber); });
  }
  return builder.finish(report, "xyz");
}

namespace {

/// One line per point: x y z, the normals if the cloud has them, then (withAttributes) every
/// attribute column, shortest round-trip numbers.
void writeRows(const PointCloud& cloud, std::ostream& out, char separator, bool withAttributes) {
  const bool normals = cloud.hasNormals();
  std::string line;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    line.clear();
    const Vec3 p = cloud.absolutePosition(i);
    for (int k = 0; k < 3; ++k) {
      line += formatNumber(p[k]);
      line += separator;
    }
    if (normals)
      for (int k = 0; k < 3; ++k) {
        line += formatNumber(cloud.normals()[i][k]);
        line += separator;
      }
    if (withAttributes)
      for (const auto& column : cloud.attributes()) {
        // Text keeps no type: write the stored value with all its double digits, so it reads
        // back (as float64) to exactly the same number.
        line += formatNumber(toStoredValue(column.values[i], column.type));
        line += separator;
      }
    line.back() = '\n';
    out << line;
  }
}

}  // namespace

void checkPwnWritable(const PointCloud& cloud) {
  if (!cloud.hasNormals())
    throw OptionError(
        "a .pwn file holds points with normals and this cloud has none: estimate them first "
        "(`scalespace normals`) or write .xyz");
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (!cloud.normals()[i].allFinite())
      throw OptionError("the normal of point " + std::to_string(i) +
                        " is NaN or infinite, which a .pwn cannot hold (its readers take such a "
                        "line for garbage): re-estimate the normals or write .ply");
}

void writeXyz(const PointCloud& cloud, std::ostream& out, char separator) {
  checkAttributeNames(cloud, "XYZ", {"x", "y", "z"},
                      {"nx", "ny", "nz", "normal_x", "normal_y", "normal_z"},
                      /*caseInsensitive=*/true);
  const bool normals = cloud.hasNormals();
  std::string line = "x";
  line += separator;
  line += 'y';
  line += separator;
  line += 'z';
  if (normals) {
    for (const char* n : {"nx", "ny", "nz"}) {
      line += separator;
      line += n;
    }
  }
  for (const auto& column : cloud.attributes()) {
    line += separator;
    line += column.name;
  }
  out << line << '\n';
  writeRows(cloud, out, separator, /*withAttributes=*/true);
}

void writePwn(const PointCloud& cloud, std::ostream& out) {
  checkPwnWritable(cloud);
  writeRows(cloud, out, ' ', /*withAttributes=*/false);
}

}  // namespace scalespace
