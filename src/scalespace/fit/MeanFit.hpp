#pragma once
// "Mean" / "Average" baseline of Sec. 1.4.3: weighted barycentre and weighted mean normal, H =
// 8 d / t^2 with d the signed distance of x to the plane through the barycentre (see PlaneFit.hpp
// for the conventions shared with the Plane estimator). Needs normals.
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

LocalFit fitMean(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                 const SurfaceSamples& samples, int minNeighbors);

}  // namespace scalespace
