#pragma once
// Whether a plane describes a region at its scale, and the chains that this splits (a departure
// from Sec. 2.3.1-2.3.2, whose filter is the alpha-shape area alone and whose graph links any
// regions of consecutive scales with Jaccard > 0.5: docs/THESIS_NOTES.md, planarity split).
// A chain can grow by less than half at each step and drift from a ground into the walls and roof
// standing on it; its one plane then describes none of its points. Non-planar regions are kept
// (a staircase's mean ramp is one, and worth finding) but never linked to planar ones, so such a
// chain splits into a planar component and a non-planar one, flagged.
#include <cstdint>
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/RegionGraph.hpp"
#include "scalespace/scales/PointNoise.hpp"

namespace scalespace {

struct PlanarityOptions {
  /// A region is planar when the RMS distance of its input points to their least-squares plane
  /// is at most max(maxRelativeRms * t, noiseFactor * noise). 0: every region is planar (the
  /// thesis' graph).
  double maxRelativeRms = 0.05;
  /// Sensor noise puts a flat region's RMS at sigma whatever its scale, so 5% of a scale below
  /// 20 sigma cannot hold: the floor is noiseFactor times the noise (pointNoiseRms).
  double noiseFactor = 2.0;
};

/// OptionError naming the field unless maxRelativeRms and noiseFactor are finite and >= 0.
void validate(const PlanarityOptions& options);

/// Per level and region, 1 when the region is planar (PlanarityOptions), else 0: the kinds that
/// buildRegionGraph keeps apart. Parallel over regions; independent of the thread count.
std::vector<std::vector<std::uint8_t>> regionPlanarity(const std::vector<Vec3>& positions,
                                                       const std::vector<RegionLevel>& levels,
                                                       double noise,
                                                       const PlanarityOptions& options = {});

}  // namespace scalespace
