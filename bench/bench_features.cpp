// Feature-curve detection (Sec. 3.4.1) against ground truth from triangle meshes: ours
// (detectFeatureCurves with the default FeatureCurveOptions), CGAL's VCM sharp edges and a
// covariance threshold, on clean points and on a noisy copy, in the same run.
//
//   bench_features [--points N (100000)] [--data DIR (/tmp/real/cgal/data/meshes)]
//                  [--models a,b,c] [--clean-only | --noise-only] [--angle DEG (30)] [--no-peers]
//                  [--salient X] [--vote-threshold X] [--min-curvature X] [--min-scales N]
//                  [--vote-radius X] [--all-salient] [--noise-curvature X] [--join-gap X]
//                  [--bound-cap X] (FeatureCurveOptions::salientBoundCap)
//                  [--min-piece-extent X] [--min-extent X] (FeatureCurveOptions::
//                  minPieceExtent, minCurveExtent)
//                  [--bound-per-scale] [--random-seed-order] [--robust-fit] [--across-weight X]
//                  [--no-visibility] [--sheet-normals X (0.05; 0: PCA)] [--sign-from-pca]
//                  (SheetSign::FromPlanes: the sheet normals take the oriented PCA normals' sign)
//                  [--own-tree-sign] (SheetSign::OwnTree: the sheet normals' own tree; the
//                  default is `features`' SheetSign::ByRays: both, the one the rays find facing
//                  inward at fewer points kept)
//                  [--reflect | --no-reflect] (NormalOrientationOptions::reflectAcrossBisector;
//                  default: featureNormalOptions()')
//                  (NormalOrientationOptions::acrossWeight and ::visibility of the estimated
//                  normals)
//                  [--mesh-normals] (the clean and noisy clouds take the mesh's interpolated
//                  normals)
//                  [--fold-borders auto|on|off] [--fold-share X] [--fold-reach X]
//                  (FeatureCurveOptions::foldBorders, auto: chooseFoldBorders,
//                  as `features`; foldBorderShare, foldReach)
//                  [--centreline-reach X]
//                  [--band-half-width X] [--centreline-linearity X]
//                  [--crease-reach X (0: off)] [--crease-half-width X] [--crease-flatness X]
//                  (FeatureCurveOptions::creaseReach, creaseHalfWidth, creaseFlatness)
//                  [--no-rim-lines] (FeatureCurveOptions::rimLines off)
//                  [--max-turn DEG] [--collision X] [--beta X] [--border-offset X] [--curvature-gap
//                  X] (CurvatureLineOptions: curvedSeedsFirst off, maxTurnDegrees,
//                  collisionFraction, beta, borderOffset, minCurvatureGap)
//                  [--per-curve] (per model: each ground-truth curve's share labelled and
//                  pieces, and how far from the sharp edges the false positives lie; for ours,
//                  why a missed curve is missed: per scale the line vertices near it, their
//                  |kappa1| t against the salient bound, the salient vertices kept; the share of
//                  its points passing the vote threshold and the minimum count of scales;
//                  where the lines near it stop: per scale its runs of >= 3 line vertices within
//                  e and how each ended, the stop reasons of the ends of the lines within e, the
//                  seeds within e and why those that started no line did not, the field at its
//                  points with no line vertex within e; how far the nearest other curve runs)
//                  (FeatureCurveOptions of ours; the library's defaults otherwise)
//
// Models: CAD meshes read from DIR (fandisk, blade, anchor, rotor, joint, part, anchor_dense,
// fandisk_large: Debian's libcgal-demo data; a missing file is skipped with a line saying so) and
// three built here: "box" (a box whose four long edges are a chamfer and fillets of radii 1, 2 and
// 4 e: fillets are smooth on the mesh, so they are not ground truth and count against a method that
// flags them), "creases" (a prism whose top is a zigzag with convex and concave creases whose face
// normals turn by 30 to 150 degrees) and "box_on_ground" (a box standing on an open ground square:
// its footprint is a concave curve; the ground's outer border is not a feature).
// Ground truth:
// - sharp edges: mesh edges between two faces whose normals differ by >= --angle degrees, convex
//   or concave (from the outward orientation; a closed mesh with negative volume is flipped);
// - points: N points drawn by area (sampleMesh), their normals dropped, then estimated and
//   oriented as the CLI does for inputs without normals (PCA 10-NN, MST); the noisy copy adds
//   Gaussian noise of sigma 1e-3 of the bounding-box diagonal to each coordinate and estimates
//   its own normals;
// - a point is a feature point when its noise-free position lies within e of a sharp edge (not of
//   a fold, below), e the mean distance to the 16th nearest neighbour on the clean points;
// - curves: sharp edges of the same sign sharing a mesh vertex (union-find), each feature point
//   on the curve of its nearest sharp edge; the per-curve figures score the curves at least 2 e
//   long (as the edges below) that are not folds (all within e of a longer curve of the other
//   sign: the zigzag of a fine triangulation along a crease, scoredCurve); the header line says
//   how many.
// Methods: "ours" labels the points with curveId >= 0 (its curves are the detected curves); "vcm
// R/r" is CGAL::compute_vcm with offset radius R and convolution radius r (multiples of e), points
// labelled by vcm_is_on_feature_edge at 0.16; "cov X" labels the points whose surface variation
// lambda0 / (lambda0 + lambda1 + lambda2) over the 16 nearest neighbours (the point included)
// exceeds X. A peer's curves are the connected components of its labelled points on the 10-NN
// graph.
// Metrics: point-wise precision, recall, MCC; Dice 2|A n B| / (|A| + |B|) (Eq. 3.4) and the
// symmetric Hausdorff distance (Eq. 3.3) between the feature points and the labelled points over
// the diagonal (distances between noise-free positions); per curve: each ground-truth curve is
// matched with the detected curve that holds most of its points; cDice and cH/diag are the means
// over ground-truth curves (cH over the matched ones), cRec the fraction of ground-truth curves
// whose match covers >= 50 % of their points; per edge the same against the mesh's edges (runs of a
// curve's sharp edges through the vertices where exactly two of one sign meet, turning by less
// than 30 degrees) and the detected edges (ours' FeatureCurveResult::edgeId; a peer's edges are
// its curves): edges, eDice, eRec. Seconds: the method on a cloud with normals (the
// peers' 10-NN graph included; settings of one peer that share a computation each report it).
// The whole run (11 models, both noise levels) took about 17 min on 2 shared cores, 13 of them in
// CGAL's VCM (about 11 s per setting and cloud of 100k points: its offset step, which r does not
// change); ours about 1 s per cloud; --no-peers runs in under a minute.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/vcm_estimate_edges.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/features/FeatureCurves.hpp"
#include "scalespace/fit/FitPoints.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"

using namespace scalespace;
using Clock = std::chrono::steady_clock;
using Vec2 = Eigen::Vector2d;
using Triangle = std::array<Index, 3>;

namespace {

constexpr int kSpacingNeighbors = 16;            // e: mean distance to the 16th nearest neighbour
constexpr std::size_t kPeerGraphNeighbors = 10;  // the peers' curves: components on the 10-NN graph
constexpr std::size_t kCovarianceNeighbors = 16;
constexpr double kNoise = 1e-3;           // sigma over the bounding-box diagonal
constexpr double kCurveCovered = 0.5;     // cRec: the match covers >= 50 % of the curve
constexpr double kVcmThreshold = 0.16;    // CGAL's example value
constexpr double kAngleTolerance = 1e-6;  // degrees: creases built at exactly --angle count
// Ground-truth edges: a curve's run turning by more than kEdgeTurnDegrees over kEdgeReach spacings
// on each side of a vertex ends there; runs shorter than kEdgeReach spacings are corners, not
// scored, nor are the runs of a fold (scoredCurve).
constexpr double kEdgeTurnDegrees = 30, kEdgeReach = 2;
constexpr std::uint64_t kSampleSeed = 1, kNoiseSeed = 2;

const char* const kCadModels[] = {"fandisk", "blade", "anchor",       "rotor",
                                  "joint",   "part",  "anchor_dense", "fandisk_large"};
const char* const kOwnModels[] = {"box", "creases", "box_on_ground"};

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// ---------------------------------------------------------------------------------------------
// Shapes of our own. They are built with their spacing in mind: e ~ sqrt(16 A / (pi N)) for N
// points on an area A, the mean 16-NN distance of a uniform sample, so that fillet radii are a
// given number of spacings whatever --points.

double expectedSpacing(double area, std::size_t points) {
  return std::sqrt(kSpacingNeighbors * area / (kPi * double(points)));
}

// `profile` (counter-clockwise in the xy-plane) extruded over z in [0, length], the caps made of
// `cap` (counter-clockwise triangles of profile indices); faces oriented outwards.
TriangleMesh extrude(const std::vector<Vec2>& profile, const std::vector<Triangle>& cap,
                     double length) {
  TriangleMesh mesh;
  const Index n = Index(profile.size());
  for (double z : {0.0, length})
    for (const Vec2& p : profile) mesh.vertices.emplace_back(p.x(), p.y(), z);
  for (const Triangle& t : cap) {
    mesh.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});  // z = length, facing +z
    mesh.triangles.push_back({t[0], t[2], t[1]});              // z = 0, facing -z
  }
  // Side quad i: (d, 0) x (d, length) = length (d.y, -d.x): the right of a counter-clockwise
  // profile, outwards.
  for (Index i = 0; i < n; ++i) {
    const Index j = (i + 1) % n;
    mesh.triangles.push_back({i, j, j + n});
    mesh.triangles.push_back({i, j + n, i + n});
  }
  return mesh;
}

