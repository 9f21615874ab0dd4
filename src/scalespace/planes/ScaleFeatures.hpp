#pragma once
// The input of the plane pipeline (Chapter 2): per scale, the differential quantities of every
// input point from the multi-scale stack (the k-nearest-neighbour graph is core/KnnGraph.hpp).
// The stack of the scales layer is converted to this; tests build it from analytic surfaces.
#include <cstdint>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

/// One scale t_j of the stack.
struct ScaleFeatures {
  double t = 0.0;                   // scale value
  std::vector<Vec3> normals;        // per input point, unit (W3 of the APSS fit)
  std::vector<float> kMax, kMin;    // principal curvatures (Eq. 1.38)
  std::vector<std::uint8_t> valid;  // 0 where the fit failed: such points join no region
  /// Per input point, its projection at t (same frame as the cloud's positions); may be empty
  /// unless RegionGrowingOptions::maxStep is set.
  std::vector<Vec3> projections;
};

/// Throws OptionError when a scale's arrays do not have `pointCount` entries or scales are not
/// strictly increasing.
void checkScaleFeatures(const std::vector<ScaleFeatures>& scales, std::size_t pointCount);

}  // namespace scalespace
