#include "scalespace/io/CloudIO.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/LasFormat.hpp"
#include "scalespace/io/MeshCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/PcdFormat.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WholeFile.hpp"
#include "scalespace/io/XyzFormat.hpp"

namespace scalespace {

namespace {

const char* const kSupported = ".ply .xyz .txt .csv .pts .pwn .off .obj .stl .las .pcd";

/// A PLY file as a mesh: its vertices with their normals when it has them, and its faces. A
/// non-finite vertex is an error or, with options.dropNonFinite, is skipped with its faces
/// (counted in `dropped`).
TriangleMesh meshFromPly(std::string_view data, const std::string& path,
                         const ReadOptions& options = {}, std::size_t* dropped = nullptr) {
  TriangleMesh mesh;
  ReadOptions vertexOptions;
  vertexOptions.dropNonFinite = options.dropNonFinite;
  ReadReport report;
  const PointCloud cloud = readPly(data, path, vertexOptions, &report, nullptr, &mesh.triangles);
  if (dropped) *dropped = report.droppedNonFinite;
  mesh.vertices.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) mesh.vertices[i] = cloud.absolutePosition(i);
  mesh.normals = cloud.normals();
  mesh.vertexLines.assign(cloud.size(), 0);  // unused: readPly has checked every vertex
  return mesh;
}

}  // namespace

CloudFormat formatFromPath(const std::string& path) {
  const std::string extension =
      io_detail::toLower(std::filesystem::path(path).extension().string());
  if (extension == ".ply") return CloudFormat::Ply;
  if (extension == ".xyz" || extension == ".txt" || extension == ".csv" || extension == ".pts" ||
      extension == ".pwn")
    return CloudFormat::Xyz;
  if (extension == ".off") return CloudFormat::Off;
  if (extension == ".obj") return CloudFormat::Obj;
  if (extension == ".stl") return CloudFormat::Stl;
  if (extension == ".las") return CloudFormat::Las;
  if (extension == ".pcd") return CloudFormat::Pcd;
  if (extension == ".laz")
    throw FileError(path, "",
                    "LAZ (compressed LAS) is not supported: no LAZ library is packaged in Debian",
                    "decompress it first, e.g. `laszip -i in.laz -o out.las` or "
                    "`pdal translate in.laz out.las`");
  throw OptionError(path + ": unknown point cloud extension '" + extension +
                    "'; supported extensions: " + kSupported);
}

const char* formatName(CloudFormat format) {
  switch (format) {
    case CloudFormat::Ply:
      return "ply";
    case CloudFormat::Xyz:
      return "xyz";
    case CloudFormat::Off:
      return "off";
    case CloudFormat::Obj:
      return "obj";
    case CloudFormat::Stl:
      return "stl";
    case CloudFormat::Las:
      return "las";
    case CloudFormat::Pcd:
      return "pcd";
  }
  return "";
}

namespace {

PointCloud readByFormat(const std::string& path, const ReadOptions& options, ReadReport* report) {
  const CloudFormat format = formatFromPath(path);
  const std::string data = io_detail::readWholeFile(path);
  switch (format) {
    case CloudFormat::Ply:
      // Sampling a PLY mesh needs its faces (meshToCloud then says when it has none).
      if (options.meshSamples == 0) return readPly(data, path, options, report);
      {
        std::size_t dropped = 0;
        TriangleMesh mesh = meshFromPly(data, path, options, &dropped);
        return io_detail::meshToCloud(std::move(mesh), path, options, report, "ply", dropped);
      }
    case CloudFormat::Stl:
      return readStl(data, path, options, report);
    case CloudFormat::Xyz:
      return readXyz(data, path, options, report);
    case CloudFormat::Off:
      return readOff(data, path, options, report);
    case CloudFormat::Obj:
      return readObj(data, path, options, report);
    case CloudFormat::Las:
      return readLas(data, path, options, report);
    case CloudFormat::Pcd:
      return readPcd(data, path, options, report);
  }
  throw OptionError(path + ": unknown format");
}

}  // namespace

