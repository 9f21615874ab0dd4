#pragma once
// What the meshless measures of Chapter 4 compare: the neighbourhood of a point seen in 3D, in
// its tangent plane (the P_i of Eq. 4.1), and the same neighbours seen in the parameter domain
// (Eq. 4.2), with the smooth decreasing weights w_ij of Eq. 4.1-4.2.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/param/ParamDomain.hpp"

namespace scalespace {

struct LocalMapSample {
  std::vector<Vec2> tangent;  // p_j - p_i in the tangent plane at p_i (basis t1 x t2 = n_i)
  std::vector<Vec2> domain;   // where j lands seen from i in the domain (DomainMap::localOffset)
  std::vector<double> weight;
  std::vector<double> distance;                 // |p_j - p_i| in 3D
  std::vector<Index> index;                     // j
  double radius = 0;                            // support of the weights
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();  // the tangent basis of `tangent`
};

/// The k nearest neighbours of point i in 3D (i itself included), weighted by the kernel of
/// Eq. 1.6, (1 - d^2 / r^2)^4, with r just beyond the k-th neighbour (the (k+1)-th's distance),
/// so every neighbour weighs. `normal` gives the tangent plane (a zero normal: the neighbours'
/// PCA plane). `neighbors` is scratch.
void gatherLocalMap(std::size_t i, std::size_t k, const std::vector<Vec3>& positions,
                    const Vec3& normal, const SpatialIndex& index, const DomainMap& domain,
                    LocalMapSample& sample, std::vector<Neighbor>& neighbors);

/// Calls visit(i, sample, scratch) for every point i with its gathered LocalMapSample (k
/// neighbours, `normals` empty or one per point), in parallel over fixed blocks, so the result of
/// a visitor that writes entry i only is the same for any thread count; `scratch` is a sample the
/// visitor may use as it likes (truncateLocalMap). Advances `tracker` by the points visited.
template <class Visit>
void forEachLocalMap(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                     const SpatialIndex& index, const DomainMap& domain, std::size_t k,
                     ProgressTracker& tracker, Visit visit) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      LocalMapSample sample, scratch;
                      std::vector<Neighbor> neighbors;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        gatherLocalMap(i, k, positions, normals.empty() ? Vec3::Zero() : normals[i],
                                       index, domain, sample, neighbors);
                        visit(i, sample, scratch);
                      }
                      tracker.advance(range.size());
                    });
}

/// Keeps the first k entries of a sample gathered with a larger k (neighbours sorted by
/// distance) and re-weights them for that size.
void truncateLocalMap(const LocalMapSample& from, std::size_t k, LocalMapSample& to);

/// The weighted 2 x 2 covariance of points around their weighted mean (Eq. 4.1-4.2).
Eigen::Matrix2d weightedCovariance(const std::vector<Vec2>& points,
                                   const std::vector<double>& weights);

}  // namespace scalespace
