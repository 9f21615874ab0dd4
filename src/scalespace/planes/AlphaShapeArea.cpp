#include "scalespace/planes/AlphaShapeArea.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_2.h>
#include <CGAL/convex_hull_2.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <map>
#include <unordered_set>

namespace scalespace {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_2<Kernel>;
using Fb = CGAL::Triangulation_face_base_with_info_2<bool, Kernel>;  // info: face is interior
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

std::vector<Kernel::Point_2> toCgal(const std::vector<Vec2>& points) {
  std::vector<Kernel::Point_2> out;
  out.reserve(points.size());
  for (const Vec2& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

// The regularized alpha shape read directly off the Delaunay triangulation: a finite triangle is
// interior when its squared circumradius is <= alpha (what CGAL::Alpha_shape_2 classifies as
// INTERIOR in REGULARIZED mode; tests/planes compare both), and the outline is made of the edges
// between an interior triangle and a non-interior (or infinite) one. Alpha_shape_2 itself also
// builds the whole alpha spectrum, which costs far more than the one alpha needed here (the
// components time of bench/bench_planes).
/// Marks the interior faces (squared circumradius <= alpha) in their info and returns their area.
double markInterior(Delaunay& dt, double alpha) {
  const auto squaredRadius = Kernel().compute_squared_radius_2_object();
  const auto area = Kernel().compute_area_2_object();
  for (auto f = dt.all_faces_begin(); f != dt.all_faces_end(); ++f) f->info() = false;
  double sum = 0;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const auto& a = f->vertex(0)->point();
    const auto& b = f->vertex(1)->point();
    const auto& c = f->vertex(2)->point();
    if (!(squaredRadius(a, b, c) <= alpha)) continue;
    f->info() = true;
    sum += std::abs(CGAL::to_double(area(a, b, c)));
  }
  return sum;
}

/// Calls edge(a, b) for every boundary edge of the shape marked by markInterior, oriented
/// counter-clockwise around its interior face (infinite faces are never interior).
template <class Edge>
void forEachBoundaryEdge(const Delaunay& dt, Edge&& edge) {
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    if (!f->info()) continue;
    for (int i = 0; i < 3; ++i)
      if (!f->neighbor(i)->info())
        edge(f->vertex(Delaunay::ccw(i))->point(), f->vertex(Delaunay::cw(i))->point());
  }
}

AlphaShape alphaShapeOf(const std::vector<Kernel::Point_2>& points, double alpha,
                        bool withOutlines) {
  AlphaShape result;
  if (points.size() < 3 || !(alpha > 0)) return result;
  Delaunay dt(points.begin(), points.end());
  result.area = markInterior(dt, alpha);
  if (!withOutlines) return result;

  // Boundary edges oriented counter-clockwise around their interior face, chained into loops by
  // their start point (coordinates, not handles, so that the loop order is reproducible).
  std::multimap<std::pair<double, double>, std::pair<double, double>> next;
  forEachBoundaryEdge(dt, [&](const Kernel::Point_2& a, const Kernel::Point_2& b) {
    next.emplace(std::make_pair(a.x(), a.y()), std::make_pair(b.x(), b.y()));
  });
  while (!next.empty()) {
    std::vector<Vec2> loop;
    auto it = next.begin();
    const auto start = it->first;
    auto current = it->first;
    while (it != next.end()) {
      loop.emplace_back(current.first, current.second);
      const auto to = it->second;
      next.erase(it);
      if (to == start) break;
      current = to;
      it = next.find(current);
    }
    result.outlines.push_back(std::move(loop));
  }
  return result;
}

/// Sum of the areas of the triangles that are interior in the alpha shape of ALL `points`, found
/// by triangulating only the points within `reach` of `centre`: a triangle of that local Delaunay
/// triangulation whose circumcircle lies inside the disk (centre, reach) has no point of the
/// whole set strictly inside its circumcircle (every point in the disk was triangulated), so it
/// is a Delaunay triangle of the whole set too (up to the choice of diagonal among cocircular
/// points, which does not change the covered area), and it is interior when its squared
/// circumradius is <= alpha. Hence a lower bound of the whole shape's area.
double certifiedArea(const std::vector<Vec2>& points, const Vec2& centre, double reach,
                     double alpha) {
  std::vector<Kernel::Point_2> local;
  for (const Vec2& p : points)
    if ((p - centre).squaredNorm() < reach * reach) local.emplace_back(p.x(), p.y());
  if (local.size() < 3) return 0;
  const Delaunay dt(local.begin(), local.end());
  const auto circumcenter = Kernel().construct_circumcenter_2_object();
  const auto squaredRadius = Kernel().compute_squared_radius_2_object();
  const auto area = Kernel().compute_area_2_object();
  const Kernel::Point_2 c(centre.x(), centre.y());
  double sum = 0;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const auto& a = f->vertex(0)->point();
    const auto& b = f->vertex(1)->point();
    const auto& d = f->vertex(2)->point();
    const double r2 = squaredRadius(a, b, d);
    if (!(r2 <= alpha)) continue;
    const double away =
        std::sqrt(CGAL::to_double(CGAL::squared_distance(circumcenter(a, b, d), c)));
    // Inside the disk, with room for the rounding of the circumcentre.
    if (away + std::sqrt(r2) <= reach * (1 - 1e-9)) sum += std::abs(CGAL::to_double(area(a, b, d)));
  }
  return sum;
}