PointCloud readCloud(const std::string& path, const ReadOptions& options, ReadReport* report) {
  PointCloud cloud = readByFormat(path, options, report);
  // Writers that have no normals often fill the columns with zeros (libcgal-demo's blobby.xyz:
  // 3,288 points, every normal 0 0 0); read as normals, every fit reaching one is invalid and
  // `features` found nothing without a word. Such a file is read as one without normals.
  if (cloud.hasNormals() &&
      std::none_of(cloud.normals().begin(), cloud.normals().end(), isUsableNormal)) {
    cloud.setNormals({});
    if (report) report->unusableNormalsDropped = true;
  }
  return cloud;
}

bool isMeshFormat(CloudFormat format) {
  return format == CloudFormat::Off || format == CloudFormat::Obj || format == CloudFormat::Stl;
}

bool canHoldFaces(CloudFormat format) { return isMeshFormat(format) || format == CloudFormat::Ply; }

bool isMeshPath(const std::string& path) {
  try {
    return isMeshFormat(formatFromPath(path));
  } catch (const Error&) {
    return false;
  }
}

std::optional<TriangleMesh> readFacesIfAny(const std::string& path) {
  const CloudFormat format = formatFromPath(path);
  if (!canHoldFaces(format)) return std::nullopt;
  const std::string data = io_detail::readWholeFile(path);
  if (format == CloudFormat::Ply && !plyDeclaresFaces(data, path)) return std::nullopt;
  TriangleMesh mesh = format == CloudFormat::Off   ? parseOff(data, path)
                      : format == CloudFormat::Obj ? parseObj(data, path)
                      : format == CloudFormat::Stl ? parseStl(data, path)
                                                   : meshFromPly(data, path);
  if (mesh.triangles.empty()) return std::nullopt;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (!io_detail::isUsablePosition(mesh.vertices[v]))
      throw FileError(path, mesh.vertexWhere(v),
                      "vertex " + std::to_string(v + 1) +
                          " has a NaN, infinite or absurdly large (beyond 1e100) coordinate",
                      "fix or remove that vertex");
  return mesh;
}

TriangleMesh readTriangleMesh(const std::string& path) {
  if (!canHoldFaces(formatFromPath(path)))
    throw FileError(path, "", "is not a mesh file", "give an .off, .obj, .stl or .ply mesh");
  std::optional<TriangleMesh> mesh = readFacesIfAny(path);
  if (!mesh)
    throw FileError(path, "", "the mesh has no faces", "give a mesh with triangles or polygons");
  return std::move(*mesh);
}

void writeCloud(const PointCloud& cloud, const std::string& path, const WriteOptions& options) {
  const CloudFormat format = formatFromPath(path);
  if (isMeshFormat(format))
    throw OptionError(path + ": cannot write ." + formatName(format) +
                      " (a point cloud has no faces); writable extensions: .ply .xyz .txt .csv "
                      ".pts .pwn .las .pcd");
  const std::string extension =
      io_detail::toLower(std::filesystem::path(path).extension().string());
  if (extension == ".pwn") checkPwnWritable(cloud);  // before any folder or file is made
  // Fail before creating any file when the cloud cannot be represented (bad attribute names...):
  // the writers check first and throw from inside writeFileAtomically, which cleans up.
  writeFileAtomically(path, [&](std::ostream& out) {
    switch (format) {
      case CloudFormat::Ply:
        writePly(cloud, out, options.ascii ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian);
        break;
      case CloudFormat::Xyz: {
        if (extension == ".pwn")
          writePwn(cloud, out);
        else
          writeXyz(cloud, out, extension == ".csv" ? ',' : ' ');
        break;
      }
      case CloudFormat::Las:
        writeLas(cloud, out, path);
        break;
      case CloudFormat::Pcd:
        writePcd(cloud, out, options.ascii);
        break;
      case CloudFormat::Off:
      case CloudFormat::Obj:
      case CloudFormat::Stl:
        break;
    }
  });
}

}  // namespace scalespace
