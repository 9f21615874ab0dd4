#include "scalespace/param/ParamShapes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/core/Error.hpp"

namespace scalespace {
namespace {

struct ShapeName {
  ParamShape shape;
  const char* name;
};
constexpr std::array<ShapeName, 10> kNames{{{ParamShape::BumpyDisk, "bumpy-disk"},
                                            {ParamShape::Hemisphere, "hemisphere"},
                                            {ParamShape::Relief, "relief"},
                                            {ParamShape::HoledSheet, "holed-sheet"},
                                            {ParamShape::PartialSphere, "partial-sphere"},
                                            {ParamShape::Triaxial, "triaxial"},
                                            {ParamShape::Blob, "blob"},
                                            {ParamShape::RoundedCube, "rounded-cube"},
                                            {ParamShape::Tube, "tube"},
                                            {ParamShape::Torus, "ring"}}};

/// A parametric surface over [0, 1]^2: the map, which parameters are inside, which parameter
/// wraps around (a closed tube or torus), and which side the normal points to.
struct GridPatch {
  std::function<Vec3(double a, double b)> map;
  std::function<bool(double a, double b)> inside;  // empty: the whole square
  bool periodicA = false, periodicB = false;
  std::function<Vec3(const Vec3& p)> outside;  // a direction the normal at p must agree with
};

/// Unit normal of the map at (a, b) by central differences (step far below any grid cell).
Vec3 patchNormal(const GridPatch& patch, double a, double b) {
  const double h = 1e-6;
  const Vec3 da = patch.map(a + h, b) - patch.map(a - h, b);
  const Vec3 db = patch.map(a, b + h) - patch.map(a, b - h);
  Vec3 n = da.cross(db);
  const double len = n.norm();
  const Vec3 p = patch.map(a, b);
  const Vec3 side = patch.outside(p);
  if (!(len > 0)) return side.normalized();  // a pole of the map: the side is the normal there
  n /= len;
  return n.dot(side) < 0 ? Vec3(-n) : n;
}

/// Appends the patch's grid: n x n cells, two triangles per cell whose corners are all inside,
/// wound so that their normal agrees with the vertex normals.
void addPatch(TriangleMesh& mesh, const GridPatch& patch, int n) {
  const int na = patch.periodicA ? n : n + 1, nb = patch.periodicB ? n : n + 1;
  std::vector<Index> id(std::size_t(na) * nb, Index(-1));
  for (int j = 0; j < nb; ++j)
    for (int i = 0; i < na; ++i) {
      const double a = double(i) / n, b = double(j) / n;
      if (patch.inside && !patch.inside(a, b)) continue;
      id[std::size_t(j) * na + i] = Index(mesh.vertices.size());
      mesh.vertices.push_back(patch.map(a, b));
      mesh.normals.push_back(patchNormal(patch, a, b));
    }
  auto vertex = [&](int i, int j) { return id[std::size_t(j % nb) * na + (i % na)]; };
  auto add = [&](Index p, Index q, Index r) {
    if (p == Index(-1) || q == Index(-1) || r == Index(-1)) return;
    const Vec3 face =
        (mesh.vertices[q] - mesh.vertices[p]).cross(mesh.vertices[r] - mesh.vertices[p]);
    const Vec3 normal = mesh.normals[p] + mesh.normals[q] + mesh.normals[r];
    if (face.dot(normal) >= 0)
      mesh.triangles.push_back({p, q, r});
    else
      mesh.triangles.push_back({p, r, q});
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      add(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1));
      add(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1));
    }
}

/// (a, b) in [0, 1]^2 -> (x, y) in [-1, 1]^2.
double centred(double a) { return 2 * a - 1; }

GridPatch heightField(std::function<double(double, double)> height,
                      std::function<bool(double, double)> insideXY) {
  GridPatch patch;
  patch.map = [height](double a, double b) {
    const double x = centred(a), y = centred(b);
    return Vec3(x, y, height(x, y));
  };
  if (insideXY)
    patch.inside = [insideXY](double a, double b) { return insideXY(centred(a), centred(b)); };
  patch.outside = [](const Vec3&) { return Vec3(0, 0, 1); };
  return patch;
}

bool inUnitDisk(double x, double y) { return x * x + y * y <= 1 + 1e-12; }

/// The unit sphere's points at polar angle r * maxPolar from +z, the disk point (x, y) giving
/// the azimuth: a cap as a disk-parametrized patch.
Vec3 capPoint(double x, double y, double maxPolar) {
  const double r = std::sqrt(x * x + y * y);
  const double theta = r * maxPolar;
  const double s = r > 0 ? std::sin(theta) / r : maxPolar;
  return Vec3(s * x, s * y, std::cos(theta));
}

