#pragma once
// CGAL Efficient RANSAC [Schnabel 2007], the plane-detection peer of Sec. 2.5.2, shared by the
// plane benchmarks: disjoint point sets, one per detected plane, in the cloud's indices.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>

#include <chrono>
#include <tuple>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::bench {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// A detection: disjoint point sets, one per plane.
struct Detection {
  std::vector<std::vector<Index>> planes;
  double seconds = 0;
};

/// Efficient RANSAC's parameters; a negative value (0 for minPoints) keeps CGAL's documented
/// default (epsilon and cluster epsilon 1 % of the bounding box, min points 1 % of the points,
/// normal threshold 0.9).
struct RansacSettings {
  double epsilon = -1, clusterEpsilon = -1, normalThreshold = -1;
  std::size_t minPoints = 0;
};

/// Planes only, on the cloud's positions and normals; `seconds` is the detection alone.
inline Detection runRansac(const PointCloud& cloud, const RansacSettings& settings = {}) {
  // Efficient RANSAC reorders its input range: each point carries its original index.
  using Item = std::tuple<Kernel::Point_3, Kernel::Vector_3, std::size_t>;
  using Items = std::vector<Item>;
  using ItemPointMap = CGAL::Nth_of_tuple_property_map<0, Item>;
  using ItemNormalMap = CGAL::Nth_of_tuple_property_map<1, Item>;
  using Traits =
      CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, Items, ItemPointMap, ItemNormalMap>;
  using Ransac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
  using Plane = CGAL::Shape_detection::Plane<Traits>;
  Items points;
  points.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.positions()[i];
    const Vec3& n = cloud.normals()[i];
    points.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), Kernel::Vector_3(n.x(), n.y(), n.z()),
                        i);
  }
  const auto start = std::chrono::steady_clock::now();
  Ransac ransac;
  ransac.set_input(points);
  ransac.add_shape_factory<Plane>();
  typename Ransac::Parameters parameters;  // CGAL's defaults unless set
  if (settings.epsilon >= 0) parameters.epsilon = settings.epsilon;
  if (settings.clusterEpsilon >= 0) parameters.cluster_epsilon = settings.clusterEpsilon;
  if (settings.normalThreshold >= 0) parameters.normal_threshold = settings.normalThreshold;
  if (settings.minPoints > 0) parameters.min_points = settings.minPoints;
  ransac.detect(parameters);
  Detection d;
  for (const auto& shape : ransac.shapes()) {
    std::vector<Index> plane;
    for (std::size_t i : shape->indices_of_assigned_points())
      plane.push_back(Index(std::get<2>(points[i])));
    d.planes.push_back(std::move(plane));
  }
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace scalespace::bench
