#include "scalespace/core/SceneGenerator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "scalespace/core/Error.hpp"

namespace scalespace {

SceneKind sceneKindFromName(const std::string& name) {
  if (name == "tri") return SceneKind::Tri;
  if (name == "stairs") return SceneKind::Stairs;
  if (name == "cubes") return SceneKind::Cubes;
  if (name == "box") return SceneKind::Box;
  if (name == "house") return SceneKind::House;
  if (name == "yard") return SceneKind::Yard;
  throw OptionError("unknown scene '" + name + "' (use tri, stairs, cubes, box, house or yard)");
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
    case SceneKind::House:
      return "house";
    case SceneKind::Yard:
      return "yard";
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

// Steps climbing along +y from `origin` (the front bottom corner at the lowest x): riser s, then
// tread s, for s = 0..steps-1.
void addSteps(std::vector<SceneFace>& faces, const Vec3& origin, double width, int steps,
              double depth, double rise) {
  for (int s = 0; s < steps; ++s) {
    addParallelogram(newFace(faces, -Vec3::UnitY()), origin + Vec3(0, s * depth, s * rise),
                     Vec3(width, 0, 0), Vec3(0, 0, rise));
    addHorizontalRect(newFace(faces, Vec3::UnitZ()), origin.x(), origin.x() + width,
                      origin.y() + s * depth, origin.y() + (s + 1) * depth,
                      origin.z() + (s + 1) * rise);
  }
}

std::vector<SceneFace> stairsFaces(int steps) {
  // Steps of depth = height = 1/steps along +y, 1 wide: the mean ramp is the 45-degree plane.
  if (steps < 1) throw OptionError("stair steps must be >= 1");
  std::vector<SceneFace> faces;
  const double d = 1.0 / steps;
  addSteps(faces, Vec3::Zero(), 1.0, steps, d, d);
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

// ------------------------------------------------------------------ house and yard (metres)

// A planar frame: points corner + a*u + b*v + h*n, with u, v orthonormal and n = u x v the
// outward normal.
struct Frame {
  Vec3 corner, u, v, n;
  Frame(const Vec3& c, const Vec3& uDir, const Vec3& vDir)
      : corner(c), u(uDir.normalized()), v(vDir.normalized()), n(u.cross(v)) {}
  Vec3 at(double a, double b, double h = 0.0) const { return corner + a * u + b * v + h * n; }
};

// The rectangle [u0,u1] x [v0,v1] in a frame's coordinates.
struct Rect2 {
  double u0, u1, v0, v1;
  bool contains(double a, double b) const { return a > u0 && a < u1 && b > v0 && b < v1; }
};

// `outer` minus the (disjoint) `holes`, appended to `face`: the footprints of what stands on the
// ground or the roof, or the wall's window openings, are hidden or empty, never sampled. The
// rectangle is cut along every hole edge; each row's runs of cells outside the holes are added
// as one parallelogram.
void addRectMinusHoles(SceneFace& face, const Frame& frame, const Rect2& outer,
                       const std::vector<Rect2>& holes) {
  std::vector<double> us{outer.u0, outer.u1}, vs{outer.v0, outer.v1};
  for (const Rect2& h : holes) {
    us.insert(us.end(),
              {std::clamp(h.u0, outer.u0, outer.u1), std::clamp(h.u1, outer.u0, outer.u1)});
    vs.insert(vs.end(),
              {std::clamp(h.v0, outer.v0, outer.v1), std::clamp(h.v1, outer.v0, outer.v1)});
  }
  for (auto* cuts : {&us, &vs}) {
    std::sort(cuts->begin(), cuts->end());
    cuts->erase(std::unique(cuts->begin(), cuts->end()), cuts->end());
  }
  const auto inHole = [&](std::size_t i, std::size_t j) {
    const double a = 0.5 * (us[i] + us[i + 1]), b = 0.5 * (vs[j] + vs[j + 1]);
    return std::any_of(holes.begin(), holes.end(),
                       [&](const Rect2& h) { return h.contains(a, b); });
  };
  for (std::size_t j = 0; j + 1 < vs.size(); ++j)
    for (std::size_t i = 0; i + 1 < us.size();) {
      if (inHole(i, j)) {
        ++i;
        continue;
      }
      std::size_t end = i + 1;
      while (end + 1 < us.size() && !inHole(end, j)) ++end;
      addParallelogram(face, frame.at(us[i], vs[j]), (us[end] - us[i]) * frame.u,
                       (vs[j + 1] - vs[j]) * frame.v);
      i = end;
    }
}

// Rectangle `r` of `frame` moved by `offset` along the frame's normal: offset > 0 raises it (a
// tile on the roof, a box on the ground), offset < 0 recesses it (a window in a wall). Five
// faces: the moved rectangle (normal n) and its four sides joining it to the frame's plane, with
// outward normals (away from the raised solid, into the recess). The frame's own face must leave
// `r` out (addRectMinusHoles).
void addOffsetRect(std::vector<SceneFace>& faces, const Frame& frame, const Rect2& r,
                   double offset) {
  const double s = offset > 0 ? 1.0 : -1.0;
  const Vec3 du = (r.u1 - r.u0) * frame.u, dv = (r.v1 - r.v0) * frame.v, rise = offset * frame.n;
  addParallelogram(newFace(faces, frame.n), frame.at(r.u0, r.v0, offset), du, dv);
  addParallelogram(newFace(faces, -s * frame.u), frame.at(r.u0, r.v0), dv, rise);
  addParallelogram(newFace(faces, s * frame.u), frame.at(r.u1, r.v0), dv, rise);
  addParallelogram(newFace(faces, -s * frame.v), frame.at(r.u0, r.v0), du, rise);
  addParallelogram(newFace(faces, s * frame.v), frame.at(r.u0, r.v1), du, rise);
}

void setGroup(std::vector<SceneFace>& faces, std::size_t first, int group) {
  for (std::size_t f = first; f < faces.size(); ++f) faces[f].group = group;
}

// A free-standing staircase on the ground climbing along +y from `origin`: treads and risers (in
// `group`: together they are the coarse mean ramp), the two stepped side faces and the back face.
// Returns its footprint on the ground.
Rect2 addStaircase(std::vector<SceneFace>& faces, const Vec3& origin, double width, int steps,
                   double depth, double rise, int group) {
  const std::size_t first = faces.size();
  addSteps(faces, origin, width, steps, depth, rise);
  setGroup(faces, first, group);
  for (int side = 0; side < 2; ++side) {
    SceneFace& face = newFace(faces, Vec3(side ? 1 : -1, 0, 0));
    for (int s = 0; s < steps; ++s)
      addParallelogram(face, origin + Vec3(side * width, s * depth, 0), Vec3(0, depth, 0),
                       Vec3(0, 0, (s + 1) * rise));
  }
  addParallelogram(newFace(faces, Vec3::UnitY()), origin + Vec3(0, steps * depth, 0),
                   Vec3(width, 0, 0), Vec3(0, 0, steps * rise));
  return {origin.x(), origin.x() + width, origin.y(), origin.y() + steps * depth};
}

// A wedge on the ground rising along +x from (x0, y0): the slope, the vertical back face and the
// two triangular sides. Returns its footprint.
Rect2 addRamp(std::vector<SceneFace>& faces, double x0, double y0, double length, double width,
              double height) {
  addParallelogram(newFace(faces, Vec3(-height, 0, length)), Vec3(x0, y0, 0),
                   Vec3(length, 0, height), Vec3(0, width, 0));
  addParallelogram(newFace(faces, Vec3::UnitX()), Vec3(x0 + length, y0, 0), Vec3(0, width, 0),
                   Vec3(0, 0, height));
  for (double y : {y0, y0 + width})
    addTriangle(newFace(faces, Vec3(0, y == y0 ? -1 : 1, 0)), Vec3(x0, y, 0),
                Vec3(x0 + length, y, 0), Vec3(x0 + length, y, height));
  return {x0, x0 + length, y0, y0 + width};
}

const Frame kGround(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());

std::vector<SceneFace> houseFaces() {
  // House [x0,x1] x [y0,y1] x [0,wall], ridge along x, `ridge` above the eaves; the staircase
  // stands beside its east wall. Sizes of a detached house: the diagonal is about 18 m, so the
  // 2.5 cm tiles and 6 cm window recesses are about 1e-3 and 3e-3 of it.
  constexpr double x0 = -5.5, x1 = 2.5, y0 = -3, y1 = 3, wall = 3, ridge = 2, recess = 0.06;
  constexpr double tileProud = 0.025, tileU = 0.8, tileV = 0.5;
  constexpr int tilesU = 6, tilesV = 4;
  std::vector<SceneFace> faces;
  const std::size_t groundFace = faces.size();
  newFace(faces, Vec3::UnitZ());
  const Rect2 stairs = addStaircase(faces, Vec3(4.0, -1.5, 0), 1.2, 10, 0.3, 0.18, 1);
  addRectMinusHoles(faces[groundFace], kGround, {-7, 7, -5, 5}, {{x0, x1, y0, y1}, stairs});

  // Walls: u along the wall, v up, so n = u x v points out. Windows 1.2 x 1.2 m, sills at 0.9 m.
  struct Wall {
    Frame frame;
    double length;
    std::vector<double> windowStarts;
    bool gable;  // an end wall: the triangle under the roof is the same plane, the same face
  };
  const Wall walls[] = {
      {Frame(Vec3(x0, y0, 0), Vec3::UnitX(), Vec3::UnitZ()), x1 - x0, {1.0, 3.4, 5.8}, false},
      {Frame(Vec3(x1, y1, 0), -Vec3::UnitX(), Vec3::UnitZ()), x1 - x0, {1.0, 3.4, 5.8}, false},
      {Frame(Vec3(x1, y0, 0), Vec3::UnitY(), Vec3::UnitZ()), y1 - y0, {1.0, 3.8}, true},
      {Frame(Vec3(x0, y1, 0), -Vec3::UnitY(), Vec3::UnitZ()), y1 - y0, {1.0, 3.8}, true}};
  for (const Wall& w : walls) {
    std::vector<Rect2> windows;
    for (double u : w.windowStarts) windows.push_back({u, u + 1.2, 0.9, 2.1});
    const std::size_t wallFace = faces.size();
    newFace(faces, w.frame.n);
    addRectMinusHoles(faces[wallFace], w.frame, {0, w.length, 0, wall}, windows);
    if (w.gable)
      addTriangle(faces[wallFace], w.frame.at(0, wall), w.frame.at(w.length, wall),
                  w.frame.at(w.length / 2, wall + ridge));
    for (const Rect2& r : windows) addOffsetRect(faces, w.frame, r, -recess);
  }

  // Roof sides from the eaves up to the ridge; the -y side carries the tiles (group 0).
  const double slope = std::hypot(y1 - y0, 2 * ridge) / 2;
  const Frame tiled(Vec3(x0, y0, wall), Vec3::UnitX(), Vec3(0, (y1 - y0) / 2, ridge));
  const Frame plain(Vec3(x1, y1, wall), -Vec3::UnitX(), Vec3(0, -(y1 - y0) / 2, ridge));
  const double gapU = (x1 - x0 - tilesU * tileU) / (tilesU + 1);
  const double gapV = (slope - tilesV * tileV) / (tilesV + 1);
  std::vector<Rect2> tiles;
  for (int j = 0; j < tilesV; ++j)
    for (int i = 0; i < tilesU; ++i) {
      const double u = gapU + i * (tileU + gapU), v = gapV + j * (tileV + gapV);
      tiles.push_back({u, u + tileU, v, v + tileV});
    }
  const std::size_t roofFace = faces.size();
  newFace(faces, tiled.n);
  addRectMinusHoles(faces[roofFace], tiled, {0, x1 - x0, 0, slope}, tiles);
  for (const Rect2& r : tiles) addOffsetRect(faces, tiled, r, tileProud);
  setGroup(faces, roofFace, 0);
  addRectMinusHoles(newFace(faces, plain.n), plain, {0, x1 - x0, 0, slope}, {});
  return faces;
}

std::vector<SceneFace> yardFaces() {
  // Things standing on a 10 x 8 m ground: a ramp, a low wall, three boxes, a 4-step staircase.
  std::vector<SceneFace> faces;
  newFace(faces, Vec3::UnitZ());
  std::vector<Rect2> footprints{addRamp(faces, -4, -3.5, 3, 1.5, 0.6),
                                addStaircase(faces, Vec3(3.0, -1.0, 0), 1.0, 4, 0.3, 0.2, 0)};
  const std::pair<Rect2, double> blocks[] = {{{-3, 3, 2.5, 2.75}, 0.8},  // the low wall
                                             {{0, 1, -1, 0}, 0.5},
                                             {{1.8, 2.4, -2.9, -2.3}, 0.6},
                                             {{-2.5, -1.3, -0.5, 0.5}, 0.4}};
  for (const auto& [r, height] : blocks) {
    addOffsetRect(faces, kGround, r, height);
    footprints.push_back(r);
  }
  addRectMinusHoles(faces[0], kGround, {-5, 5, -4, 4}, footprints);
  return faces;
}

}  // namespace

std::vector<std::string> sceneGroupNames(SceneKind kind) {
  if (kind == SceneKind::House) return {"tiled roof side", "staircase ramp"};
  if (kind == SceneKind::Yard) return {"staircase ramp"};
  return {};
}

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
    case SceneKind::House:
      return houseFaces();
    case SceneKind::Yard:
      return yardFaces();
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
  std::vector<double> labels(n), groups(n);
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
    groups[i] = faces[tri.face].group;
  }

  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  cloud.setNormals(std::move(normals));
  cloud.addAttribute("gt_face", ScalarType::Int32).values = std::move(labels);
  if (!sceneGroupNames(kind).empty())
    cloud.addAttribute("gt_group", ScalarType::Int32).values = std::move(groups);
  return cloud;
}

}  // namespace scalespace
