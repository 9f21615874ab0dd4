#pragma once
// PLY (Stanford polygon format): ascii, binary_little_endian and binary_big_endian.
//
// Reading: the `vertex` element gives the points: x y z -> positions, nx ny nz -> normals, every
// other scalar property -> an attribute column of that PLY type (char/uchar/.../double and the
// int8/.../float64 aliases). List properties and other elements are parsed and skipped; so are
// the `face` element (unless the caller asks for the faces: a mesh) and the `edge` element (scalar
// vertex1, vertex2: polylines, io/Polylines.hpp) unless the caller asks for it. Comments and
// obj_info are ignored. Writing: x y z as float32 when that is exact, else float64; nx ny nz
// float32; then every attribute column with its ScalarType, in column order; then, when given, the
// edges as `element edge` with `int vertex1, int vertex2` (the layout CloudCompare, MeshLab and
// Blender use).
#include <array>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

/// An item of the `edge` element: the 0-based indices of the two vertices it joins.
using PlyEdge = std::array<Index, 2>;

/// Parses a whole PLY file held in `data`; `file` names it in error messages. With `edges`, also
/// hands back the `edge` element's items in file order (none when the file has no such element),
/// each index checked against the vertex count (FileError naming the edge's line or byte); an edge
/// element without scalar vertex1 and vertex2 properties is a FileError.
/// With `triangles`, also hands back the `face` element's polygons (its `vertex_indices` or
/// `vertex_index` list) as triangle fans, each index checked against the vertex count; none when
/// the file has no face element. With ReadOptions::dropNonFinite, a skipped vertex takes the edges
/// and triangles that use it along, and the other indices are renumbered to the points kept.
PointCloud readPly(std::string_view data, const std::string& file, const ReadOptions& options = {},
                   ReadReport* report = nullptr, std::vector<PlyEdge>* edges = nullptr,
                   std::vector<std::array<Index, 3>>* triangles = nullptr);

/// Whether the header declares a non-empty `face` element (only the header is parsed: a point
/// cloud's body is not read twice by callers that look for faces first).
bool plyDeclaresFaces(std::string_view data, const std::string& file);

/// Writes the cloud as the vertex element and, when `edges` is given, an edge element after it
/// (indices below cloud.size(), which must fit an int: Error otherwise).
void writePly(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding,
              const std::vector<PlyEdge>* edges = nullptr);

}  // namespace scalespace