/// Area of the minor circular segment of radius r cut off by a chord of length l <= 2r.
double circularSegment(double l, double r) {
  const double half = std::min(l / 2, r);
  return r * r * std::asin(half / r) - half * std::sqrt(std::max(r * r - half * half, 0.0));
}

}  // namespace

// Why alphaShapeAreaLowerBound holds (S the points, P the subset, r = sqrt(alpha), A_r(X) the
// union of the Delaunay triangles of X with circumradius <= r):
// 1. A point x of conv(S) outside A_r(S) lies in a Delaunay triangle of S whose circumradius is
//    > r, hence in an S-empty open disk of radius > r, hence in an S-empty (so P-empty) open disk
//    D of radius r (shrink the disk towards x).
// 2. Such a D meets A_r(P) only within the circular segments of radius r on the boundary edges of
//    A_r(P): D's centre is not inside an interior triangle T of A_r(P) (every point of T is within
//    R_T <= r of a vertex of T, which D does not contain); so the segment from the centre to a
//    point y of D inside A_r(P) last enters A_r(P) through a boundary edge [a, b], at a point of
//    D; the chord of D on that line avoids a and b (D is P-empty), so lies inside (a, b); and the
//    part beyond a line of a disk of radius r whose chord lies inside (a, b) is inside the
//    segment of radius r on [a, b] (the disk through a and b is the extreme one).
// 3. A_r(P) lies in conv(P), inside conv(S). So area A_r(S) >= area A_r(P) - the segments.
double alphaShapeAreaLowerBound(const std::vector<Vec2>& points, double alpha, double cell) {
  if (points.size() < 3 || !(alpha > 0) || !(cell > 0)) return 0;
  Eigen::AlignedBox2d box;
  for (const Vec2& p : points) box.extend(p);
  // One point per cell, the first in input order (reproducible); cells numbered row by row.
  const Vec2 extent = box.sizes() / cell;
  if (!(extent.maxCoeff() < 1e7)) return 0;
  const std::uint64_t columns = std::uint64_t(extent.x()) + 1;
  std::unordered_set<std::uint64_t> taken;
  std::vector<Kernel::Point_2> subset;
  for (const Vec2& p : points) {
    const Vec2 c = (p - box.min()) / cell;
    if (taken.insert(std::uint64_t(c.y()) * columns + std::uint64_t(c.x())).second)
      subset.emplace_back(p.x(), p.y());
  }
  if (subset.size() < 3) return 0;
  Delaunay dt(subset.begin(), subset.end());
  double bound = markInterior(dt, alpha);
  const double r = std::sqrt(alpha);
  forEachBoundaryEdge(dt, [&](const Kernel::Point_2& a, const Kernel::Point_2& b) {
    bound -= circularSegment(std::sqrt(CGAL::to_double(CGAL::squared_distance(a, b))), r);
  });
  return std::max(bound, 0.0);
}