struct Corner {
  enum Kind { Sharp, Chamfer, Fillet } kind = Sharp;
  double size = 0;  // chamfer: cut along each side; fillet: radius
};

// The rectangle [0, w] x [0, h], counter-clockwise from (0, 0), with its corners cut.
std::vector<Vec2> cutRectangle(double w, double h, const std::array<Corner, 4>& corners) {
  const std::array<Vec2, 4> p{Vec2(0, 0), Vec2(w, 0), Vec2(w, h), Vec2(0, h)};
  constexpr int kFilletSegments = 12;  // 7.5 degrees per facet: smooth for any --angle above it
  std::vector<Vec2> out;
  for (int k = 0; k < 4; ++k) {
    const Vec2 in = (p[k] - p[(k + 3) % 4]).normalized(),
               next = (p[(k + 1) % 4] - p[k]).normalized();
    const double s = corners[k].size;
    switch (corners[k].kind) {
      case Corner::Sharp:
        out.push_back(p[k]);
        break;
      case Corner::Chamfer:
        out.push_back(p[k] - s * in);
        out.push_back(p[k] + s * next);
        break;
      case Corner::Fillet: {
        const Vec2 start = p[k] - s * in, centre = start + s * Vec2(-in.y(), in.x());
        for (int i = 0; i <= kFilletSegments; ++i) {
          const double a = 0.5 * kPi * i / kFilletSegments;  // counter-clockwise quarter turn
          const Vec2 r = start - centre;
          out.push_back(centre + Vec2(std::cos(a) * r.x() - std::sin(a) * r.y(),
                                      std::sin(a) * r.x() + std::cos(a) * r.y()));
        }
        break;
      }
    }
  }
  return out;
}

std::vector<Triangle> convexFan(std::size_t n) {
  std::vector<Triangle> fan;
  for (Index i = 1; i + 1 < n; ++i) fan.push_back({0, i, i + 1});
  return fan;
}

TriangleMesh makeBox(std::size_t points) {
  const double w = 1.0, h = 0.6, length = 0.8;
  const double e = expectedSpacing(2 * (w * h + w * length + h * length), points);
  const std::array<Corner, 4> corners{Corner{Corner::Chamfer, 2 * e}, Corner{Corner::Fillet, e},
                                      Corner{Corner::Fillet, 2 * e}, Corner{Corner::Fillet, 4 * e}};
  const std::vector<Vec2> profile = cutRectangle(w, h, corners);
  return extrude(profile, convexFan(profile.size()), length);
}

// A prism over a flat base whose top is a polyline of equal segments at the given slopes
// (degrees): each change of slope is a crease whose normals turn by that difference, concave when
// the slope increases. The cap is the strips between the top vertices and their feet.
TriangleMesh makeCreases() {
  const std::vector<double> slopes{0,   30, 0,   60,  0,  -45, 45,
                                   -45, 75, -45, -75, 75, -75, 0};  // |turns|: 30 to 150
  const double segment = 0.2, base = 0.25, length = 0.8;
  std::vector<Vec2> top{Vec2(0, base)};
  for (double s : slopes)
    top.push_back(top.back() + segment * Vec2(std::cos(s * kPi / 180), std::sin(s * kPi / 180)));
  const Index m = Index(top.size());
  std::vector<Vec2> profile;  // feet left to right, then the top right to left
  for (const Vec2& t : top) profile.emplace_back(t.x(), 0);
  for (Index i = m; i-- > 0;) profile.push_back(top[i]);
  std::vector<Triangle> cap;
  const auto foot = [](Index i) { return i; };
  const auto head = [m](Index i) { return 2 * m - 1 - i; };
  for (Index i = 0; i + 1 < m; ++i) {
    cap.push_back({foot(i), foot(i + 1), head(i + 1)});
    cap.push_back({foot(i), head(i + 1), head(i)});
  }
  return extrude(profile, cap, length);
}

