#pragma once
// The sensor noise of a cloud, read from the points themselves: what the planes' planarity floor
// (planes/RegionPlanarity.hpp) and the feature curves' salient bound (features/FeatureCurves.hpp)
// scale with, so that one set of defaults holds on clean CAD samples and on noisy scans.
#include <cstddef>
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// The sensor noise: the median over the points of the RMS distance of the point and its graph
/// neighbours to their least-squares plane (sqrt of the covariance's smallest eigenvalue, times
/// sqrt(m / (m - 3)) for the m points, the plane's three degrees of freedom), or 0 for an empty
/// graph. On flat parts it is the noise's sigma; curvature and edges touch few points.
double pointNoiseRms(const std::vector<Vec3>& positions, const KnnGraph& knn);

struct SurfaceNoiseOptions {
  /// Neighbours of each read point the quadric is fitted to (the point itself included). Wider
  /// than the plane's 10: when sigma nears a third of the spacing, the 10 nearest points hug a
  /// plane through the noise and read it low (0.23 e for a true 0.34 e); 30 read 0.37 e.
  int neighbors = 30;
  /// Points read, evenly spread over the input order (all when fewer): a median over 20,000 is
  /// within 1% of the median over all, at a fiftieth of the cost on 1M points.
  std::size_t maxSamples = 20000;
};

/// The sensor noise when the points lie on a curved surface: the median over the read points of
/// the RMS residual of the height field z = quadric(x, y) fitted by least squares to the point's
/// neighbours in their PCA frame, times sqrt(m / (m - 6)) for its six coefficients. A quadric
/// takes up the surface's curvature, which the plane of pointNoiseRms reads as noise (0.035 e on
/// a clean kitten against 0.024 e). `index` is built on `positions`. 0 for fewer than 7 points.
double surfaceNoiseRms(const std::vector<Vec3>& positions, const SpatialIndex& index,
                       const SurfaceNoiseOptions& options = {});

}  // namespace scalespace
