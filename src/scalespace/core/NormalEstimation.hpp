#pragma once
// Normal estimation for clouds without normals: PCA of the neighbourhood of each point (the
// normal is the eigenvector of the smallest eigenvalue of the local covariance, [Hoppe 1992],
// thesis §1.1 "covariance analysis"). Normals are unit but unoriented: orient them with
// orientNormals() (NormalOrientation.hpp).
#include <cstdint>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct NormalEstimationOptions {
  /// Neighbourhood: the k nearest neighbours (the point itself included) when radius == 0,
  /// otherwise all points with |p - q| < radius.
  std::size_t k = 10;
  double radius = 0.0;
  /// A neighbourhood is degenerate (normal flagged invalid) when it has fewer than 3 distinct
  /// points or is colinear: middle eigenvalue <= colinearity * largest eigenvalue.
  double colinearity = 1e-8;
};

struct NormalEstimationResult {
  std::vector<Vec3> normals;  // unit length for every point (flagged ones included), unoriented
  /// Surface variation lambda0 / (lambda0 + lambda1 + lambda2) in [0, 1/3] [Pauly 2002, Eq. 5]:
  /// 0 on a plane, larger on curved or noisy parts; 1/3 where flagged.
  std::vector<double> surfaceVariation;
  std::vector<std::uint8_t> valid;  // 0 = degenerate neighbourhood (see the options)
  std::size_t invalidCount = 0;
};

/// Estimates one normal per point of `points` using `index` (built on the same points).
/// Reorder the points with spatialOrder() first: on points in random order this is much faster
/// (bench/bench_spatial_index.cpp measures both orders).
/// Parallel and deterministic (each point is computed independently). Throws OptionError for
/// k < 3 (radius == 0) or a negative/non-finite radius, Cancelled if `progress` returns false.
NormalEstimationResult estimateNormals(const std::vector<Vec3>& points, const SpatialIndex& index,
                                       const NormalEstimationOptions& options = {},
                                       const ProgressCallback& progress = {});

/// Same, building the default index internally.
NormalEstimationResult estimateNormals(const std::vector<Vec3>& points,
                                       const NormalEstimationOptions& options = {},
                                       const ProgressCallback& progress = {});

}  // namespace scalespace
