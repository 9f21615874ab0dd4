#include "scalespace/io/Polylines.hpp"

#include <filesystem>
#include <ostream>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WholeFile.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

std::string extensionOf(const std::string& path) {
  return toLower(std::filesystem::path(path).extension().string());
}

/// The PLY edges of `lines`: each line's segments in order, then its closing edge.
std::vector<PlyEdge> edgesOf(const PolylineSet& lines) {
  std::vector<PlyEdge> edges;
  edges.reserve(lines.vertices.size());
  for (std::size_t l = 0; l < lines.lineCount(); ++l) {
    const Index first = Index(lines.offsets[l]), last = Index(lines.offsets[l + 1] - 1);
    for (Index v = first; v < last; ++v) edges.push_back({v, Index(v + 1)});
    if (lines.isClosed(l)) edges.push_back({last, first});
  }
  return edges;
}

void writeObj(const PolylineSet& lines, std::ostream& out) {
  const PointCloud& vertices = lines.vertices;
  out << "# written by scalespace " SCALESPACE_VERSION "\n# " << vertices.size() << " vertices, "
      << lines.lineCount() << " polylines (a closed line repeats its first vertex)\n";
  // Say what the file lacks, so that nobody mistakes it for the full result.
  std::string dropped = vertices.hasNormals() ? " nx ny nz" : "";
  for (const AttributeColumn& column : vertices.attributes()) dropped += ' ' + column.name;
  if (!dropped.empty())
    out << "# OBJ stores positions only; not stored here:" << dropped
        << "\n# (write the polylines as .ply to keep them)\n";
  std::string line;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3 p = vertices.absolutePosition(i);
    line = "v";
    for (int k = 0; k < 3; ++k) {
      line += ' ';
      line += formatNumber(p[k]);
    }
    line += '\n';
    out << line;
  }
  for (std::size_t l = 0; l < lines.lineCount(); ++l) {
    line = "l";
    for (std::size_t v = lines.offsets[l]; v < lines.offsets[l + 1]; ++v) {
      line += ' ';
      line += std::to_string(v + 1);
    }
    if (lines.isClosed(l)) {
      line += ' ';
      line += std::to_string(lines.offsets[l] + 1);
    }
    line += '\n';
    out << line;
  }
}

/// Chains `edges` into lines (rule in the header) and copies the vertices in line order.
PolylineSet chainEdges(const PointCloud& cloud, const std::vector<PlyEdge>& edges) {
  PolylineSet lines;
  std::vector<Index> order;
  order.reserve(edges.size() + 1);
  bool growing = false;  // the last line may still be continued
  std::size_t start = 0;
  for (const PlyEdge& e : edges) {
    if (growing && e[0] == order.back()) {
      if (e[1] == order[start]) {
        lines.closed.back() = 1;
        lines.offsets.push_back(order.size());
        growing = false;
      } else {
        order.push_back(e[1]);
      }
      continue;
    }
    if (growing) lines.offsets.push_back(order.size());
    start = order.size();
    order.push_back(e[0]);
    order.push_back(e[1]);
    lines.closed.push_back(0);
    growing = true;
  }
  if (growing) lines.offsets.push_back(order.size());
  lines.vertices = cloud.subset(order);
  return lines;
}

}  // namespace

void validatePolylineSet(const PolylineSet& lines, const std::string& context) {
  const std::string prefix = context.empty() ? "" : context + ": ";
  const std::vector<std::size_t>& offsets = lines.offsets;
  const std::size_t n = lines.vertices.size();
  if (offsets.empty()) {
    if (n != 0)
      throw OptionError(prefix + "PolylineSet::offsets is empty but there are " +
                        std::to_string(n) + " vertices (give offsets {0, ..., " +
                        std::to_string(n) + "})");
  } else if (offsets.front() != 0 || offsets.back() != n) {
    throw OptionError(prefix + "PolylineSet::offsets must start at 0 and end at the vertex count " +
                      std::to_string(n) + " (they run from " + std::to_string(offsets.front()) +
                      " to " + std::to_string(offsets.back()) + ")");
  }
  for (std::size_t l = 0; l < lines.lineCount(); ++l) {
    if (offsets[l + 1] < offsets[l])
      throw OptionError(prefix + "PolylineSet::offsets decrease at line " + std::to_string(l) +
                        " (" + std::to_string(offsets[l]) + " then " +
                        std::to_string(offsets[l + 1]) + ")");
    const std::size_t size = offsets[l + 1] - offsets[l];
    if (size < 2)
      throw OptionError(prefix + "PolylineSet::offsets: line " + std::to_string(l) + " has " +
                        std::to_string(size) + (size == 1 ? " vertex" : " vertices") +
                        "; a polyline has at least 2");
  }
  if (!lines.closed.empty() && lines.closed.size() != lines.lineCount())
    throw OptionError(prefix + "PolylineSet::closed has " + std::to_string(lines.closed.size()) +
                      " flags for " + std::to_string(lines.lineCount()) +
                      " lines (give one per line, or none when every line is open)");
}

void writePolylines(const PolylineSet& lines, const std::string& path,
                    const WriteOptions& options) {
  const std::string extension = extensionOf(path);
  if (extension != ".ply" && extension != ".obj")
    throw OptionError(path +
                      ": polylines are written as .ply (with their attributes) or .obj "
                      "(positions only), not '" +
                      extension + "'");
  // Before any file is created: a malformed set leaves nothing behind.
  validatePolylineSet(lines, path);
  if (extension == ".obj") {
    writeFileAtomically(path, [&](std::ostream& out) { writeObj(lines, out); });
    return;
  }
  const std::vector<PlyEdge> edges = edgesOf(lines);
  writeFileAtomically(path, [&](std::ostream& out) {
    writePly(lines.vertices, out,
             options.ascii ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian, &edges);
  });
}

PolylineSet readPolylinesPly(std::string_view data, const std::string& file) {
  std::vector<PlyEdge> edges;
  const PointCloud cloud = readPly(data, file, {}, nullptr, &edges);
  return chainEdges(cloud, edges);
}

PolylineSet readPolylines(const std::string& path) {
  if (extensionOf(path) != ".ply")
    throw OptionError(path + ": polylines are read from .ply files (vertex and edge elements)");
  return readPolylinesPly(readWholeFile(path), path);
}

}  // namespace scalespace
