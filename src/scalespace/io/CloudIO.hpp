#pragma once
// Reading and writing point clouds, dispatching on the file extension (case-insensitive).
//
//   .ply                     PLY ascii / binary_little_endian / binary_big_endian  (read, write)
//   .xyz .txt .csv .pts      text columns "x y z [nx ny nz] [more]"               (read, write)
//   .pwn                     CGAL's points with normals, "x y z nx ny nz"         (read, write)
//                            (read as text columns; written without a header, positions and
//                            normals only)
//   .off .obj                triangle meshes: vertices or area-uniform samples     (read)
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
#include <string>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

enum class CloudFormat { Ply, Xyz, Off, Obj, Las, Pcd };

/// The format for `path`'s extension. Throws OptionError listing the supported extensions, or
/// FileError for .laz (compressed LAS), which cannot be read.
CloudFormat formatFromPath(const std::string& path);
const char* formatName(CloudFormat format);  // "ply", "xyz", "off", "obj", "las", "pcd"

/// Reads the whole file and parses it according to its extension. An empty cloud (0 points) is
/// valid and returned as such; callers decide whether that is an error.
PointCloud readCloud(const std::string& path, const ReadOptions& options = {},
                     ReadReport* report = nullptr);

struct WriteOptions {
  bool ascii = false;  // PLY/PCD: ascii instead of binary; XYZ is always text
};

/// Writes `cloud` atomically (writeFileAtomically). OFF/OBJ cannot be written (a point cloud has no
/// faces): OptionError.
void writeCloud(const PointCloud& cloud, const std::string& path, const WriteOptions& options = {});

/// True for the extensions of the mesh formats (.off, .obj), whose faces readTriangleMesh reads.
bool isMeshPath(const std::string& path);

/// The triangles of an OFF or OBJ file (polygons as fans) with its vertices and vertex normals
/// when it has usable ones. FileError naming the file (and the line) for another format, a vertex
/// with a NaN, infinite or absurd coordinate, or no triangle.
TriangleMesh readTriangleMesh(const std::string& path);

}  // namespace scalespace
