#pragma once
// Polylines over a point cloud (curvature lines, feature curves: Ch. 3) and their files.
//
// A PolylineSet stores every vertex once, line after line, in a PointCloud, so that per-vertex
// quantities (curvatures, the scale, a line id) are ordinary named attribute columns, written and
// read like a cloud's. Line l is the vertices [offsets[l], offsets[l + 1]).
//
// Files, by extension (case-insensitive):
//   .ply  element vertex (x y z, nx ny nz when the vertices have normals, then every attribute
//         column with its type), then element edge (int vertex1, int vertex2): the segments of
//         each line in order, then, for a closed line, the edge from its last vertex back to its
//         first. Binary little endian, or ascii with WriteOptions::ascii. Read and written.
//   .obj  `v x y z` lines, then one `l i j k ...` record per line (1-based; a closed line repeats
//         its first index at the end). OBJ has no per-vertex attributes: normals and columns are
//         not stored, and the file's header comment lists what was left out. Written only.
// Positions are written as absolute coordinates (PointCloud::absolutePosition), atomically
// (io/AtomicFile.hpp).
//
// Reading a PLY chains its edges back into lines, in file order: an edge (a, b) continues the
// current line when a is that line's last vertex, and closes it when b is also the line's first
// vertex; any other edge starts a new line. A file written here reads back as written; in a file
// from elsewhere, each line's vertices are copied in line order (a vertex on two lines appears in
// both), and vertices no edge uses are dropped. A PLY without an edge element has no lines.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace scalespace {

struct PolylineSet {
  /// Positions (+ optional normals) and attribute columns, one row per vertex, line after line.
  PointCloud vertices;
  /// lineCount() + 1 entries: offsets.front() == 0, offsets.back() == vertices.size(), each line
  /// at least 2 vertices. Empty is accepted for a set without vertices.
  std::vector<std::size_t> offsets{0};
  /// Empty (every line open) or one flag per line: 1 = the last vertex joins the first.
  std::vector<std::uint8_t> closed;

  std::size_t lineCount() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t lineSize(std::size_t line) const { return offsets[line + 1] - offsets[line]; }
  bool isClosed(std::size_t line) const { return !closed.empty() && closed[line] != 0; }
};

/// OptionError naming the field (PolylineSet::offsets, PolylineSet::closed) unless `lines` is
/// well formed (see the fields); `context` (e.g. the output path) starts the message when given.
void validatePolylineSet(const PolylineSet& lines, const std::string& context = {});

/// Writes `lines` to `path` (.ply or .obj, see the file comment), atomically: on any error no file
/// is left (an existing one is kept). OptionError for another extension or a malformed set;
/// Error for an attribute name PLY cannot hold; FileError naming `path` for I/O failures.
void writePolylines(const PolylineSet& lines, const std::string& path,
                    const WriteOptions& options = {});

/// Reads a .ply polyline file (see the file comment). FileError naming `path` for a missing,
/// malformed or truncated file or an edge whose index is not a vertex; OptionError for another
/// extension. NaN or infinite positions are a FileError (dropping a vertex would renumber the
/// edges).
PolylineSet readPolylines(const std::string& path);

/// readPolylines on a PLY file held in memory (for tests and fuzzers); `file` names it in errors.
PolylineSet readPolylinesPly(std::string_view data, const std::string& file);

}  // namespace scalespace
