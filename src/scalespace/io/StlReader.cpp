#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/MeshCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

constexpr std::size_t kHeaderBytes = 80, kTriangleBytes = 50;

/// Welds corners with bit-identical coordinates into one vertex, in order of first appearance
/// (+0 and -0 are one; NaN corners are never welded, so each keeps its own place for errors).
class CornerWelder {
 public:
  explicit CornerWelder(TriangleMesh& mesh) : mesh_(mesh) {}
  Index add(const Vec3& p, std::size_t where) {
    Key key{};
    for (int c = 0; c < 3; ++c) {
      const double v = p[c] == 0 ? 0.0 : p[c];  // -0 welds with +0
      std::memcpy(&key[std::size_t(c)], &v, sizeof v);
    }
    if (p.allFinite()) {
      const auto [it, inserted] = index_.try_emplace(key, Index(mesh_.vertices.size()));
      if (!inserted) return it->second;
    }
    if (mesh_.vertices.size() >= std::size_t(std::numeric_limits<Index>::max()))
      throw OptionError("the mesh has more vertices than a point index holds");
    mesh_.vertices.push_back(p);
    mesh_.vertexLines.push_back(where);
    return Index(mesh_.vertices.size() - 1);
  }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0x9e3779b97f4a7c15ull;
      for (const std::uint64_t v : k) h = (h ^ v) * 0x100000001b3ull + (h >> 29);
      return std::size_t(h);
    }
  };
  TriangleMesh& mesh_;
  std::unordered_map<Key, Index, KeyHash> index_;
};

void addTriangle(TriangleMesh& mesh, const std::array<Index, 3>& t) {
  // A triangle whose corners welded together has no area and no edge: dropped.
  if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) mesh.triangles.push_back(t);
}

TriangleMesh parseBinary(std::string_view data, const std::string& file, std::size_t count) {
  TriangleMesh mesh;
  mesh.vertexBytes = true;
  CornerWelder welder(mesh);
  ByteReader in(data, file);
  in.seek(kHeaderBytes + 4, "the triangle count");
  mesh.triangles.reserve(count);
  for (std::size_t n = 0; n < count; ++n) {
    in.skip(12, "a facet normal");
    std::array<Index, 3> t{};
    for (Index& corner : t) {
      const std::size_t at = in.offset();
      Vec3 p;
      for (int c = 0; c < 3; ++c) p[c] = double(in.read<float>("a vertex coordinate"));
      corner = welder.add(p, at);
    }
    in.skip(2, "the attribute byte count");
    addTriangle(mesh, t);
  }
  return mesh;
}

TriangleMesh parseAscii(std::string_view data, const std::string& file) {
  TriangleMesh mesh;
  CornerWelder welder(mesh);
  LineScanner lines(data);
  std::vector<std::string_view> tokens;
  std::string_view line;
  std::array<Index, 3> t{};
  int corners = 0;  // of the current facet
  bool ended = false;
  while (lines.next(line)) {
    splitWhitespace(line, tokens);
    if (tokens.empty()) continue;
    const std::size_t at = lines.lineNumber();
    const std::string_view word = tokens[0];
    if (word == "vertex") {
      if (tokens.size() != 4) throw FileError(file, lineWhere(at), "expected 'vertex x y z'");
      if (corners == 3)
        throw FileError(file, lineWhere(at), "a facet has more than 3 vertices",
                        "STL facets are triangles: 'outer loop', 3 vertex lines, 'endloop'");
      Vec3 p;
      for (int c = 0; c < 3; ++c) {
        const auto v = parseNumber(tokens[std::size_t(c) + 1]);
        if (!v)
          throw FileError(file, lineWhere(at),
                          quoted(tokens[std::size_t(c) + 1]) + " is not a number");
        p[c] = *v;
      }
      t[std::size_t(corners++)] = welder.add(p, at);
    } else if (word == "endloop") {
      if (corners != 3)
        throw FileError(file, lineWhere(at),
                        "a facet has " + std::to_string(corners) + " vertices, not 3",
                        "STL facets are triangles");
      addTriangle(mesh, t);
      corners = 0;
    } else if (word == "endsolid") {
      ended = true;
    } else if (!(word == "solid" || word == "endfacet" ||
                 (word == "facet" && tokens.size() >= 2 && tokens[1] == "normal") ||
                 (word == "outer" && tokens.size() == 2 && tokens[1] == "loop"))) {
      throw FileError(file, lineWhere(at), "unexpected " + quoted(line) + " in an ASCII STL file",
                      "expected solid, facet, outer loop, vertex, endloop, endfacet or endsolid");
    }
  }
  if (corners != 0 || !ended)
    throw FileError(
        file, lineWhere(lines.lineNumber()),
        "unexpected end of file: " + std::string(corners != 0 ? "inside a facet" : "no 'endsolid'"),
        "the file is truncated");
  return mesh;
}

}  // namespace

std::string TriangleMesh::vertexWhere(std::size_t v) const {
  return vertexBytes ? byteWhere(vertexLines[v]) : lineWhere(vertexLines[v]);
}

TriangleMesh parseStl(std::string_view data, const std::string& file) {
  // Binary when the declared count matches the size exactly: some binary exporters also start
  // their header with "solid".
  if (data.size() >= kHeaderBytes + 4) {
    std::uint32_t count = 0;
    std::memcpy(&count, data.data() + kHeaderBytes, 4);
    if (data.size() == kHeaderBytes + 4 + kTriangleBytes * std::size_t(count))
      return parseBinary(data, file, count);
  }
  // ASCII: "solid" first and the words of a facet (or the end) somewhere; a binary file whose
  // header starts with "solid" but whose size does not match its count has neither.
  std::size_t start = 0;
  while (start < data.size() && std::isspace(static_cast<unsigned char>(data[start]))) ++start;
  if (data.substr(start, 5) == "solid" && (data.find("facet") != std::string_view::npos ||
                                           data.find("endsolid") != std::string_view::npos))
    return parseAscii(data, file);
  if (data.size() < kHeaderBytes + 4)
    throw FileError(file, "",
                    "too short for a binary STL (" + std::to_string(data.size()) +
                        " bytes, at least 84 needed) and not an ASCII one ('solid')",
                    "the file is truncated or not an STL file");
  std::uint32_t count = 0;
  std::memcpy(&count, data.data() + kHeaderBytes, 4);
  throw FileError(file, byteWhere(kHeaderBytes),
                  "a binary STL declaring " + std::to_string(count) + " triangles has " +
                      std::to_string(kHeaderBytes + 4 + kTriangleBytes * std::size_t(count)) +
                      " bytes, this file " + std::to_string(data.size()),
                  "the file is truncated or not an STL file");
}

PointCloud readStl(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report) {
  return io_detail::meshToCloud(parseStl(data, file), file, options, report, "stl");
}

}  // namespace scalespace
