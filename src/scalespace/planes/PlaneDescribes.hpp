#pragma once
// "A large region's plane describes these points": one rule for the merging's join of a union to
// a large region (planes/RegionMerging) and the refinement's give-back of a union's points to one
// (planes/BoundaryRefinement), so that the two cannot drift apart. Neither is in Sec. 2.3.1
// (docs/THESIS_NOTES.md, coplanar merging and boundary refinement).
#include <algorithm>

namespace scalespace {

/// The points' RMS (or distance) to the plane may exceed the region's own RMS by this factor: the
/// exact face of a box then does not take the bent normals along its edge, which carry points of
/// the next face.
constexpr double kPlaneDescribesTolerance = 1.25;

/// The largest RMS or distance to a region's plane that the plane still describes: `tolerance`
/// times the region's own RMS, or the noise floor where the region is flatter than the noise.
inline double planeDescribesBound(double regionRms, double noiseFloor,
                                  double tolerance = kPlaneDescribesTolerance) {
  return tolerance * std::max(regionRms, noiseFloor);
}

}  // namespace scalespace
