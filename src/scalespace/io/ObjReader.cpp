#include <limits>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/MeshCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

constexpr long kNoNormal = -1;
constexpr long kConflictingNormals = -2;

/// Resolves an OBJ index (1-based, or negative counting back from the last defined element).
bool resolveIndex(std::string_view token, std::size_t defined, std::size_t& index) {
  bool negative = false;
  if (!token.empty() && token.front() == '-') {
    negative = true;
    token.remove_prefix(1);
  }
  const auto value = parseUnsigned(token);
  if (!value || *value == 0 || *value > defined) return false;
  index = negative ? defined - std::size_t(*value) : std::size_t(*value) - 1;
  return true;
}

}  // namespace

TriangleMesh parseObj(std::string_view data, const std::string& file) {
  LineScanner lines(data);
  std::string_view line;
  std::vector<std::string_view> tokens;
  TriangleMesh mesh;
  std::vector<Vec3> fileNormals;
  std::vector<long> normalOf;  // per vertex: vn index, kNoNormal or kConflictingNormals
  bool facesReferenceNormals = false;
  std::vector<Index> polygon;
  while (lines.next(line)) {
    splitWhitespace(line, tokens);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    const std::string where = lineWhere(lines.lineNumber());
    const std::string_view keyword = tokens[0];
    if (keyword == "v" || keyword == "vn") {
      if (tokens.size() < 4)
        throw FileError(file, where, "expected '" + std::string(keyword) + " x y z'");
      double values[3];
      for (int k = 0; k < 3; ++k) {
        const auto value = parseNumber(tokens[std::size_t(k) + 1]);
        if (!value)
          throw FileError(file, where, quoted(tokens[std::size_t(k) + 1]) + " is not a number");
        values[k] = *value;
      }
      if (keyword == "v") {
        if (mesh.vertices.size() >= std::numeric_limits<Index>::max())
          throw FileError(file, where, "too many vertices");
        mesh.vertices.emplace_back(values[0], values[1], values[2]);
        mesh.vertexLines.push_back(lines.lineNumber());
        normalOf.push_back(kNoNormal);
      } else {
        fileNormals.emplace_back(values[0], values[1], values[2]);
      }
    } else if (keyword == "f") {
      if (tokens.size() < 4) throw FileError(file, where, "a face needs at least 3 vertices");
      polygon.clear();
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        // v, v/vt, v/vt/vn or v//vn
        const std::string_view corner = tokens[k];
        const std::size_t slash = corner.find('/');
        std::size_t vertex = 0;
        if (!resolveIndex(corner.substr(0, slash), mesh.vertices.size(), vertex))
          throw FileError(file, where,
                          "vertex reference " + quoted(corner) + " is not one of the " +
                              std::to_string(mesh.vertices.size()) + " vertices defined so far");
        polygon.push_back(Index(vertex));
        const std::size_t second =
            slash == std::string_view::npos ? std::string_view::npos : corner.find('/', slash + 1);
        if (second == std::string_view::npos) continue;
        std::size_t normal = 0;
        if (!resolveIndex(corner.substr(second + 1), fileNormals.size(), normal))
          throw FileError(file, where,
                          "normal reference in " + quoted(corner) + " is not one of the " +
                              std::to_string(fileNormals.size()) + " normals defined so far");
        facesReferenceNormals = true;
        long& current = normalOf[vertex];
        if (current == kNoNormal)
          current = long(normal);
        else if (current != long(normal))
          current = kConflictingNormals;
      }
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
        mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
    }
    // vt, o, g, s, usemtl, mtllib, l, p, ...: not needed for points.
  }
  if (facesReferenceNormals) {
    bool unique = true;
    for (long n : normalOf) unique = unique && n >= 0;
    if (unique) {
      mesh.normals.reserve(mesh.vertices.size());
      for (long n : normalOf) mesh.normals.push_back(fileNormals[std::size_t(n)]);
    }
  } else if (!fileNormals.empty() && fileNormals.size() == mesh.vertices.size()) {
    mesh.normals = std::move(fileNormals);
  }
  return mesh;
}

PointCloud readObj(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  return io_detail::meshToCloud(parseObj(data, file), file, options, report, "obj");
}

}  // namespace scalespace
