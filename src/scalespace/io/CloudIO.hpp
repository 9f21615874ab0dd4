#pragma once
// Reading and writing point clouds, dispatching on the file extension (case-insensitive).
//
//   .ply                     PLY ascii / binary_little_endian / binary_big_endian  (read, write)
//                            (with a face element: a mesh, sampled like the ones below when
//                            asked)
//   .xyz .txt .csv .pts      text columns "x y z [nx ny nz] [more]"               (read, write)
//   .pwn                     CGAL's points with normals, "x y z nx ny nz"         (read, write)
//                            (read as text columns; written without a header, positions and
//                            normals only)
//   .off .obj .stl           triangle meshes: vertices or area-uniform samples     (read)
//                            (STL ascii or binary, its shared corners welded)
//   .las                     LAS 1.0-1.4 uncompressed, point formats 0-3 and 6-8   (read, write)
//                            written as LAS 1.2, or as LAS 1.4 with "extra bytes" holding the
//                            normals and the columns LAS records have no field for
//   .pcd                     PCD v0.7 ascii / binary / binary_compressed           (read, write)
//   .laz                     rejected with a FileError: no LAZ library is packaged in Debian
//
// Every reader is strict: malformed input throws FileError naming the file, the line or byte, what
// was expected and a fix. Declared counts are checked against the file size before allocating.
// The per-format functions (PlyFormat.hpp, ...) parse from memory, for the fuzzers and for tests.
//
// Policies shared by every reader:
//  - NaN/Inf coordinates (and magnitudes beyond 1e100): FileError, or skipped and counted with
//    ReadOptions::dropNonFinite. Attributes may hold NaN.
//  - Normals are kept as read: a cloud whose file has normals "has normals" even if some are zero
//    or NaN; callers needing valid normals check them or re-estimate them.
//  - Empty clouds are valid files and read as empty clouds.
//  - Values of float32 columns read from text are rounded to float, as the binary encodings store.
#include <optional>
#include <string>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

enum class CloudFormat { Ply, Xyz, Off, Obj, Stl, Las, Pcd };

/// The format for `path`'s extension. Throws OptionError listing the supported extensions, or
/// FileError for .laz (compressed LAS), which cannot be read.
CloudFormat formatFromPath(const std::string& path);
const char* formatName(CloudFormat format);  // "ply", "xyz", "off", "obj", "stl", "las", "pcd"

/// Reads the whole file and parses it according to its extension. An empty cloud (0 points) is
/// valid and returned as such; callers decide whether that is an error. Normals that are all
/// zero or NaN/Inf are dropped (ReadReport::unusableNormalsDropped).
PointCloud readCloud(const std::string& path, const ReadOptions& options = {},
                     ReadReport* report = nullptr);

struct WriteOptions {
  bool ascii = false;  // PLY/PCD: ascii instead of binary; XYZ is always text
};

/// Writes `cloud` atomically (writeFileAtomically). OFF/OBJ cannot be written (a point cloud has no
/// faces): OptionError.
void writeCloud(const PointCloud& cloud, const std::string& path, const WriteOptions& options = {});

/// The mesh formats (.off, .obj, .stl): files of vertices and faces, never written.
bool isMeshFormat(CloudFormat format);
/// The formats whose files may hold faces: the mesh formats and PLY (a `face` element).
bool canHoldFaces(CloudFormat format);
/// True for the extensions of the mesh formats.
bool isMeshPath(const std::string& path);

/// The faces of a file that may hold some (canHoldFaces), as triangles (polygons as fans), with
/// its vertices and their normals when it has usable ones; nullopt for a point cloud format or a
/// file without faces (an OFF of vertices only, a PLY without a face element). FileError naming
/// the file (and the line) for a malformed file or a vertex with a NaN, infinite or absurd
/// coordinate.
std::optional<TriangleMesh> readFacesIfAny(const std::string& path);

/// readFacesIfAny, with a FileError for a format without faces or a file without a triangle.
TriangleMesh readTriangleMesh(const std::string& path);

}  // namespace scalespace
