#include "scalespace/planes/AlphaShapeArea.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_2.h>
#include <CGAL/convex_hull_2.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <map>

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
// builds the whole alpha spectrum: with it, the components of a 1M-point Stairs scene took 25 s,
// now 2 s.
AlphaShape alphaShapeOf(const std::vector<Kernel::Point_2>& points, double alpha,
                        bool withOutlines) {
  AlphaShape result;
  if (points.size() < 3 || !(alpha > 0)) return result;
  Delaunay dt(points.begin(), points.end());
  const auto squaredRadius = Kernel().compute_squared_radius_2_object();
  const auto area = Kernel().compute_area_2_object();
  for (auto f = dt.all_faces_begin(); f != dt.all_faces_end(); ++f) f->info() = false;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const auto& a = f->vertex(0)->point();
    const auto& b = f->vertex(1)->point();
    const auto& c = f->vertex(2)->point();
    if (!(squaredRadius(a, b, c) <= alpha)) continue;
    f->info() = true;
    result.area += std::abs(CGAL::to_double(area(a, b, c)));
  }
  if (!withOutlines) return result;

  // Boundary edges oriented counter-clockwise around their interior face, chained into loops by
  // their start point (coordinates, not handles, so that the loop order is reproducible).
  std::multimap<std::pair<double, double>, std::pair<double, double>> next;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    if (!f->info()) continue;
    for (int i = 0; i < 3; ++i) {
      if (f->neighbor(i)->info()) continue;  // infinite faces are never interior
      const auto& a = f->vertex(Delaunay::ccw(i))->point();
      const auto& b = f->vertex(Delaunay::cw(i))->point();
      next.emplace(std::make_pair(a.x(), a.y()), std::make_pair(b.x(), b.y()));
    }
  }
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

}  // namespace

AlphaShape alphaShape2(const std::vector<Vec2>& points, double alpha, bool withOutlines) {
  return alphaShapeOf(toCgal(points), alpha, withOutlines);
}

bool alphaShapeAreaAtLeast(const std::vector<Vec2>& points, double alpha, double minArea) {
  if (points.size() < 3 || !(alpha > 0)) return 0 >= minArea;
  // "No" from upper bounds: the interior triangles are Delaunay triangles, which tile a subset of
  // the convex hull, itself inside the bounding box. On a 200k-point Stairs scene most large
  // regions the filter rejects at coarse scales fail one of these.
  Eigen::AlignedBox2d box;
  for (const Vec2& p : points) box.extend(p);
  if (box.volume() < minArea) return false;
  const std::vector<Kernel::Point_2> cgalPoints = toCgal(points);
  std::vector<Kernel::Point_2> hull;
  CGAL::convex_hull_2(cgalPoints.begin(), cgalPoints.end(), std::back_inserter(hull));
  const double hullArea = CGAL::polygon_area_2(hull.begin(), hull.end(), Kernel());
  if (std::abs(hullArea) * (1 + 1e-9) < minArea) return false;
  // "Yes" from a patch around the middle (certifiedArea), when the patch is a small part of a
  // large set; otherwise the whole shape decides.
  const double reach = 2 * std::sqrt(alpha);
  if (points.size() >= 64) {
    Vec2 mean = Vec2::Zero();
    for (const Vec2& p : points) mean += p;
    mean /= double(points.size());
    Vec2 centre = points.front();
    for (const Vec2& p : points)
      if ((p - mean).squaredNorm() < (centre - mean).squaredNorm()) centre = p;
    std::size_t near = 0;
    for (const Vec2& p : points) near += (p - centre).squaredNorm() < reach * reach ? 1 : 0;
    if (2 * near < points.size() && certifiedArea(points, centre, reach, alpha) >= minArea)
      return true;
  }
  return alphaShapeOf(cgalPoints, alpha, false).area >= minArea;
}

PlaneFit fitPlane(const std::vector<Vec3>& positions, const std::vector<Index>& indices) {
  PlaneFit fit;
  if (indices.size() < 3) return fit;
  Vec3 c = Vec3::Zero();
  for (Index i : indices) c += positions[i];
  c /= double(indices.size());
  Mat3 cov = Mat3::Zero();
  for (Index i : indices) {
    const Vec3 d = positions[i] - c;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  fit.centroid = c;
  fit.normal = eig.eigenvectors().col(0).normalized();
  fit.axisU = eig.eigenvectors().col(2).normalized();
  fit.axisV = fit.normal.cross(fit.axisU);
  fit.offset = fit.normal.dot(c);
  // The smallest eigenvalue is the sum of squared distances to the plane.
  fit.rms = std::sqrt(std::max(0.0, eig.eigenvalues()(0)) / double(indices.size()));
  fit.valid = true;
  return fit;
}

std::vector<Vec2> projectOnPlane(const PlaneFit& plane, const std::vector<Vec3>& positions,
                                 const std::vector<Index>& indices) {
  std::vector<Vec2> out;
  out.reserve(indices.size());
  for (Index i : indices) {
    const Vec3 d = positions[i] - plane.centroid;
    out.emplace_back(d.dot(plane.axisU), d.dot(plane.axisV));
  }
  return out;
}

Vec3 liftFromPlane(const PlaneFit& plane, const Vec2& p) {
  return plane.centroid + p.x() * plane.axisU + p.y() * plane.axisV;
}

}  // namespace scalespace