/// The closed star-shaped surface r(d) d over the six faces of a cube sphere (each face's grid
/// mapped through tan for even cells).
void addStarShape(TriangleMesh& mesh, const std::function<double(const Vec3&)>& radius, int n) {
  const std::array<Mat3, 6> frames = [] {
    std::array<Mat3, 6> f;
    const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
    for (int k = 0; k < 3; ++k)
      for (int s = 0; s < 2; ++s) {
        const Vec3 c = (s == 0 ? 1.0 : -1.0) * axes[k];
        const Vec3 u = axes[(k + 1) % 3];
        const Vec3 v = c.cross(u);
        Mat3 m;
        m.col(0) = c;
        m.col(1) = u;
        m.col(2) = v;
        f[std::size_t(2 * k + s)] = m;
      }
    return f;
  }();
  for (const Mat3& frame : frames) {
    GridPatch patch;
    patch.map = [frame, radius](double a, double b) {
      const Vec3 d = (frame.col(0) + std::tan(centred(a) * kPi / 4) * frame.col(1) +
                      std::tan(centred(b) * kPi / 4) * frame.col(2))
                         .normalized();
      return Vec3(radius(d) * d);
    };
    patch.outside = [](const Vec3& p) { return p; };
    addPatch(mesh, patch, n);
  }
}

}  // namespace

const char* paramShapeName(ParamShape shape) {
  for (const ShapeName& s : kNames)
    if (s.shape == shape) return s.name;
  return "?";
}

bool isParamShapeName(const std::string& name) {
  return std::any_of(kNames.begin(), kNames.end(),
                     [&](const ShapeName& s) { return name == s.name; });
}

ParamShape parseParamShape(const std::string& name) {
  for (const ShapeName& s : kNames)
    if (name == s.name) return s.shape;
  std::string list;
  for (const ShapeName& s : kNames) list += (list.empty() ? "" : ", ") + std::string(s.name);
  throw OptionError("unknown parametrization shape '" + name + "' (expected one of " + list + ")");
}

std::vector<ParamShape> allParamShapes() {
  std::vector<ParamShape> shapes;
  for (const ShapeName& s : kNames) shapes.push_back(s.shape);
  return shapes;
}

ParamTopology paramShapeTopology(ParamShape shape) {
  switch (shape) {
    case ParamShape::Triaxial:
    case ParamShape::Blob:
    case ParamShape::RoundedCube:
      return ParamTopology::Sphere;
    case ParamShape::Tube:
      return ParamTopology::Annulus;
    case ParamShape::Torus:
      return ParamTopology::Torus;
    default:
      return ParamTopology::Disk;
  }
}

const char* paramTopologyName(ParamTopology topology) {
  switch (topology) {
    case ParamTopology::Disk:
      return "disk";
    case ParamTopology::Sphere:
      return "sphere";
    case ParamTopology::Annulus:
      return "annulus";
    case ParamTopology::Torus:
      return "torus";
  }
  return "?";
}

