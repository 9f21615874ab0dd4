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
  /// (Not in Hoppe 1992.) Under noise comparable to the sampling a k-neighbourhood's PCA plane
  /// follows the noise: k doubles, up to maxK, while the normals of k and 2k neighbours differ by
  /// more than maxNoiseAngleDegrees (median over a sample of the points, unsigned). Clean and
  /// moderately noisy clouds keep k: the real table scan (9.9 degrees between 10 and 20), the
  /// libcgal-demo point sets and CAD parts under noise 1e-3 of the diagonal at 100k points (7.5
  /// for rotor); the pipe rack at 1M points under the same noise goes to 40 (29.3, then 13.8 and
  /// 6.1 degrees; with k = 10, 57% of its normals were more than 30 degrees off, 1.3% with 40).
  /// maxK = k (or a radius) turns it off. NormalEstimationResult::k is the count used.
  std::size_t maxK = 80;
  double maxNoiseAngleDegrees = 12.0;
  /// A neighbourhood is degenerate (normal flagged invalid) when it has fewer than 3 distinct
  /// points or is colinear: middle eigenvalue <= colinearity * largest eigenvalue.
  double colinearity = 1e-8;
  /// Sheet normals (not in Hoppe 1992; 0: the PCA normal of every neighbourhood). Of the planes
  /// through the point and two of its neighbours, the one that the most neighbours lie within a
  /// band of (half-width sheetTolerance times the distance to the farthest neighbour, or
  /// sheetNoiseFactor times the cloud's noise, noiseRms below, whichever is larger), refitted to
  /// those neighbours: at a crease, the plane of the side the point is on rather than the average
  /// of both; on a part thinner than the sampling (a blade's rim), the plane of its own side
  /// rather than one tilted through both. A neighbourhood whose PCA plane's RMS is within the
  /// band (smooth, curved or noisy) keeps its PCA normal (8: with 4 the noisy CAD clouds and the
  /// real table scan lost to PCA; docs/THESIS_NOTES.md, "Feature curves", sheet normals).
  double sheetTolerance = 0.0;
  double sheetNoiseFactor = 8.0;
};

struct NormalEstimationResult {
  std::vector<Vec3> normals;  // unit length for every point (flagged ones included), unoriented
  /// With sheet normals (NormalEstimationOptions::sheetTolerance > 0): every point's PCA normal,
  /// unoriented (core/OrientedNormals orients by them). Empty otherwise.
  std::vector<Vec3> planeNormals;
  /// Surface variation lambda0 / (lambda0 + lambda1 + lambda2) in [0, 1/3] [Pauly 2002, Eq. 5]:
  /// 0 on a plane, larger on curved or noisy parts; 1/3 where flagged.
  std::vector<double> surfaceVariation;
  std::vector<std::uint8_t> valid;  // 0 = degenerate neighbourhood (see the options)
  std::size_t invalidCount = 0;
  /// The median over the valid points of the RMS distance of their neighbourhood to its PCA
  /// plane: the sensor noise where the surface is smooth at the neighbourhood's size.
  double noiseRms = 0.0;
  /// The neighbour count used (NormalEstimationOptions::maxK); 0 with a radius.
  std::size_t k = 0;
};

/// Estimates one normal per point of `points` using `index` (built on the same points).
/// Reorder the points with spatialOrder() first: on points in random order this is much faster
/// (bench/bench_spatial_index.cpp measures both orders).
/// Parallel and deterministic (each point is computed independently). Throws OptionError for
/// k < 3 (radius == 0), a negative/non-finite radius or sheet option, Cancelled if `progress`
/// returns false.
NormalEstimationResult estimateNormals(const std::vector<Vec3>& points, const SpatialIndex& index,
                                       const NormalEstimationOptions& options = {},
                                       const ProgressCallback& progress = {});

/// Same, building the default index internally.
NormalEstimationResult estimateNormals(const std::vector<Vec3>& points,
                                       const NormalEstimationOptions& options = {},
                                       const ProgressCallback& progress = {});

}  // namespace scalespace
