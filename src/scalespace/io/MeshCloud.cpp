#include "scalespace/io/MeshCloud.hpp"

#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace::io_detail {

PointCloud meshToCloud(TriangleMesh mesh, const std::string& file, const ReadOptions& options,
                       ReadReport* report, const std::string& formatDescription,
                       std::size_t droppedBefore) {
  const bool normals = mesh.normals.size() == mesh.vertices.size() && !mesh.vertices.empty();
  if (options.meshSamples == 0) {
    CloudBuilder builder(file, options);
    if (normals) builder.enableNormals();
    builder.reserve(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
      builder.addPoint(mesh.vertices[v], normals ? mesh.normals[v] : Vec3::Zero(), nullptr,
                       [&] { return mesh.vertexWhere(v); });
    PointCloud cloud = builder.finish(report, formatDescription);
    if (report) report->droppedNonFinite += droppedBefore;
    return cloud;
  }

  // Sampling: a non-finite vertex is an error, or (dropNonFinite) removes its faces.
  std::vector<bool> bad(mesh.vertices.size(), false);
  std::size_t dropped = 0;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (isUsablePosition(mesh.vertices[v])) continue;
    if (!options.dropNonFinite)
      throw FileError(file, mesh.vertexWhere(v),
                      "vertex " + std::to_string(v + 1) +
                          " has a NaN, infinite or absurdly large (beyond 1e100) coordinate",
                      "skip its faces with ReadOptions::dropNonFinite");
    bad[v] = true;
    ++dropped;
  }
  if (dropped > 0) {
    std::vector<std::array<Index, 3>> kept;
    for (const auto& t : mesh.triangles)
      if (!bad[t[0]] && !bad[t[1]] && !bad[t[2]]) kept.push_back(t);
    mesh.triangles = std::move(kept);
  }
  if (mesh.triangles.empty())
    throw FileError(
        file, "",
        "the mesh has no faces to sample " + std::to_string(options.meshSamples) + " points from",
        "read its vertices instead (no mesh sampling)");
  PointCloud cloud;
  try {
    // The file's own vertex normals are interpolated as given; ours (area-weighted) only where
    // they do not lean across a crease.
    const bool own = mesh.normals.size() == mesh.vertices.size() && !mesh.vertices.empty();
    cloud =
        sampleMesh(mesh, options.meshSamples, options.seed, own ? 180.0 : kMeshCreaseAngleDegrees);
  } catch (const OptionError& e) {
    throw FileError(file, "", e.what(), "check that the faces are not all degenerate");
  }
  if (report) {
    report->droppedNonFinite = droppedBefore + dropped;
    report->format =
        formatDescription + ", " + std::to_string(options.meshSamples) + " area samples";
  }
  return cloud;
}

}  // namespace scalespace::io_detail