TriangleMesh paramShapeMesh(ParamShape shape, int resolution) {
  if (resolution < 4 || resolution > 4096)
    throw OptionError("ParamShapeOptions::resolution must be in [4, 4096]");
  TriangleMesh mesh;
  const int n = resolution;
  switch (shape) {
    case ParamShape::BumpyDisk:
      addPatch(mesh,
               heightField(
                   [](double x, double y) {
                     return 0.06 * std::sin(4 * x) * std::sin(4 * y) +
                            0.04 * std::cos(6 * std::sqrt(x * x + y * y));
                   },
                   inUnitDisk),
               n);
      break;
    case ParamShape::Hemisphere:
    case ParamShape::PartialSphere: {
      const bool partial = shape == ParamShape::PartialSphere;
      const double maxPolar = partial ? 2 * kPi / 3 : kPi / 2;
      // The scan's occlusion hole: directions within 18 degrees of polar angle 60, azimuth 0.
      const Vec3 holeAxis(std::sin(kPi / 3), 0, std::cos(kPi / 3));
      GridPatch patch;
      patch.map = [maxPolar](double a, double b) {
        return capPoint(centred(a), centred(b), maxPolar);
      };
      patch.inside = [partial, maxPolar, holeAxis](double a, double b) {
        const double x = centred(a), y = centred(b);
        if (!inUnitDisk(x, y)) return false;
        return !partial || capPoint(x, y, maxPolar).dot(holeAxis) < std::cos(18 * kPi / 180);
      };
      patch.outside = [](const Vec3& p) { return p; };
      addPatch(mesh, patch, n);
      break;
    }
    case ParamShape::Relief:
      addPatch(mesh,
               heightField(
                   [](double x, double y) {
                     const double bump =
                         0.25 * std::exp(-((x - 0.35) * (x - 0.35) + (y + 0.3) * (y + 0.3)) / 0.06);
                     const double s = y - 0.5 * x - 0.45;
                     const double ridge = 0.12 * std::exp(-s * s / 0.01);
                     const double valley =
                         -0.15 *
                         std::exp(-((x + 0.45) * (x + 0.45) + (y + 0.35) * (y + 0.35)) / 0.04);
                     return bump + ridge + valley;
                   },
                   {}),
               n);
      break;
    case ParamShape::HoledSheet:
      addPatch(
          mesh,
          heightField([](double x, double y) { return 0.1 * std::sin(2 * x) * std::cos(1.5 * y); },
                      [](double x, double y) {
                        const double r1 = (x - 0.45) * (x - 0.45) + (y - 0.1) * (y - 0.1);
                        const double r2 = (x + 0.45) * (x + 0.45) + (y - 0.1) * (y - 0.1);
                        return r1 > 0.09 && r2 > 0.09;
                      }),
          n);
      break;
    case ParamShape::Triaxial:
      addStarShape(
          mesh,
          [](const Vec3& d) {
            return 1 / std::sqrt(d.x() * d.x() + d.y() * d.y() / 2.25 + d.z() * d.z() / 4);
          },
          n);
      break;
    case ParamShape::Blob:
      addStarShape(
          mesh,
          [](const Vec3& d) {
            return 1 + 0.18 * std::sin(3 * d.x() + 1) * std::cos(2 * d.y()) +
                   0.12 * d.z() * d.z() * d.z() + 0.08 * std::sin(4 * d.z() + 2 * d.x());
          },
          n);
      break;
    case ParamShape::RoundedCube:
      addStarShape(
          mesh,
          [](const Vec3& d) {
            const double s = std::pow(d.x(), 8) + std::pow(d.y(), 8) + std::pow(d.z(), 8);
            return std::pow(s, -1.0 / 8);
          },
          n);
      break;
    case ParamShape::Tube: {
      GridPatch patch;
      patch.map = [](double a, double b) {
        return Vec3(0.5 * std::cos(2 * kPi * a), 0.5 * std::sin(2 * kPi * a), 2 * b - 1);
      };
      patch.periodicA = true;
      patch.outside = [](const Vec3& p) { return Vec3(p.x(), p.y(), 0); };
      addPatch(mesh, patch, n);
      break;
    }
    case ParamShape::Torus: {
      GridPatch patch;
      patch.map = [](double a, double b) {
        const double u = 2 * kPi * a, v = 2 * kPi * b;
        const double r = 1 + 0.35 * std::cos(v);
        return Vec3(r * std::cos(u), r * std::sin(u), 0.35 * std::sin(v));
      };
      patch.periodicA = patch.periodicB = true;
      patch.outside = [](const Vec3& p) {
        const Vec3 ring = Vec3(p.x(), p.y(), 0).normalized();
        return Vec3(p - ring);
      };
      addPatch(mesh, patch, n);
      break;
    }
  }
  return mesh;
}

PointCloud generateParamShape(ParamShape shape, const ParamShapeOptions& options) {
  if (options.pointCount == 0) throw OptionError("ParamShapeOptions::pointCount must be >= 1");
  if (!(options.noise >= 0) || !std::isfinite(options.noise))
    throw OptionError("ParamShapeOptions::noise must be finite and >= 0");
  int resolution = options.resolution;
  if (resolution == 0)
    resolution = int(std::clamp(2.0 * std::sqrt(double(options.pointCount)), 64.0, 1024.0));
  // Closed shapes spread the grid over six faces.
  if (options.resolution == 0 && paramShapeTopology(shape) == ParamTopology::Sphere)
    resolution = std::max(32, resolution / 2);
  const TriangleMesh mesh = paramShapeMesh(shape, resolution);
  PointCloud cloud = sampleMesh(mesh, options.pointCount, options.seed);
  if (options.noise > 0) {
    std::vector<Vec3> positions(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) positions[i] = cloud.absolutePosition(i);
    addPositionNoise(positions, options.noise * cloud.boundingBoxDiagonal(), options.seed + 1);
    std::vector<Vec3> normals = cloud.normals();
    cloud.setAbsolutePositions(positions);
    cloud.setNormals(std::move(normals));
  }
  return cloud;
}

}  // namespace scalespace
