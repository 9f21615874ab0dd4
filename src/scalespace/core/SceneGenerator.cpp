#include "scalespace/core/SceneGenerator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "scalespace/core/Error.hpp"

namespace scalespace {

SceneKind sceneKindFromName(const std::string& name) {
  if (name == "tri") return SceneKind::Tri;
  if (name == "stairs") return SceneKind::Stairs;
  if (name == "cubes") return SceneKind::Cubes;
  if (name == "box") return SceneKind::Box;
  throw OptionError("unknown scene '" + name + "' (use tri, stairs, cubes or box)");
}

const char* sceneKindName(SceneKind kind) {
  switch (kind) {
    case SceneKind::Tri:
      return "tri";
    case SceneKind::Stairs:
      return "stairs";
    case SceneKind::Cubes:
      return "cubes";
    case SceneKind::Box:
      return "box";
  }
  return "unknown";
}

double SceneFace::area() const {
  double a = 0.0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
    a += 0.5 * (triangles[t + 1] - triangles[t]).cross(triangles[t + 2] - triangles[t]).norm();
  return a;
}

namespace {

// Adds the parallelogram {corner + a*u + b*v, a,b in [0,1]} as two triangles.
// Triangles are wound counter-clockwise seen from outside (their cross product is the normal).
void addParallelogram(SceneFace& face, const Vec3& corner, Vec3 u, Vec3 v) {
  if (u.cross(v).dot(face.normal) < 0) std::swap(u, v);
  const Vec3 p0 = corner, p1 = corner + u, p2 = corner + u + v, p3 = corner + v;
  face.triangles.insert(face.triangles.end(), {p0, p1, p2, p0, p2, p3});
}

void addTriangle(SceneFace& face, const Vec3& a, Vec3 b, Vec3 c) {
  if ((b - a).cross(c - a).dot(face.normal) < 0) std::swap(b, c);
  face.triangles.insert(face.triangles.end(), {a, b, c});
}

SceneFace& newFace(std::vector<SceneFace>& faces, const Vec3& normal) {
  SceneFace face;
  face.label = int(faces.size());
  face.normal = normal.normalized();
  faces.push_back(face);
  return faces.back();
}

// Axis-aligned rectangle [x0,x1]x[y0,y1] at height z, appended to `face`.
void addHorizontalRect(SceneFace& face, double x0, double x1, double y0, double y1, double z) {
  addParallelogram(face, Vec3(x0, y0, z), Vec3(x1 - x0, 0, 0), Vec3(0, y1 - y0, 0));
}

// Horizontal ring: the square [-outer,outer]^2 minus [-inner,inner]^2, as four rectangles.
void addHorizontalRing(SceneFace& face, double outer, double inner, double z) {
  addHorizontalRect(face, -outer, outer, -outer, -inner, z);
  addHorizontalRect(face, -outer, outer, inner, outer, z);
  addHorizontalRect(face, -outer, -inner, -inner, inner, z);
  addHorizontalRect(face, inner, outer, -inner, inner, z);
}

// The four vertical sides of the box [-h,h]^2 x [z0,z1], one face each.
void addSides(std::vector<SceneFace>& faces, double h, double z0, double z1) {
  const double height = z1 - z0;
  addParallelogram(newFace(faces, Vec3::UnitX()), Vec3(h, -h, z0), Vec3(0, 2 * h, 0),
                   Vec3(0, 0, height));
  addParallelogram(newFace(faces, -Vec3::UnitX()), Vec3(-h, -h, z0), Vec3(0, 2 * h, 0),
                   Vec3(0, 0, height));
  addParallelogram(newFace(faces, Vec3::UnitY()), Vec3(-h, h, z0), Vec3(2 * h, 0, 0),
                   Vec3(0, 0, height));
  addParallelogram(newFace(faces, -Vec3::UnitY()), Vec3(-h, -h, z0), Vec3(2 * h, 0, 0),
                   Vec3(0, 0, height));
}

std::vector<SceneFace> triFaces() {
  // Ground [-1,1]^2 at z = 0 carrying a prism x in [-0.6,0.6], y in [-0.4,0.4], ridge at z = 0.4:
  // the coarse structure is the ground plane, the details are the two roof slopes and gables.
  std::vector<SceneFace> faces;
  const double hx = 0.6, hy = 0.4, ridge = 0.4;
  SceneFace& ground = newFace(faces, Vec3::UnitZ());
  addHorizontalRect(ground, -1, 1, -1, -hy, 0);
  addHorizontalRect(ground, -1, 1, hy, 1, 0);
  addHorizontalRect(ground, -1, -hx, -hy, hy, 0);
  addHorizontalRect(ground, hx, 1, -hy, hy, 0);
  addParallelogram(newFace(faces, Vec3(0, -ridge, hy)), Vec3(-hx, -hy, 0), Vec3(2 * hx, 0, 0),
                   Vec3(0, hy, ridge));
  addParallelogram(newFace(faces, Vec3(0, ridge, hy)), Vec3(-hx, hy, 0), Vec3(0, -hy, ridge),
                   Vec3(2 * hx, 0, 0));
  for (double sx : {-1.0, 1.0}) {
    SceneFace& gable = newFace(faces, Vec3(sx, 0, 0));
    addTriangle(gable, Vec3(sx * hx, -hy, 0), Vec3(sx * hx, hy, 0), Vec3(sx * hx, 0, ridge));
  }
  return faces;
}

std::vector<SceneFace> stairsFaces(int steps) {
  // Steps of depth = height = 1/steps along +y, 1 wide: the mean ramp is the 45-degree plane.
  if (steps < 1) throw OptionError("stair steps must be >= 1");
  std::vector<SceneFace> faces;
  const double d = 1.0 / steps;
  for (int s = 0; s < steps; ++s) {
    addParallelogram(newFace(faces, -Vec3::UnitY()), Vec3(0, s * d, s * d), Vec3(1, 0, 0),
                     Vec3(0, 0, d));
    addHorizontalRect(newFace(faces, Vec3::UnitZ()), 0, 1, s * d, (s + 1) * d, (s + 1) * d);
  }
  return faces;
}

std::vector<SceneFace> cubesFaces(int levels) {
  // Level l is a cube of edge 2/2^l centred on the top of level l-1 (the base sits on z = 0).
  if (levels < 1) throw OptionError("cube levels must be >= 1");
  std::vector<SceneFace> faces;
  addHorizontalRect(newFace(faces, -Vec3::UnitZ()), -1, 1, -1, 1, 0);
  double z = 0.0, half = 1.0;
  for (int l = 0; l < levels; ++l) {
    addSides(faces, half, z, z + 2 * half);
    z += 2 * half;
    SceneFace& top = newFace(faces, Vec3::UnitZ());
    if (l + 1 < levels)
      addHorizontalRing(top, half, half / 2, z);
    else
      addHorizontalRect(top, -half, half, -half, half, z);
    half /= 2;
  }
  return faces;
}

std::vector<SceneFace> boxFaces(const Vec3& size) {
  if ((size.array() <= 0).any()) throw OptionError("box size must be positive");
  std::vector<SceneFace> faces;
  const Vec3 h = size / 2;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (double sign : {-1.0, 1.0}) {
      Vec3 n = Vec3::Zero();
      n[axis] = sign;
      Vec3 corner = -h;
      corner[axis] = sign * h[axis];
      Vec3 u = Vec3::Zero(), v = Vec3::Zero();
      u[a] = size[a];
      v[b] = size[b];
      addParallelogram(newFace(faces, n), corner, u, v);
    }
  }
  return faces;
}

}  // namespace