// A box (no bottom) standing on the ground square [-1, 1]^2 with a hole at its footprint: the
// footprint edges join ground and walls (a concave curve); the ground's border is open.
TriangleMesh makeBoxOnGround() {
  const double hx = 0.3, hy = 0.2, height = 0.4;
  TriangleMesh mesh;
  const std::array<Vec2, 4> square{Vec2(-1, -1), Vec2(1, -1), Vec2(1, 1), Vec2(-1, 1)};
  for (const Vec2& s : square) mesh.vertices.emplace_back(s.x(), s.y(), 0);  // 0-3: ground
  for (double z : {0.0, height})                                             // 4-7, 8-11
    for (const Vec2& s : square) mesh.vertices.emplace_back(hx * s.x(), hy * s.y(), z);
  for (Index i = 0; i < 4; ++i) {
    const Index j = (i + 1) % 4;
    mesh.triangles.push_back({i, j, 4 + j});  // ground ring, facing +z
    mesh.triangles.push_back({i, 4 + j, 4 + i});
    mesh.triangles.push_back({4 + i, 4 + j, 8 + j});  // wall, facing outwards
    mesh.triangles.push_back({4 + i, 8 + j, 8 + i});
  }
  mesh.triangles.push_back({8, 9, 10});
  mesh.triangles.push_back({8, 10, 11});
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Ground truth.

struct DisjointSets {
  std::vector<Index> parent;
  explicit DisjointSets(std::size_t n) : parent(n) {
    for (std::size_t i = 0; i < n; ++i) parent[i] = Index(i);
  }
  Index find(Index i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(Index a, Index b) { parent[find(a)] = find(b); }
};

struct SharpEdge {
  Index a = 0, b = 0;
  int sign = 0;  // +1 convex, -1 concave
  int curve = -1;
  int edge = -1;  // the straight or smoothly turning run of the curve it is on
};

struct MeshEdges {
  std::vector<SharpEdge> sharp;
  int curves = 0;
  int edges = 0;
  std::vector<double> edgeLength;   // per edge
  std::vector<int> edgeCurve;       // per edge: its curve
  std::vector<double> curveLength;  // per curve
  std::vector<bool> curveFold;      // per curve: a fold of the triangulation (findSharpEdges)
  std::size_t convex = 0, concave = 0;
  std::size_t border = 0, nonManifold = 0,
              inconsistent = 0;                      // edges with 1, > 2 faces; bad winding
  std::vector<std::pair<Index, Index>> borderEdges;  // --per-curve: false positives near them
  bool flipped = false;
};

Vec3 faceNormal(const TriangleMesh& mesh, const Triangle& t) {
  return (mesh.vertices[t[1]] - mesh.vertices[t[0]])
      .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
}

// Six times the signed volume: positive for a closed mesh whose faces point outwards.
double orientedVolume(const TriangleMesh& mesh) {
  double v = 0;
  for (const Triangle& t : mesh.triangles)
    v += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return v;
}

// +1 when the face runs a -> b, -1 when b -> a.
int direction(const Triangle& t, Index a, Index b) {
  for (int k = 0; k < 3; ++k)
    if (t[k] == a) return t[(k + 1) % 3] == b ? 1 : -1;
  return 0;
}

Index opposite(const Triangle& t, Index a, Index b) {
  for (Index v : t)
    if (v != a && v != b) return v;
  return a;
}

double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Sharp edges (normals turning by >= angleDegrees) with their sign, grouped into curves.
MeshEdges findSharpEdges(const TriangleMesh& mesh, double angleDegrees, double spacing) {
  std::unordered_map<std::uint64_t, std::vector<Index>> faces;  // edge (lo, hi) -> faces
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index a = mesh.triangles[f][k], b = mesh.triangles[f][(k + 1) % 3];
      faces[(std::uint64_t(std::min(a, b)) << 32) | std::max(a, b)].push_back(Index(f));
    }
  MeshEdges out;
  bool closed = true;
  for (const auto& [key, list] : faces) closed = closed && list.size() == 2;
  out.flipped = closed && orientedVolume(mesh) < 0;
  const double cosLimit = std::cos((angleDegrees - kAngleTolerance) * kPi / 180);
  for (const auto& [key, list] : faces) {
    if (list.size() != 2) {
      ++(list.size() == 1 ? out.border : out.nonManifold);
      if (list.size() == 1)
        out.borderEdges.emplace_back(Index(key >> 32), Index(key & 0xffffffffu));
      continue;
    }
    const Index a = Index(key >> 32), b = Index(key & 0xffffffffu);
    const Triangle &f1 = mesh.triangles[list[0]], &f2 = mesh.triangles[list[1]];
    const Vec3 n1 = faceNormal(mesh, f1), n2 = faceNormal(mesh, f2);
    if (n1.norm() == 0 || n2.norm() == 0) continue;  // degenerate face: no angle
    if (n1.normalized().dot(n2.normalized()) > cosLimit) continue;
    if (direction(f1, a, b) == direction(f2, a, b)) ++out.inconsistent;
    // Convex when the other face bends below the plane of the first (outward normals).
    const double side = n1.dot(mesh.vertices[opposite(f2, a, b)] - mesh.vertices[a]);
    SharpEdge edge{a, b, (side < 0) != out.flipped ? 1 : -1, -1};
    ++(edge.sign > 0 ? out.convex : out.concave);
    out.sharp.push_back(edge);
  }
  // Same-sign edges sharing a vertex form one curve: one union-find per sign.
  for (int sign : {1, -1}) {
    DisjointSets sets(mesh.vertices.size());
    for (const SharpEdge& e : out.sharp)
      if (e.sign == sign) sets.unite(e.a, e.b);
    std::map<Index, int> curveOfRoot;
    for (SharpEdge& e : out.sharp)
      if (e.sign == sign) {
        const auto [it, added] = curveOfRoot.emplace(sets.find(e.a), out.curves);
        out.curves += added;
        e.curve = it->second;
      }
  }
  // Edges: a curve's sharp edges chained through the vertices where exactly two sharp edges meet,
  // of the same sign, where the chain's chords over kEdgeReach spacings on each side turn by less
  // than kEdgeTurnDegrees (a finely tessellated arc is one edge; a fillet of a few spacings, as
  // the samples see it, is a corner; a box's corner, where three meet, ends three).
  std::vector<std::vector<Index>> atVertex(mesh.vertices.size());
  for (std::size_t k = 0; k < out.sharp.size(); ++k) {
    atVertex[out.sharp[k].a].push_back(Index(k));
    atVertex[out.sharp[k].b].push_back(Index(k));
  }
  const auto other = [&](Index edge, Index v) {
    return out.sharp[edge].a == v ? out.sharp[edge].b : out.sharp[edge].a;
  };
  // The vertex reached from v along `edge`, on along the chain until kEdgeReach e away or its end.
  const auto reach = [&](Index v, Index edge) {
    const Vec3 start = mesh.vertices[v];
    Index at = other(edge, v);
    for (std::size_t steps = 0; steps < out.sharp.size(); ++steps) {
      if ((mesh.vertices[at] - start).norm() >= kEdgeReach * spacing || atVertex[at].size() != 2)
        break;
      edge = atVertex[at][0] == edge ? atVertex[at][1] : atVertex[at][0];
      const Index next = other(edge, at);
      if (next == v) break;  // a closed loop
      at = next;
    }
    return mesh.vertices[at];
  };
  DisjointSets runs(out.sharp.size());
  const double turnLimit = std::cos(kEdgeTurnDegrees * kPi / 180);
  for (std::size_t v = 0; v < atVertex.size(); ++v) {
    if (atVertex[v].size() != 2) continue;
    const Index e1 = atVertex[v][0], e2 = atVertex[v][1];
    if (out.sharp[e1].sign != out.sharp[e2].sign) continue;
    const Vec3 in = mesh.vertices[v] - reach(Index(v), e1);
    const Vec3 onward = reach(Index(v), e2) - mesh.vertices[v];
    if (in.norm() > 0 && onward.norm() > 0 && in.normalized().dot(onward.normalized()) > turnLimit)
      runs.unite(e1, e2);
  }
  std::map<Index, int> edgeOfRoot;
  for (std::size_t k = 0; k < out.sharp.size(); ++k) {
    const auto [it, added] = edgeOfRoot.emplace(runs.find(Index(k)), out.edges);
    out.edges += added;
    out.sharp[k].edge = it->second;
  }
  out.edgeLength.assign(std::size_t(out.edges), 0.0);
  out.curveLength.assign(std::size_t(out.curves), 0.0);
  out.edgeCurve.assign(std::size_t(out.edges), -1);
  for (const SharpEdge& e : out.sharp) {
    out.edgeCurve[std::size_t(e.edge)] = e.curve;
    const double length = (mesh.vertices[e.a] - mesh.vertices[e.b]).norm();
    out.edgeLength[std::size_t(e.edge)] += length;
    out.curveLength[std::size_t(e.curve)] += length;
  }
  // A fold: a curve whose every edge lies within e of a longer curve of the other sign.
  out.curveFold.assign(std::size_t(out.curves), true);
  for (const SharpEdge& e : out.sharp) {
    const std::size_t c = std::size_t(e.curve);
    if (!out.curveFold[c]) continue;
    const Vec3 middle = 0.5 * (mesh.vertices[e.a] + mesh.vertices[e.b]);
    const double length = out.curveLength[c];
    out.curveFold[c] = std::any_of(out.sharp.begin(), out.sharp.end(), [&](const SharpEdge& o) {
      return o.sign != e.sign && out.curveLength[std::size_t(o.curve)] > length &&
             segmentDistance(middle, mesh.vertices[o.a], mesh.vertices[o.b]) <= spacing;
    });
  }
  return out;
}

// Per point, the curve (or, with `byEdge`, the edge) of its nearest sharp edge (folds left out)
// when that edge lies within `radius`, else -1. Each edge queries balls along itself (pieces <= 2
// radius long) rather than one ball around it: a long edge would otherwise visit most of the
// cloud.
std::vector<int> featureCurveOfPoints(const std::vector<Vec3>& positions, const SpatialIndex& index,
                                      const TriangleMesh& mesh, const Vec3& origin,
                                      const MeshEdges& edges, double radius, bool byEdge = false) {
  std::vector<int> curve(positions.size(), -1);
  std::vector<double> best(positions.size(), radius);
  std::vector<Neighbor> found;
  for (const SharpEdge& e : edges.sharp) {
    if (edges.curveFold[std::size_t(e.curve)]) continue;  // no crease of the shape (scoredCurve)
    const Vec3 a = mesh.vertices[e.a] - origin, b = mesh.vertices[e.b] - origin;
    const double length = (b - a).norm();
    const int pieces = std::max(1, int(std::ceil(length / (2 * radius))));
    for (int k = 0; k < pieces; ++k) {
      const Vec3 centre = a + (b - a) * ((k + 0.5) / pieces);
      index.radiusSearch(centre, 0.5 * length / pieces + radius, found);
      for (const Neighbor& n : found) {
        const double d = segmentDistance(positions[n.index], a, b);
        if (d <= best[n.index]) best[n.index] = d, curve[n.index] = byEdge ? e.edge : e.curve;
      }
    }
  }
  return curve;
}

// ---------------------------------------------------------------------------------------------
// Clouds.

double acrossWeight = NormalOrientationOptions{}.acrossWeight;  // --across-weight
double sheetNormals = 0.05;  // --sheet-normals, as `scalespace features` (kFeatureSheetNormals)
bool visibility = NormalOrientationOptions{}.visibility;  // --no-visibility
// --reflect / --no-reflect (NormalOrientationOptions::reflectAcrossBisector)
bool reflect = featureNormalOptions().orientation.reflectAcrossBisector;
// As `features` (featureNormalOptions(): ByRays); --sign-from-pca: FromPlanes; --own-tree-sign:
// OwnTree (before 2026-11-30).
SheetSign sheetSign = featureNormalOptions().sheetSign;

bool printPerCurve = false;  // --per-curve
// --fold-borders auto|on|off (FeatureCurveOptions::foldBorders; auto: as `features`,
// chooseFoldBorders).
enum class FoldBorders { Auto, On, Off };
FoldBorders foldBorders = FoldBorders::Auto;

// As the CLI does for an input without normals (cli/CliCommon.cpp, ensureNormals); returns
// what the orientation's rays found (closed, open share), for `auto`'s fold borders.
NormalOrientationResult estimateSceneNormals(PointCloud& cloud) {
  auto index = makeSpatialIndex(cloud.positions());
  OrientedNormalsOptions options = featureNormalOptions(sheetNormals);
  options.orientation.acrossWeight = acrossWeight;
  options.orientation.visibility = visibility;
  options.orientation.reflectAcrossBisector = reflect;
  options.sheetSign = sheetSign;
  OrientedNormals normals = estimateOrientedNormals(cloud.positions(), *index, options);
  if (sheetSign == SheetSign::ByRays && printPerCurve)
    std::printf(
        "# signs by the rays: differing at %zu points, inward own tree %zu, PCA signs %zu of "
        "%zu: kept %s\n",
        normals.rays.differing, normals.rays.firstInward, normals.rays.secondInward,
        normals.rays.sampled, normals.signSource == SheetSign::OwnTree ? "own tree" : "PCA signs");
  if (printPerCurve)
    std::printf(
        "# orientation: k %zu, %zu components, %zu pieces, %zu closed, closed surface %s, open "
        "share %.3f\n",
        normals.estimation.k, normals.orientation.componentCount, normals.orientation.pieceCount,
        normals.orientation.closedComponents, normals.orientation.closedSurface ? "yes" : "no",
        normals.orientation.openShare);
  cloud.setNormals(std::move(normals.normals));
  return normals.orientation;
}

PointCloud noisyCopy(const PointCloud& clean, double sigma) {
  std::mt19937_64 rng(kNoiseSeed);
  std::normal_distribution<double> gauss(0.0, sigma);
  std::vector<Vec3> moved = clean.positions();
  for (Vec3& p : moved)
    for (int c = 0; c < 3; ++c) p[c] += gauss(rng);
  PointCloud noisy;
  noisy.setRelativePositions(std::move(moved), clean.origin());
  return noisy;
}

bool meshNormals = false;  // --mesh-normals
FeatureCurveOptions ourOptions;
// --per-curve: ours' last result, for the reasons a curve is missed.
std::unique_ptr<FeatureCurveResult> lastOurs;
const PointCloud* lastCloud = nullptr;  // the cloud ours ran on

struct Model {
  std::string name;
  TriangleMesh mesh;
  NormalOrientationResult cleanRays;  // what the rays found on the clean cloud
  PointCloud clean;                   // with estimated normals
  std::vector<Vec3> meshNormals;      // of the samples, interpolated from the mesh
  std::vector<int> gt;                // per point: ground-truth curve or -1
  std::vector<int> gtEdge;            // per point: ground-truth edge or -1 (where gt is not)
  std::vector<int> gt2,
      gt3;               // the same within 2 e and 3 e (--per-curve: where false positives lie)
  int gtCurves = 0;      // curves with at least one point
  int scoredCurves = 0;  // of those, the ones at least kEdgeReach e long (scoredCurve)
  MeshEdges edges;
  double spacing = 0, diagonal = 0;
};

/// Whether a ground-truth curve is scored per curve (its points stay feature points either way):
/// - like an edge (scoreEdges), one shorter than kEdgeReach spacings is below what scales of e to
///   3 e resolve;
/// - a fold is not a crease of the shape but of its triangulation: a finely tessellated mesh
///   zigzags along a crease, and the short runs of the other sign it leaves lie within e of the
///   crease all along, a step no sampling at spacing e can see. On libcgal-demo's fandisk_large
///   254 of 273 curves are under 2 e and 6 more are folds; anchor_dense, anchor retessellated,
///   has 21 curves, of which 1 is under 2 e and 4 are folds: the 16 left are anchor's 16, of the
///   same lengths.
bool scoredCurve(const Model& m, std::size_t curve) {
  return m.edges.curveLength[curve] >= kEdgeReach * m.spacing && !m.edges.curveFold[curve];
}

/// --per-curve: where the estimated orientation disagrees with the mesh's (outward where the mesh
/// is closed and consistently oriented; on an open mesh either side).
void printOrientation(const Model& m, const std::vector<Vec3>& estimated, const char* which) {
  std::size_t flipped = 0;
  for (std::size_t i = 0; i < m.meshNormals.size(); ++i)
    flipped += m.meshNormals[i].dot(estimated[i]) < 0;
  const double share = double(flipped) / double(std::max<std::size_t>(1, m.meshNormals.size()));
  std::printf("# %s, %s: estimated normals opposite to the mesh's at %.1f %% of the points",
              m.name.c_str(), which, 100 * std::min(share, 1 - share));
  // Where: among the feature points (within e of a sharp edge) or elsewhere.
  if (m.gt.size() == m.meshNormals.size()) {
    std::size_t onFeature = 0, features = 0;
    for (std::size_t i = 0; i < m.gt.size(); ++i) {
      if (m.gt[i] < 0) continue;
      ++features;
      onFeature += (m.meshNormals[i].dot(estimated[i]) < 0) != (2 * flipped > m.gt.size());
    }
    std::printf(" (%zu of the %zu feature points)", onFeature, features);
  }
  std::printf("\n");
}

Model prepareModel(std::string name, TriangleMesh mesh, std::size_t points, double angle) {
  Model m;
  m.name = std::move(name);
  m.mesh = std::move(mesh);
  m.clean = sampleMesh(m.mesh, points, kSampleSeed);
  const std::vector<Vec3> truth = m.clean.normals();
  m.clean.setNormals({});  // drop the mesh's normals: the methods see a raw scan
  m.cleanRays = estimateSceneNormals(m.clean);
  const std::vector<Vec3> estimated = m.clean.normals();
  m.meshNormals = truth;
  if (meshNormals) m.clean.setNormals(truth);  // a diagnostic: the orientation out of the way
  m.diagonal = m.clean.boundingBoxDiagonal();
  m.spacing = meanKthNeighborDistance(m.clean.positions(), kSpacingNeighbors);  // ours' default
  m.edges = findSharpEdges(m.mesh, angle, m.spacing);
  const auto index = makeSpatialIndex(m.clean.positions());
  m.gtEdge = featureCurveOfPoints(m.clean.positions(), *index, m.mesh, m.clean.origin(), m.edges,
                                  m.spacing, true);
  // The curve of each point's edge (the same nearest sharp edge either way).
  std::map<int, int> curveOfEdge;
  for (const SharpEdge& e : m.edges.sharp) curveOfEdge[e.edge] = e.curve;
  m.gt.resize(m.gtEdge.size());
  for (std::size_t i = 0; i < m.gtEdge.size(); ++i)
    m.gt[i] = m.gtEdge[i] < 0 ? -1 : curveOfEdge.at(m.gtEdge[i]);
  if (printPerCurve) printOrientation(m, estimated, "clean");
  if (printPerCurve) {
    m.gt2 = featureCurveOfPoints(m.clean.positions(), *index, m.mesh, m.clean.origin(), m.edges,
                                 2 * m.spacing);
    m.gt3 = featureCurveOfPoints(m.clean.positions(), *index, m.mesh, m.clean.origin(), m.edges,
                                 3 * m.spacing);
  }
  std::vector<bool> used(std::size_t(m.edges.curves), false);
  for (int c : m.gt)
    if (c >= 0) used[std::size_t(c)] = true;
  m.gtCurves = int(std::count(used.begin(), used.end(), true));
  for (std::size_t c = 0; c < used.size(); ++c) m.scoredCurves += used[c] && scoredCurve(m, c);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Metrics.

std::unique_ptr<SpatialIndex> indexOf(const std::vector<Index>& set,
                                      const std::vector<Vec3>& positions) {
  std::vector<Vec3> p;
  p.reserve(set.size());
  for (Index i : set) p.push_back(positions[i]);
  return makeSpatialIndex(p);
}

// max over `from` of the distance to the nearest point of the set indexed by `to`. In parallel:
// a peer's giant component is matched by every ground-truth curve of a CAD model.
double directedHausdorff(const std::vector<Index>& from, const SpatialIndex& to,
                         const std::vector<Vec3>& positions) {
  const double worst = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, from.size(), 1024), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double w) {
        std::vector<Neighbor> nearest;
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          to.knnSearch(positions[from[k]], 1, nearest);
          w = std::max(w, nearest.front().distSq);
        }
        return w;
      },
      [](double a, double b) { return std::max(a, b); });
  return std::sqrt(worst);
}

