#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/MeshFormat.hpp"

namespace scalespace {

namespace {

/// Uniform double in [0, 1) from the top 53 bits: unlike std::uniform_real_distribution its
/// result is the same with every standard library, so samples are reproducible everywhere.
double uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

}  // namespace

std::vector<Vec3> areaWeightedVertexNormals(const TriangleMesh& mesh) {
  std::vector<Vec3> normals(mesh.vertices.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    // The cross product's length is twice the area: summing it weights each face by its area.
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (!n.allFinite()) continue;
    for (Index v : t) normals[v] += n;
  }
  for (Vec3& n : normals) {
    const double length = n.norm();
    n = length > 0 ? Vec3(n / length) : Vec3::Zero();
  }
  return normals;
}

PointCloud sampleMesh(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed,
                      double creaseAngleDegrees) {
  const double cosCrease = std::cos(std::clamp(creaseAngleDegrees, 0.0, 180.0) * M_PI / 180);
  if (count > std::numeric_limits<Index>::max())
    throw OptionError("mesh sampling: " + std::to_string(count) + " samples exceed the limit of " +
                      std::to_string(std::numeric_limits<Index>::max()) + " points");
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0.0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const double area = 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                  .norm();
    if (std::isfinite(area)) total += area;
    cumulative[f] = total;
  }
  if (!(total > 0) || !std::isfinite(total))
    throw OptionError("mesh sampling: the mesh has no triangle of positive area to sample");

  const std::vector<Vec3> vertexNormals =
      mesh.normals.size() == mesh.vertices.size() ? mesh.normals : areaWeightedVertexNormals(mesh);
  std::mt19937_64 rng(seed);
  std::vector<Vec3> points(count), normals(count);
  for (std::size_t i = 0; i < count; ++i) {
    // Triangle with probability area / total: the first whose cumulative area exceeds u.
    // Zero-area triangles have empty intervals and are never chosen.
    const double u = uniform01(rng) * total;
    std::size_t f =
        std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin());
    f = std::min(f, cumulative.size() - 1);
    while (f > 0 && cumulative[f] == cumulative[f - 1]) --f;  // never land on a zero-area face
    const auto& t = mesh.triangles[f];
    // Uniform point in a triangle: with s = sqrt(r1) the weights (1 - s, s (1 - r2), s r2) have
    // the uniform density over the triangle (Osada et al. 2002).
    const double s = std::sqrt(uniform01(rng));
    const double r2 = uniform01(rng);
    const double wa = 1.0 - s, wb = s * (1.0 - r2), wc = s * r2;
    points[i] = wa * mesh.vertices[t[0]] + wb * mesh.vertices[t[1]] + wc * mesh.vertices[t[2]];
    const Vec3 face = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                          .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                          .normalized();
    const bool crease = creaseAngleDegrees < 180 && (vertexNormals[t[0]].dot(face) < cosCrease ||
                                                     vertexNormals[t[1]].dot(face) < cosCrease ||
                                                     vertexNormals[t[2]].dot(face) < cosCrease);
    Vec3 n =
        crease
            ? face
            : Vec3(wa * vertexNormals[t[0]] + wb * vertexNormals[t[1]] + wc * vertexNormals[t[2]]);
    double length = n.norm();
    if (!(length > 1e-12) || !std::isfinite(length)) {
      // Opposite vertex normals cancelled out (or the file gave zero normals): use the face's.
      n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
              .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      length = n.norm();
    }
    normals[i] = n / length;
  }
  PointCloud cloud;
  cloud.setAbsolutePositions(points);
  cloud.setNormals(std::move(normals));
  return cloud;
}

}  // namespace scalespace