AlphaShape alphaShape2(const std::vector<Vec2>& points, double alpha, bool withOutlines) {
  return alphaShapeOf(toCgal(points), alpha, withOutlines);
}

/// alphaShapeAreaLowerBound is tried on sets of at least this many points whose subset has at
/// most a quarter of them (so that its triangulation is cheap next to the whole one).
constexpr std::size_t kSubsetPoints = 4096;

/// The first "yes" test's patch: the points within kPatchRadius sqrt(alpha) of the middle (a disk
/// of area pi alpha), thinned to one per cell of side sqrt(alpha) / kPatchCells, give a lower
/// bound (alphaShapeAreaLowerBound holds for any subset). Regions hold every input point, so at
/// coarse scales the certified patch below held tens of thousands of them, costly to
/// triangulate; the thinned patch keeps ~200 points.
constexpr double kPatchRadius = 1.0;
constexpr double kPatchCells = 8;

bool alphaShapeAreaAtLeast(const std::vector<Vec2>& points, double alpha, double minArea) {
  if (points.size() < 3 || !(alpha > 0)) return 0 >= minArea;
  // "No" from an upper bound: the interior triangles are Delaunay triangles, which tile a subset
  // of the convex hull, itself inside the bounding box. Most small regions fail this at once.
  Eigen::AlignedBox2d box;
  for (const Vec2& p : points) box.extend(p);
  if (box.volume() < minArea) return false;
  // "Yes" from a patch around the middle (certifiedArea), when the patch is a small part of a
  // large set. Tried before the convex hull below: almost every large region passes here, and
  // the hull of all its points cost as much as the patch.
  if (points.size() >= 64) {
    Vec2 mean = Vec2::Zero();
    for (const Vec2& p : points) mean += p;
    mean /= double(points.size());
    Vec2 centre = points.front();
    for (const Vec2& p : points)
      if ((p - mean).squaredNorm() < (centre - mean).squaredNorm()) centre = p;
    const double radius = kPatchRadius * std::sqrt(alpha);
    std::vector<Vec2> patch;
    for (const Vec2& p : points)
      if ((p - centre).squaredNorm() < radius * radius) patch.push_back(p);
    if (alphaShapeAreaLowerBound(patch, alpha, std::sqrt(alpha) / kPatchCells) >= minArea)
      return true;
    // Else the points within 2 sqrt(alpha), all of them, when they are a small part of the set.
    const double reach = 2 * std::sqrt(alpha);
    std::size_t near = 0;
    for (const Vec2& p : points) near += (p - centre).squaredNorm() < reach * reach ? 1 : 0;
    if (2 * near < points.size() && certifiedArea(points, centre, reach, alpha) >= minArea)
      return true;
  }
  // "No" from the convex hull's area (a bound as above). On a 200k-point Stairs scene most large
  // regions the filter rejects at coarse scales fail it.
  const std::vector<Kernel::Point_2> cgalPoints = toCgal(points);
  std::vector<Kernel::Point_2> hull;
  CGAL::convex_hull_2(cgalPoints.begin(), cgalPoints.end(), std::back_inserter(hull));
  const double hullArea = CGAL::polygon_area_2(hull.begin(), hull.end(), Kernel());
  if (std::abs(hullArea) * (1 + 1e-9) < minArea) return false;
  // "Yes" from a subset: coarse-scale regions lie within a few radii of their middle, so the
  // patch is the whole set; one point per cell of radius / 32 keeps a few thousand of them.
  // Triangulating whole shapes was most of the filter's time (filtering in bench/bench_planes).
  const double cell = std::sqrt(alpha) / 32;
  const double cells = box.volume() / (cell * cell);  // at most this many subset points
  if (points.size() >= kSubsetPoints && 4 * cells < double(points.size()) &&
      alphaShapeAreaLowerBound(points, alpha, cell) >= minArea)
    return true;
  return alphaShapeOf(cgalPoints, alpha, false).area >= minArea;
}

}  // namespace scalespace
