#include <limits>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/MeshCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

/// Next line holding data (comments after '#' removed), split into tokens; false at the end.
bool nextDataLine(LineScanner& lines, std::vector<std::string_view>& tokens) {
  std::string_view line;
  while (lines.next(line)) {
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    splitWhitespace(line, tokens);
    if (!tokens.empty()) return true;
  }
  return false;
}

}  // namespace

TriangleMesh parseOff(std::string_view data, const std::string& file) {
  LineScanner lines(data);
  std::vector<std::string_view> tokens;
  if (!nextDataLine(lines, tokens))
    throw FileError(file, "line 1", "empty file: expected the OFF header", "not an OFF file");
  const std::string_view keyword = tokens[0];
  if (keyword != "OFF" && keyword != "NOFF" && keyword != "COFF" && keyword != "CNOFF")
    throw FileError(file, lineWhere(lines.lineNumber()),
                    "expected the header OFF, NOFF, COFF or CNOFF, found " + quoted(keyword),
                    "not an OFF file: check the file extension");
  const bool withNormals = keyword == "NOFF" || keyword == "CNOFF";
  tokens.erase(tokens.begin());
  if (tokens.empty() && !nextDataLine(lines, tokens))
    throw FileError(file, lineWhere(lines.lineNumber()), "missing the vertex and face counts");
  const auto vertexCount = tokens.size() >= 2 ? parseUnsigned(tokens[0]) : std::nullopt;
  const auto faceCount = tokens.size() >= 2 ? parseUnsigned(tokens[1]) : std::nullopt;
  if (!vertexCount || !faceCount)
    throw FileError(file, lineWhere(lines.lineNumber()),
                    "expected '<vertex count> <face count> [edge count]'");
  // Every vertex and face is a line of at least 6 bytes ("0 0 0\n", "3 0 1 2\n" is longer).
  const std::size_t available = lines.remainingBytes() / 6 + 1;
  if (*vertexCount > available || *faceCount > available ||
      *vertexCount > std::numeric_limits<Index>::max())
    throw FileError(file, lineWhere(lines.lineNumber()),
                    "the header declares " + std::to_string(*vertexCount) + " vertices and " +
                        std::to_string(*faceCount) + " faces but the file has only " +
                        std::to_string(lines.remainingBytes()) + " bytes left",
                    "the file is truncated or its counts are wrong");

  TriangleMesh mesh;
  mesh.vertices.reserve(*vertexCount);
  mesh.vertexLines.reserve(*vertexCount);
  if (withNormals) mesh.normals.reserve(*vertexCount);
  const std::size_t needed = withNormals ? 6 : 3;
  for (std::size_t v = 0; v < *vertexCount; ++v) {
    if (!nextDataLine(lines, tokens))
      throw FileError(file, lineWhere(lines.lineNumber()),
                      "unexpected end of file: " + std::to_string(*vertexCount) +
                          " vertices declared, " + std::to_string(v) + " found",
                      "the file is truncated or its counts are wrong");
    const std::string where = lineWhere(lines.lineNumber());
    if (tokens.size() < needed)
      throw FileError(file, where,
                      "expected " + std::to_string(needed) + " vertex values, found " +
                          std::to_string(tokens.size()));
    double values[6];
    for (std::size_t k = 0; k < needed; ++k) {
      const auto value = parseNumber(tokens[k]);
      if (!value) throw FileError(file, where, quoted(tokens[k]) + " is not a number");
      values[k] = *value;
    }
    mesh.vertices.emplace_back(values[0], values[1], values[2]);
    if (withNormals) mesh.normals.emplace_back(values[3], values[4], values[5]);
    mesh.vertexLines.push_back(lines.lineNumber());
  }
  for (std::size_t f = 0; f < *faceCount; ++f) {
    if (!nextDataLine(lines, tokens))
      throw FileError(file, lineWhere(lines.lineNumber()),
                      "unexpected end of file: " + std::to_string(*faceCount) +
                          " faces declared, " + std::to_string(f) + " found",
                      "the file is truncated or its counts are wrong");
    const std::string where = lineWhere(lines.lineNumber());
    const auto corners = parseUnsigned(tokens[0]);
    if (!corners || *corners < 3 || *corners > tokens.size() - 1)
      throw FileError(file, where,
                      "expected '<n >= 3> <n vertex indices>', found " + quoted(tokens[0]) +
                          " with " + std::to_string(tokens.size() - 1) + " values after it");
    std::vector<Index> polygon(*corners);
    for (std::size_t k = 0; k < *corners; ++k) {
      const auto index = parseUnsigned(tokens[k + 1]);
      if (!index || *index >= mesh.vertices.size())
        throw FileError(file, where,
                        "vertex index " + quoted(tokens[k + 1]) + " is not in [0, " +
                            std::to_string(mesh.vertices.size()) + ")");
      polygon[k] = Index(*index);
    }
    // Fan triangulation of the (assumed convex) polygon.
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
      mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
  return mesh;
}

PointCloud readOff(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  return io_detail::meshToCloud(parseOff(data, file), file, options, report, "off");
}

}  // namespace scalespace
