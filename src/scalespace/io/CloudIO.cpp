#include "scalespace/io/CloudIO.hpp"

#include <filesystem>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/LasFormat.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/io/PcdFormat.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/TextParsing.hpp"
#include "scalespace/io/WholeFile.hpp"
#include "scalespace/io/XyzFormat.hpp"

namespace scalespace {

namespace {

const char* const kSupported = ".ply .xyz .txt .csv .pts .pwn .off .obj .las .pcd";

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
    case CloudFormat::Las:
      return "las";
    case CloudFormat::Pcd:
      return "pcd";
  }
  return "";
}

PointCloud readCloud(const std::string& path, const ReadOptions& options, ReadReport* report) {
  const CloudFormat format = formatFromPath(path);
  const std::string data = io_detail::readWholeFile(path);
  switch (format) {
    case CloudFormat::Ply:
      return readPly(data, path, options, report);
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

bool isMeshPath(const std::string& path) {
  try {
    const CloudFormat format = formatFromPath(path);
    return format == CloudFormat::Off || format == CloudFormat::Obj;
  } catch (const Error&) {
    return false;
  }
}

TriangleMesh readTriangleMesh(const std::string& path) {
  if (!isMeshPath(path))
    throw FileError(path, "", "is not a mesh file", "give an .off or .obj file");
  const std::string data = io_detail::readWholeFile(path);
  TriangleMesh mesh =
      formatFromPath(path) == CloudFormat::Off ? parseOff(data, path) : parseObj(data, path);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (!io_detail::isUsablePosition(mesh.vertices[v]))
      throw FileError(path, io_detail::lineWhere(mesh.vertexLines[v]),
                      "vertex " + std::to_string(v + 1) +
                          " has a NaN, infinite or absurdly large (beyond 1e100) coordinate",
                      "fix or remove that vertex");
  if (mesh.triangles.empty())
    throw FileError(path, "", "the mesh has no faces", "give a mesh with triangles or polygons");
  return mesh;
}

void writeCloud(const PointCloud& cloud, const std::string& path, const WriteOptions& options) {
  const CloudFormat format = formatFromPath(path);
  if (format == CloudFormat::Off || format == CloudFormat::Obj)
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
        break;
    }
  });
}

}  // namespace scalespace