double hausdorff(const std::vector<Index>& a, const std::vector<Index>& b,
                 const std::vector<Vec3>& positions) {
  if (a.empty() || b.empty()) return NAN;
  return std::max(directedHausdorff(a, *indexOf(b, positions), positions),
                  directedHausdorff(b, *indexOf(a, positions), positions));
}

double dice(std::size_t common, std::size_t a, std::size_t b) {
  return a + b ? 2.0 * double(common) / double(a + b) : 1.0;
}

std::vector<std::vector<Index>> groups(const std::vector<int>& label, int count) {
  std::vector<std::vector<Index>> out(std::size_t(std::max(count, 0)));
  for (std::size_t i = 0; i < label.size(); ++i)
    if (label[i] >= 0) out[std::size_t(label[i])].push_back(Index(i));
  return out;
}

struct Scores {
  double labelled = 0, precision = 0, recall = 0, mcc = 0, dice = 0, hausdorff = NAN;
  std::size_t curves = 0;
  double curveDice = 0, curveHausdorff = NAN, curveRecall = 0, seconds = 0;
  std::size_t edges = 0;  // detected edges (a peer's are its curves)
  double edgeDice = 0, edgeRecall = 0;
};

// Why ours misses a curve: per scale, the share of its points with a salient vertex of that scale
// within e; the share whose votes pass v = voteThreshold V_max, the minimum count of scales, both;
// quantiles of |vote| / V_max over its points.
void explainMiss(const Model& m, const FeatureCurveResult& r, const std::vector<Index>& points) {
  const std::size_t n = points.size();
  std::vector<std::size_t> near(32, 0);
  const auto index = makeSpatialIndex(r.salientPositions);
  std::vector<Neighbor> found;
  std::size_t passVote = 0, passScales = 0, passBoth = 0;
  std::vector<double> ratio;
  const double threshold = ourOptions.voteThreshold * r.maxVote;
  for (const Index p : points) {
    index->radiusSearch(m.clean.positions()[p], m.spacing, found);
    std::uint32_t mask = 0;
    for (const Neighbor& nb : found) mask |= 1u << r.salientScales[nb.index];
    for (int s = 0; s < 32; ++s) near[std::size_t(s)] += (mask >> s) & 1u;
    const bool v = std::abs(r.votes[p]) > threshold;
    const bool c = __builtin_popcount(r.voterScales[p]) >= ourOptions.minVotingScales;
    passVote += v, passScales += c, passBoth += v && c;
    ratio.push_back(std::abs(r.votes[p]) / r.maxVote);
  }
  std::sort(ratio.begin(), ratio.end());
  {  // How close another curve runs (thin features: at scales above their width the APSS
     // merges their two creases into one ridge between them): the median over this curve's points
     // of the distance to the nearest feature point of another curve.
    const int g = m.gt[points[0]];
    std::vector<Index> others;
    for (std::size_t i = 0; i < m.gt.size(); ++i)
      if (m.gt[i] >= 0 && m.gt[i] != g) others.push_back(Index(i));
    double otherMedian = 10;
    if (!others.empty()) {
      const auto oi = indexOf(others, m.clean.positions());
      std::vector<double> d;
      for (const Index p : points) {
        oi->radiusSearch(m.clean.positions()[p], 10 * m.spacing, found);
        double b = 10 * m.spacing;
        for (const Neighbor& nb : found) b = std::min(b, std::sqrt(nb.distSq));
        d.push_back(b);
      }
      std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
      otherMedian = d[d.size() / 2] / m.spacing;
    }
    std::printf("#     another curve's feature points at (median) %.2f e (10: none within 10 e)\n",
                otherMedian);
  }
  // Per scale: line vertices near the curve, the largest |kappa1| t within e of each point.
  for (std::size_t s = 0; s < r.lineSets.size(); ++s) {
    const double t = r.scales[s].scale;
    std::vector<Vec3> pos;
    std::vector<double> k;
    for (const CurvatureLine& line : r.lineSets[s].lines)
      for (const CurvatureLineVertex& v : line.vertices) {
        pos.push_back(v.position);
        k.push_back(std::abs(v.kappa1) * t);
      }
    if (pos.empty()) continue;
    const auto li = makeSpatialIndex(pos);
    std::vector<double> best;
    std::size_t any = 0, pass = 0;
    const double bound = r.scales[s].vertexBound * t;
    for (const Index p : points) {
      li->radiusSearch(m.clean.positions()[p], m.spacing, found);
      double b = 0;
      for (const Neighbor& nb : found) b = std::max(b, k[nb.index]);
      any += !found.empty();
      pass += b > bound;
      best.push_back(b);
    }
    std::sort(best.begin(), best.end());
    // Where the lines near the curve stop and why: the open ends (first / last vertex) of the
    // lines with a vertex within e of the curve, by stop reason, split by whether the end itself
    // lies within e of the curve; and the seeds (the tracer's Poisson disk, redrawn) within e.
    std::vector<std::size_t> lineOf, touching;
    for (std::size_t l = 0; l < r.lineSets[s].lines.size(); ++l)
      for (std::size_t v = 0; v < r.lineSets[s].lines[l].vertices.size(); ++v) lineOf.push_back(l);
    std::vector<std::uint8_t> nearLine(r.lineSets[s].lines.size(), 0);
    for (const Index p : points) {
      li->radiusSearch(m.clean.positions()[p], m.spacing, found);
      for (const Neighbor& nb : found) nearLine[lineOf[nb.index]] = 1;
    }
    const auto ci = indexOf(points, m.clean.positions());
    std::size_t endsOn[16] = {}, endsOff[16] = {};
    std::size_t nearLines = 0;
    for (std::size_t l = 0; l < nearLine.size(); ++l) {
      if (!nearLine[l]) continue;
      ++nearLines;
      const CurvatureLine& line = r.lineSets[s].lines[l];
      if (line.closed) continue;
      const LineStop why[2] = {line.stopBackward, line.stopForward};
      const Vec3 at[2] = {line.vertices.front().position, line.vertices.back().position};
      for (int k = 0; k < 2; ++k) {
        ci->radiusSearch(at[k], m.spacing, found);
        (found.empty() ? endsOff : endsOn)[int(why[k])]++;
      }
    }
    // Runs along the curve: >= 3 consecutive vertices of one line within e of it; how each run
    // ends (the line's stop, or the line leaving the curve).
    std::size_t runEnds[16] = {}, runLeft = 0, runs = 0, runVertices = 0;
    for (const CurvatureLine& line : r.lineSets[s].lines) {
      const std::size_t nv = line.vertices.size();
      std::vector<std::uint8_t> on(nv, 0);
      for (std::size_t v = 0; v < nv; ++v) {
        ci->radiusSearch(line.vertices[v].position, m.spacing, found);
        on[v] = !found.empty();
      }
      for (std::size_t a = 0; a < nv;) {
        if (!on[a]) {
          ++a;
          continue;
        }
        std::size_t b = a;
        while (b + 1 < nv && on[b + 1]) ++b;
        if (b - a + 1 >= 3) {
          ++runs;
          runVertices += b - a + 1;
          if (a == 0 && !line.closed)
            ++runEnds[int(line.stopBackward)];
          else if (a > 0)
            ++runLeft;
          if (b == nv - 1 && !line.closed)
            ++runEnds[int(line.stopForward)];
          else if (b < nv - 1)
            ++runLeft;
        }
        a = b + 1;
      }
    }
    std::printf("#     scale %zu: %zu runs along the curve (%zu vertices), their ends: left it %zu",
                s, runs, runVertices, runLeft);
    for (int k = 0; k <= int(LineStop::MaxSteps); ++k)
      if (runEnds[k]) std::printf(" %s %zu", lineStopName(LineStop(k)), runEnds[k]);
    std::printf("\n");
    // Seeds within e of the curve (the tracer's Poisson disk, redrawn) and why those that started
    // no line did not: refit there.
    std::size_t seedsNear = 0, seedsStarted = 0, seedInvalid = 0, seedUmbilic = 0;
    if (lastCloud) {
      const CurvatureLineOptions& lo = ourOptions.lines;
      const std::vector<Index> sampleIds =
          lineSamples(lastCloud->positions(), lo.alpha, t, lo.seed);
      const std::vector<Index> seeds =
          poissonDiskSample(lastCloud->positions(), sampleIds, 2 * lo.beta * t, lo.seed + 1);
      std::vector<std::uint8_t> started(lastCloud->size(), 0);
      for (const CurvatureLine& line : r.lineSets[s].lines) started[line.seed] = 1;
      std::vector<Vec3> missed;
      for (const Index q : seeds) {
        ci->radiusSearch(lastCloud->positions()[q], m.spacing, found);
        if (found.empty()) continue;
        ++seedsNear;
        seedsStarted += started[q];
        if (!started[q]) missed.push_back(lastCloud->positions()[q]);
      }
      std::vector<Vec3> sp(sampleIds.size()), sn(sampleIds.size());
      for (std::size_t i = 0; i < sampleIds.size(); ++i) {
        sp[i] = lastCloud->positions()[sampleIds[i]];
        sn[i] = lastCloud->normals()[sampleIds[i]];
      }
      const auto si = makeSpatialIndex(sp);
      const std::vector<double> ts{t};
      FitPointsOptions fo;
      fo.fit = lo.fit;
      for (const LocalFit& f : fitPoints(SurfaceSamples{sp, sn, *si}, FitQueries{missed, ts}, fo)) {
        if (!f.valid) {
          ++seedInvalid;
          continue;
        }
        const double a1 = std::max(std::abs(f.kMax), std::abs(f.kMin)),
                     a2 = std::min(std::abs(f.kMax), std::abs(f.kMin));
        seedUmbilic += (a1 - a2) * t < lo.minAnisotropy || a2 > (1 - lo.minCurvatureGap) * a1;
      }
    }
    // The field on the curve's points that have no line vertex within e: the fit there (valid,
    // near-umbilic) and the angle of v_min to the curve (its points' principal axis within 2 e).
    std::size_t uncovered = 0, unInvalid = 0, unUmbilic = 0, unAlong = 0;
    if (lastCloud) {
      const CurvatureLineOptions& lo = ourOptions.lines;
      const std::vector<Index> sampleIds =
          lineSamples(lastCloud->positions(), lo.alpha, t, lo.seed);
      std::vector<Vec3> sp(sampleIds.size()), sn(sampleIds.size());
      for (std::size_t i = 0; i < sampleIds.size(); ++i) {
        sp[i] = lastCloud->positions()[sampleIds[i]];
        sn[i] = lastCloud->normals()[sampleIds[i]];
      }
      const auto si = makeSpatialIndex(sp);
      std::vector<Vec3> queries, axes;
      for (const Index p : points) {
        li->radiusSearch(m.clean.positions()[p], m.spacing, found);
        if (!found.empty()) continue;
        queries.push_back(lastCloud->positions()[p]);
        ci->radiusSearch(m.clean.positions()[p], 2 * m.spacing, found);
        Vec3 mean = Vec3::Zero();
        for (const Neighbor& nb : found) mean += m.clean.positions()[points[nb.index]];
        mean /= double(found.size());
        Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
        for (const Neighbor& nb : found) {
          const Vec3 d = m.clean.positions()[points[nb.index]] - mean;
          cov += d * d.transpose();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
        axes.push_back(eig.eigenvectors().col(2));
      }
      const std::vector<double> ts{t};
      FitPointsOptions fo;
      fo.fit = lo.fit;
      const auto fits = fitPoints(SurfaceSamples{sp, sn, *si}, FitQueries{queries, ts}, fo);
      uncovered = fits.size();
      for (std::size_t q = 0; q < fits.size(); ++q) {
        const LocalFit& f = fits[q];
        if (!f.valid) {
          ++unInvalid;
          continue;
        }
        const bool maxFirst = std::abs(f.kMax) >= std::abs(f.kMin);
        const double a1 = std::abs(maxFirst ? f.kMax : f.kMin),
                     a2 = std::abs(maxFirst ? f.kMin : f.kMax);
        if ((a1 - a2) * t < lo.minAnisotropy || a2 > (1 - lo.minCurvatureGap) * a1) {
          ++unUmbilic;
          continue;
        }
        const Vec3 dir = maxFirst ? f.dirMin : f.dirMax;
        unAlong += std::abs(dir.dot(axes[q])) > std::cos(30 * kPi / 180);
      }
    }
    std::printf(
        "#     scale %zu: %zu curve points without a line vertex within e: %zu invalid, "
        "%zu umbilic, %zu with v_min within 30 deg of the curve\n",
        s, uncovered, unInvalid, unUmbilic, unAlong);
    std::printf(
        "#     scale %zu: %zu lines within e, seeds within e %zu (%zu started a line; of "
        "the rest %zu invalid, %zu umbilic, the others at a border or on a line); their "
        "ends within e of the curve:",
        s, nearLines, seedsNear, seedsStarted, seedInvalid, seedUmbilic);
    for (int k = 0; k <= int(LineStop::MaxSteps); ++k)
      if (endsOn[k]) std::printf(" %s %zu", lineStopName(LineStop(k)), endsOn[k]);
    std::printf("; elsewhere:");
    for (int k = 0; k <= int(LineStop::MaxSteps); ++k)
      if (endsOff[k]) std::printf(" %s %zu", lineStopName(LineStop(k)), endsOff[k]);
    std::printf("\n");
    std::printf(
        "#     scale %zu (t %.2f e): line vertex within e %.0f%%, max |k1|t q50 %.2f q90 %.2f; "
        "bound %.2f (0.5 K t %.2f, cap %.2f, floor %.2f) passed by %.0f%%\n",
        s, t / m.spacing, 100.0 * double(any) / double(n), best[n / 2],
        best[std::min(n - 1, n * 9 / 10)], bound,
        (1 - ourOptions.salientThreshold) * r.scales[s].salientBound * t,
        ourOptions.salientBoundCap, r.salientCurvatureFloor, 100.0 * double(pass) / double(n));
  }
  std::printf("#     salient within e per scale:");
  for (std::size_t s = 0; s < r.scales.size(); ++s)
    std::printf(" %.0f%%", 100.0 * double(near[s]) / double(n));
  std::printf(
      "; |v| > %.2f Vmax %.0f%%, >= %d scales %.0f%%, both %.0f%%; |v|/Vmax q50 %.3f q90 %.3f\n",
      ourOptions.voteThreshold, 100.0 * double(passVote) / double(n), ourOptions.minVotingScales,
      100.0 * double(passScales) / double(n), 100.0 * double(passBoth) / double(n), ratio[n / 2],
      ratio[std::min(n - 1, n * 9 / 10)]);
}

// Each ground-truth group (curve or edge) against the detected group holding most of its points:
// match[g] (-1 for none) and the points they share.
struct Matches {
  std::map<std::pair<int, int>, std::size_t> overlap;  // (truth, detected) -> shared points
  std::vector<int> match;
  std::vector<std::size_t> common;
};

Matches bestMatches(const std::vector<int>& truth, int truthCount,
                    const std::vector<int>& detected) {
  Matches out;
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (truth[i] >= 0 && detected[i] >= 0) ++out.overlap[{truth[i], detected[i]}];
  out.match.assign(std::size_t(truthCount), -1);
  out.common.assign(std::size_t(truthCount), 0);
  for (const auto& [pair, k] : out.overlap)
    if (k > out.common[std::size_t(pair.first)])
      out.common[std::size_t(pair.first)] = k, out.match[std::size_t(pair.first)] = pair.second;
  return out;
}

// Per edge: the same matching between the mesh's edges and the detected edges (Dice and the
// share covered >= kCurveCovered).
void scoreEdges(const Model& m, const std::vector<int>& detected, int detectedCount, Scores& s) {
  const std::vector<std::vector<Index>> truth = groups(m.gtEdge, m.edges.edges),
                                        found = groups(detected, detectedCount);
  const Matches matches = bestMatches(m.gtEdge, m.edges.edges, detected);
  double diceSum = 0;
  std::size_t counted = 0, covered = 0;
  for (std::size_t g = 0; g < truth.size(); ++g) {
    if (truth[g].empty() || m.edges.edgeLength[g] < kEdgeReach * m.spacing ||
        m.edges.curveFold[std::size_t(m.edges.edgeCurve[g])])
      continue;
    ++counted;
    if (matches.match[g] < 0) continue;
    diceSum +=
        dice(matches.common[g], truth[g].size(), found[std::size_t(matches.match[g])].size());
    covered += double(matches.common[g]) >= kCurveCovered * double(truth[g].size());
  }
  s.edges = std::size_t(detectedCount);
  if (counted == 0) return;
  s.edgeDice = diceSum / double(counted);
  s.edgeRecall = double(covered) / double(counted);
}

// Per curve: each ground-truth curve against the detected curve holding most of its points.
void scoreCurves(const Model& m, const std::vector<int>& detected, int detectedCount, Scores& s) {
  const std::vector<std::vector<Index>> truth = groups(m.gt, m.edges.curves),
                                        found = groups(detected, detectedCount);
  const Matches matches = bestMatches(m.gt, m.edges.curves, detected);
  const auto& overlap = matches.overlap;
  const std::vector<int>& match = matches.match;
  const std::vector<std::size_t>& common = matches.common;
  std::map<int, std::unique_ptr<SpatialIndex>> foundIndex;  // a large component matches many
  double diceSum = 0, hausdorffSum = 0;
  std::size_t counted = 0, matched = 0, covered = 0;
  for (std::size_t g = 0; g < truth.size(); ++g) {
    if (truth[g].empty() || !scoredCurve(m, g)) continue;
    ++counted;
    if (printPerCurve) {  // why a curve is missed: unlabelled, or cut into pieces
      std::size_t labelled = 0, pieces = 0;
      for (const auto& [pair, k] : overlap)
        if (pair.first == int(g)) {
          labelled += k;
          pieces += double(k) >= 0.05 * double(truth[g].size());
        }
      std::printf(
          "#   curve %zu: %zu points, %.0f%% labelled, best match %.0f%%, %zu pieces >= 5%%\n", g,
          truth[g].size(), 100.0 * double(labelled) / double(truth[g].size()),
          100.0 * double(common[g]) / double(truth[g].size()), pieces);
      if (lastOurs && &lastOurs->curveId != &detected && lastOurs->curveId == detected &&
          double(common[g]) < kCurveCovered * double(truth[g].size())) {
        // The detected curves it falls into (a sign turned by the normals' orientation cuts it).
        std::printf("#     in detected curves (points, sign):");
        for (const auto& [pair, k] : overlap)
          if (pair.first == int(g))
            std::printf(" %zu %+d", k, lastOurs->curves[std::size_t(pair.second)].convexity);
        std::printf("\n");
        explainMiss(m, *lastOurs, truth[g]);
      }
    }
    if (match[g] < 0) continue;
    const std::vector<Index>& d = found[std::size_t(match[g])];
    diceSum += dice(common[g], truth[g].size(), d.size());
    covered += double(common[g]) >= kCurveCovered * double(truth[g].size());
    auto& index = foundIndex[match[g]];
    if (!index) index = indexOf(d, m.clean.positions());
    hausdorffSum += std::max(
        directedHausdorff(truth[g], *index, m.clean.positions()),
        directedHausdorff(d, *indexOf(truth[g], m.clean.positions()), m.clean.positions()));
    ++matched;
  }
  s.curves = std::size_t(detectedCount);
  if (counted == 0) return;
  s.curveDice = diceSum / double(counted);
  s.curveRecall = double(covered) / double(counted);
  if (matched) s.curveHausdorff = hausdorffSum / double(matched) / m.diagonal;
}

// `detected`: per point, its detected curve or -1 (labelled = detected >= 0); `edges`: per point,
// its detected edge (labelled where detected is).
Scores score(const Model& m, const std::vector<int>& detected, int detectedCount,
             const std::vector<int>& edges, int edgeCount) {
  double tp = 0, fp = 0, fn = 0, tn = 0;
  std::vector<Index> truthSet, labelledSet;
  for (std::size_t i = 0; i < m.gt.size(); ++i) {
    const bool t = m.gt[i] >= 0, l = detected[i] >= 0;
    (t ? (l ? tp : fn) : (l ? fp : tn)) += 1;
    if (t) truthSet.push_back(Index(i));
    if (l) labelledSet.push_back(Index(i));
  }
  if (printPerCurve) {  // false positives just beside an edge (a band too wide) or far from it
    std::size_t within2 = 0, within3 = 0, far = 0, farNearBorder = 0;
    for (std::size_t i = 0; i < m.gt.size(); ++i)
      if (m.gt[i] < 0 && detected[i] >= 0) {
        ++(m.gt2[i] >= 0 ? within2 : m.gt3[i] >= 0 ? within3 : far);
        if (m.gt3[i] >= 0) continue;
        for (const auto& [a, b] : m.edges.borderEdges)
          if (segmentDistance(m.clean.positions()[i], m.mesh.vertices[a] - m.clean.origin(),
                              m.mesh.vertices[b] - m.clean.origin()) < 3 * m.spacing) {
            ++farNearBorder;
            break;
          }
      }
    std::printf(
        "#   false positives %.0f: within 2e %zu, 2e-3e %zu, beyond 3e %zu (%zu of them within 3e "
        "of the mesh's border)\n",
        fp, within2, within3, far, farNearBorder);
  }
  Scores s;
  s.labelled = (tp + fp) / double(m.gt.size());
  s.precision = tp + fp > 0 ? tp / (tp + fp) : 0;
  s.recall = tp + fn > 0 ? tp / (tp + fn) : 0;
  const double denominator = (tp + fp) * (tp + fn) * (tn + fp) * (tn + fn);
  s.mcc = denominator > 0 ? (tp * tn - fp * fn) / std::sqrt(denominator) : 0;
  s.dice = dice(std::size_t(tp), truthSet.size(), labelledSet.size());
  s.hausdorff = hausdorff(truthSet, labelledSet, m.clean.positions()) / m.diagonal;
  scoreCurves(m, detected, detectedCount, s);
  scoreEdges(m, edges, edgeCount, s);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Methods. Each returns per point its curve (or -1) and the number of curves.

struct Detection {
  std::vector<int> curve;
  int count = 0;
  std::vector<int> edge;  // ours' edges; empty: a peer's, whose edges are its curves
  int edgeCount = 0;
};

// Ours with the library's defaults unless --salient / --vote-threshold / --min-curvature /
// --vote-radius say otherwise (to measure a setting against the same ground truth).

Detection runOurs(const PointCloud& cloud, const NormalOrientationResult& rays) {
  FeatureCurveOptions options = ourOptions;
  // As `features` does for a cloud whose normals it estimated.
  if (foldBorders == FoldBorders::Auto)
    chooseFoldBorders(options, rays);
  else
    options.foldBorders = foldBorders == FoldBorders::On;
  FeatureCurveResult result = detectFeatureCurves(cloud, options);
  if (printPerCurve)
    std::printf("# fold borders %s: %zu points%s\n", result.foldsApplied ? "on" : "off",
                result.foldPoints,
                result.foldSeeThrough >= 0
                    ? (", " + std::to_string(int(std::lround(100 * result.foldSeeThrough))) +
                       "% seeing out on both sides")
                          .c_str()
                    : "");
  Detection d;
  d.curve = result.curveId;
  for (int c : d.curve) d.count = std::max(d.count, c + 1);
  d.edge = result.edgeId;
  d.edgeCount = int(result.edges.size());
  if (printPerCurve) {
    lastOurs = std::make_unique<FeatureCurveResult>(std::move(result));
    lastCloud = &cloud;
  }
  return d;
}

// The peers' curves: connected components of the labelled points on the (symmetrised) graph.
Detection components(const std::vector<bool>& labelled, const KnnGraph& graph) {
  DisjointSets sets(labelled.size());
  for (std::size_t i = 0; i < graph.size(); ++i)
    if (labelled[i])
      for (std::size_t k = graph.offsets[i]; k < graph.offsets[i + 1]; ++k)
        if (labelled[graph.neighbors[k]]) sets.unite(Index(i), graph.neighbors[k]);
  Detection d;
  d.curve.assign(labelled.size(), -1);
  std::unordered_map<Index, int> idOfRoot;
  for (std::size_t i = 0; i < labelled.size(); ++i)
    if (labelled[i]) {
      const auto [it, added] = idOfRoot.emplace(sets.find(Index(i)), d.count);
      d.count += added;
      d.curve[i] = it->second;
    }
  return d;
}

struct VcmSetting {
  double offset, convolution;  // R and r over e
};
const VcmSetting kVcmSettings[] = {{2, 1}, {4, 1}, {4, 2}};
const double kCovarianceThresholds[] = {0.02, 0.05, 0.1};

std::vector<bool> vcmLabels(const PointCloud& cloud, const VcmSetting& setting, double spacing) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<Kernel::Point_3> points;
  points.reserve(cloud.size());
  for (const Vec3& p : cloud.positions()) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::array<double, 6>> cov;
  CGAL::compute_vcm(points, cov, setting.offset * spacing, setting.convolution * spacing);
  std::vector<bool> labelled(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    labelled[i] = CGAL::vcm_is_on_feature_edge(cov[i], kVcmThreshold);
  return labelled;
}

// ---------------------------------------------------------------------------------------------
// Output.

struct Row {
  std::string method;
  Scores scores;
};

void printHeader(double noise) {
  std::printf("\n# noise %g of the diagonal\n", noise);
  std::printf("%-14s %-11s %6s %6s %6s %6s %6s %8s %6s %6s %8s %5s %8s %6s %6s %5s\n", "model",
              "method", "lab%", "P", "R", "MCC", "Dice", "H/diag", "curves", "cDice", "cH/diag",
              "cRec", "seconds", "edges", "eDice", "eRec");
}

// A Hausdorff distance over the diagonal, "-" when one of the sets is empty.
std::string distanceText(double d) {
  char buf[16] = "-";
  if (!std::isnan(d)) std::snprintf(buf, sizeof buf, "%.4f", d);
  return buf;
}

void printScores(const char* model, const char* method, const Scores& s) {
  std::printf(
      "%-14s %-11s %6.2f %6.3f %6.3f %6.3f %6.3f %8s %6zu %6.3f %8s %5.2f %8.2f %6zu %6.3f %5.2f\n",
      model, method, 100 * s.labelled, s.precision, s.recall, s.mcc, s.dice,
      distanceText(s.hausdorff).c_str(), s.curves, s.curveDice,
      distanceText(s.curveHausdorff).c_str(), s.curveRecall, s.seconds, s.edges, s.edgeDice,
      s.edgeRecall);
  std::fflush(stdout);
}

void printModel(const Model& m, std::size_t gtPoints) {
  std::printf(
      "# %s: %zu vertices, %zu triangles; sharp edges %zu (convex %zu, concave %zu) in %d curves, "
      "%d with points (%d scored: >= %g e long, not folds), %d edges; %.2f %% of the points are "
      "feature "
      "points; e %.4g, diagonal %.4g",
      m.name.c_str(), m.mesh.vertices.size(), m.mesh.triangles.size(), m.edges.sharp.size(),
      m.edges.convex, m.edges.concave, m.edges.curves, m.gtCurves, m.scoredCurves, kEdgeReach,
      m.edges.edges, 100.0 * double(gtPoints) / double(m.gt.size()), m.spacing, m.diagonal);
  if (m.edges.border) std::printf("; %zu border edges", m.edges.border);
  if (m.edges.nonManifold) std::printf("; %zu non-manifold edges", m.edges.nonManifold);
  if (m.edges.inconsistent)
    std::printf("; %zu sharp edges wound inconsistently", m.edges.inconsistent);
  if (m.edges.flipped) std::printf("; faces point inwards: signs flipped");
  std::printf("\n");
}

// Means over the models of each method's scores (NaN Hausdorff values left out).
void printMeans(const std::vector<Row>& rows) {
  std::vector<std::string> methods;
  for (const Row& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end())
      methods.push_back(r.method);
  for (const std::string& method : methods) {
    Scores mean;
    double n = 0, nH = 0, nCH = 0, curves = 0, edges = 0;
    mean.hausdorff = mean.curveHausdorff = 0;
    for (const Row& r : rows) {
      if (r.method != method) continue;
      const Scores& s = r.scores;
      n += 1;
      mean.labelled += s.labelled, mean.precision += s.precision, mean.recall += s.recall;
      mean.mcc += s.mcc, mean.dice += s.dice, curves += double(s.curves);
      mean.curveDice += s.curveDice, mean.curveRecall += s.curveRecall, mean.seconds += s.seconds;
      mean.edgeDice += s.edgeDice, mean.edgeRecall += s.edgeRecall, edges += double(s.edges);
      if (!std::isnan(s.hausdorff)) mean.hausdorff += s.hausdorff, nH += 1;
      if (!std::isnan(s.curveHausdorff)) mean.curveHausdorff += s.curveHausdorff, nCH += 1;
    }
    for (double* v :
         {&mean.labelled, &mean.precision, &mean.recall, &mean.mcc, &mean.dice, &mean.curveDice,
          &mean.curveRecall, &mean.seconds, &mean.edgeDice, &mean.edgeRecall})
      *v /= n;
    mean.hausdorff = nH ? mean.hausdorff / nH : NAN;
    mean.curveHausdorff = nCH ? mean.curveHausdorff / nCH : NAN;
    mean.curves = std::size_t(std::lround(curves / n));
    mean.edges = std::size_t(std::lround(edges / n));
    printScores("mean", method.c_str(), mean);
  }
}

// ---------------------------------------------------------------------------------------------

bool readMesh(const std::string& dir, const std::string& name, TriangleMesh& mesh) {
  const std::string path = dir + "/" + name + ".off";
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::printf("# %s: %s not found, skipped\n", name.c_str(), path.c_str());
    return false;
  }
  std::stringstream data;
  data << in.rdbuf();
  mesh = parseOff(data.str(), path);
  return true;
}

bool makeMesh(const std::string& name, const std::string& dir, std::size_t points,
              TriangleMesh& mesh) {
  if (name == "box")
    mesh = makeBox(points);
  else if (name == "creases")
    mesh = makeCreases();
  else if (name == "box_on_ground")
    mesh = makeBoxOnGround();
  else
    return readMesh(dir, name, mesh);
  return true;
}

// Every method on one cloud (clean or noisy) of a model.
void runMethods(const Model& m, const PointCloud& cloud, const NormalOrientationResult& rays,
                bool peers, std::vector<Row>& rows) {
  const auto add = [&](const std::string& method, const Detection& d, double seconds) {
    Row row{method, d.edge.empty() ? score(m, d.curve, d.count, d.curve, d.count)
                                   : score(m, d.curve, d.count, d.edge, d.edgeCount)};
    row.scores.seconds = seconds;
    printScores(m.name.c_str(), method.c_str(), row.scores);
    rows.push_back(row);
  };
  Clock::time_point start = Clock::now();
  const Detection ours = runOurs(cloud, rays);
  add("ours", ours, secondsSince(start));
  if (printPerCurve && lastOurs) {
    // How far ours' salient vertices lie from the sharp edges, per scale, in units of e: the APSS
    // rounds an edge, so its vertices lie inside a convex edge (outside a concave one).
    const FeatureCurveResult& r = *lastOurs;
    for (std::size_t sc = 0; sc < r.scales.size(); ++sc) {
      std::vector<double> d;
      for (std::size_t k = 0; k < r.salientPositions.size(); ++k) {
        if (r.salientScales[k] != sc) continue;
        double best = 1e300;
        for (const SharpEdge& e : m.edges.sharp)
          best = std::min(
              best, segmentDistance(r.salientPositions[k], m.mesh.vertices[e.a] - m.clean.origin(),
                                    m.mesh.vertices[e.b] - m.clean.origin()));
        d.push_back(best / m.spacing);
      }
      std::sort(d.begin(), d.end());
      auto q = [&](double f) { return d.empty() ? 0.0 : d[std::size_t(f * (d.size() - 1))]; };
      std::size_t far = std::count_if(d.begin(), d.end(), [](double x) { return x > 0.5; });
      std::printf(
          "#   salient vertices at scale %zu: %zu, distance to the nearest sharp edge / e: "
          "q25 %.2f q50 %.2f q75 %.2f q90 %.2f, beyond 0.5 e %zu\n",
          sc, d.size(), q(.25), q(.5), q(.75), q(.9), far);
    }
  }
  if (!peers) return;

  start = Clock::now();
  const KnnGraph graph = buildKnnGraph(cloud.positions(), kPeerGraphNeighbors);
  const double graphSeconds = secondsSince(start);
  for (const VcmSetting& setting : kVcmSettings) {
    start = Clock::now();
    const std::vector<bool> labelled = vcmLabels(cloud, setting, m.spacing);
    const Detection d = components(labelled, graph);
    char name[32];
    std::snprintf(name, sizeof name, "vcm %ge/%ge", setting.offset, setting.convolution);
    add(name, d, secondsSince(start) + graphSeconds);
  }
  start = Clock::now();
  NormalEstimationOptions covariance;
  covariance.k = kCovarianceNeighbors;
  const NormalEstimationResult est = estimateNormals(cloud.positions(), covariance);
  const double covarianceSeconds = secondsSince(start);
  for (double threshold : kCovarianceThresholds) {
    start = Clock::now();
    std::vector<bool> labelled(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
      labelled[i] = est.surfaceVariation[i] > threshold;
    const Detection d = components(labelled, graph);
    char name[32];
    std::snprintf(name, sizeof name, "cov %.2f", threshold);
    add(name, d, secondsSince(start) + covarianceSeconds + graphSeconds);
  }
}

std::vector<std::string> splitList(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

static int run(int argc, char** argv) {
  scalespace::retainFreedMemory();  // as the CLI does (core/MemoryReuse.hpp)
  std::size_t points = 100000;
  std::string dir = "/tmp/real/cgal/data/meshes";
  std::vector<std::string> models(std::begin(kCadModels), std::end(kCadModels));
  models.insert(models.end(), std::begin(kOwnModels), std::end(kOwnModels));
  double angle = 30;
  bool clean = true, noisy = true, peers = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--points" && hasValue) {
      points = scalespace::bench::countArgument(argv, ++i);
    } else if (a == "--data" && hasValue) {
      dir = argv[++i];
    } else if (a == "--models" && hasValue) {
      models = splitList(argv[++i]);
    } else if (a == "--angle" && hasValue) {
      angle = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--fold-borders" && hasValue) {
      const std::string v = argv[++i];
      if (v != "auto" && v != "on" && v != "off") {
        std::fprintf(stderr, "--fold-borders takes auto, on or off\n");
        return 2;
      }
      foldBorders = v == "on" ? FoldBorders::On : v == "off" ? FoldBorders::Off : FoldBorders::Auto;
    } else if (a == "--fold-share" && hasValue) {
      ourOptions.foldBorderShare = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--fold-reach" && hasValue) {
      ourOptions.foldReach = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--clean-only") {
      noisy = false;
    } else if (a == "--noise-only") {
      clean = false;
    } else if (a == "--salient" && hasValue) {
      ourOptions.salientThreshold = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--vote-threshold" && hasValue) {
      ourOptions.voteThreshold = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--min-curvature" && hasValue) {
      ourOptions.minSalientCurvature = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--bound-cap" && hasValue) {
      ourOptions.salientBoundCap = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--all-salient") {
      ourOptions.ridgeOnly = false;
    } else if (a == "--noise-curvature" && hasValue) {
      ourOptions.noiseSalientFactor = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--min-scales" && hasValue) {
      ourOptions.minVotingScales = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--vote-radius" && hasValue) {
      ourOptions.voteRadiusFactor = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--random-seed-order") {
      ourOptions.lines.curvedSeedsFirst = false;
    } else if (a == "--max-turn" && hasValue) {
      ourOptions.lines.maxTurnDegrees = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--collision" && hasValue) {
      ourOptions.lines.collisionFraction = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--beta" && hasValue) {
      ourOptions.lines.beta = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--border-offset" && hasValue) {
      ourOptions.lines.borderOffset = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--curvature-gap" && hasValue) {
      ourOptions.lines.minCurvatureGap = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--min-piece-extent" && hasValue) {
      ourOptions.minPieceExtent = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--min-extent" && hasValue) {
      ourOptions.minCurveExtent = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--join-gap" && hasValue) {
      ourOptions.joinGap = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--centreline-reach" && hasValue) {
      ourOptions.centrelineReach = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--band-half-width" && hasValue) {
      ourOptions.bandHalfWidth = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--crease-reach" && hasValue) {
      ourOptions.creaseReach = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--crease-half-width" && hasValue) {
      ourOptions.creaseHalfWidth = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--no-rim-lines") {
      ourOptions.rimLines = false;
    } else if (a == "--crease-flatness" && hasValue) {
      ourOptions.creaseFlatness = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--centreline-linearity" && hasValue) {
      ourOptions.centrelineLinearity = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--across-weight" && hasValue) {
      acrossWeight = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--sheet-normals" && hasValue) {
      sheetNormals = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--no-visibility") {
      visibility = false;
    } else if (a == "--reflect") {
      reflect = true;
    } else if (a == "--no-reflect") {
      reflect = false;
    } else if (a == "--sign-from-pca") {
      sheetSign = SheetSign::FromPlanes;
    } else if (a == "--own-tree-sign") {
      sheetSign = SheetSign::OwnTree;
    } else if (a == "--mesh-normals") {
      meshNormals = true;
    } else if (a == "--robust-fit") {
      ourOptions.lines.fit.robust = true;
    } else if (a == "--bound-per-scale") {
      ourOptions.salientBoundFromFinest = false;
    } else if (a == "--per-curve") {
      printPerCurve = true;
      ourOptions.keepVotingDetail = true;
    } else if (a == "--no-peers") {
      peers = false;
    } else {
      std::fprintf(stderr, "bench_features: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  std::printf(
      "# %zu points per model; sharp edges: face normals turning by >= %g degrees; feature "
      "points within e of one; cRec: share of ground-truth curves whose best-overlapping detected "
      "curve covers >= %.0f %% of their points; vcm R/r (threshold %.2f), cov: surface variation "
      "over %zu neighbours > X; peers' curves: components on the %zu-NN graph\n",
      points, angle, 100 * kCurveCovered, kVcmThreshold, kCovarianceNeighbors, kPeerGraphNeighbors);
  std::vector<double> noiseLevels;
  if (clean) noiseLevels.push_back(0);
  if (noisy) noiseLevels.push_back(kNoise);
  for (double noise : noiseLevels) {
    printHeader(noise);
    std::vector<Row> rows;
    for (const std::string& name : models) {
      try {
        TriangleMesh mesh;
        if (!makeMesh(name, dir, points, mesh)) continue;
        const Model m = prepareModel(name, std::move(mesh), points, angle);
        printModel(
            m, std::size_t(std::count_if(m.gt.begin(), m.gt.end(), [](int c) { return c >= 0; })));
        if (noise == 0) {
          runMethods(m, m.clean, m.cleanRays, peers, rows);
        } else {
          PointCloud cloud = noisyCopy(m.clean, noise * m.diagonal);
          const NormalOrientationResult rays = estimateSceneNormals(cloud);
          if (printPerCurve) printOrientation(m, cloud.normals(), "noisy");
          if (meshNormals) cloud.setNormals(m.meshNormals);
          runMethods(m, cloud, rays, peers, rows);
        }
      } catch (const Error& error) {
        std::printf("# %s: skipped (%s)\n", name.c_str(), error.what());
      }
    }
    printMeans(rows);
  }
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_features", [&] { return run(argc, argv); });
}
