#pragma once
// The sensor noise of a cloud, read from the points themselves: what the planes' planarity floor
// (planes/RegionPlanarity.hpp) and the feature curves' salient bound (features/FeatureCurves.hpp)
// scale with, so that one set of defaults holds on clean CAD samples and on noisy scans.
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// The sensor noise: the median over the points of the RMS distance of the point and its graph
/// neighbours to their least-squares plane (sqrt of the covariance's smallest eigenvalue, times
/// sqrt(m / (m - 3)) for the m points, the plane's three degrees of freedom), or 0 for an empty
/// graph. On flat parts it is the noise's sigma; curvature and edges touch few points.
double pointNoiseRms(const std::vector<Vec3>& positions, const KnnGraph& knn);

}  // namespace scalespace