std::vector<SceneFace> sceneFaces(SceneKind kind, const SceneOptions& options) {
  switch (kind) {
    case SceneKind::Tri:
      return triFaces();
    case SceneKind::Stairs:
      return stairsFaces(options.stairSteps);
    case SceneKind::Cubes:
      return cubesFaces(options.cubeLevels);
    case SceneKind::Box:
      return boxFaces(options.boxSize);
  }
  return {};
}

PointCloud generateScene(SceneKind kind, const SceneOptions& options) {
  if (options.noise < 0)
    throw OptionError("SceneOptions::noise must be >= 0 (fraction of the diagonal)");
  const std::vector<SceneFace> faces = sceneFaces(kind, options);

  // Cumulative triangle areas: drawing u in [0, total) and locating it picks a triangle with
  // probability proportional to its area, so the samples are uniform by area over the scene.
  struct Tri {
    Vec3 a, b, c;
    int face;
  };
  std::vector<Tri> tris;
  std::vector<double> cumulative;
  double total = 0.0;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (std::size_t t = 0; t + 2 < faces[f].triangles.size(); t += 3) {
      const Tri tri{faces[f].triangles[t], faces[f].triangles[t + 1], faces[f].triangles[t + 2],
                    int(f)};
      total += 0.5 * (tri.b - tri.a).cross(tri.c - tri.a).norm();
      cumulative.push_back(total);
      tris.push_back(tri);
      for (const Vec3& p : {tri.a, tri.b, tri.c}) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
  const double sigma = options.noise * (hi - lo).norm();

  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, sigma > 0 ? sigma : 1.0);
  const std::size_t n = options.pointCount;
  std::vector<Vec3> positions(n), normals(n);
  std::vector<double> labels(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = uniform(rng) * total;
    std::size_t t =
        std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin());
    t = std::min(t, tris.size() - 1);
    double r1 = uniform(rng), r2 = uniform(rng);
    if (r1 + r2 > 1.0) {  // reflect into the triangle: uniform barycentric coordinates
      r1 = 1.0 - r1;
      r2 = 1.0 - r2;
    }
    const Tri& tri = tris[t];
    Vec3 p = tri.a + r1 * (tri.b - tri.a) + r2 * (tri.c - tri.a);
    if (sigma > 0) p += Vec3(gauss(rng), gauss(rng), gauss(rng));
    positions[i] = p;
    normals[i] = faces[tri.face].normal;
    labels[i] = faces[tri.face].label;
  }

  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  cloud.setNormals(std::move(normals));
  cloud.addAttribute("gt_face", ScalarType::Int32).values = std::move(labels);
  return cloud;
}

}  // namespace scalespace
