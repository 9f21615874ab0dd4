#pragma once
// Normals for a cloud that has none: estimated (NormalEstimation.hpp) and oriented
// (NormalOrientation.hpp) in one call, as every command does for such a cloud.
//
// Sheet normals (NormalEstimationOptions::sheetTolerance) are right at creases and where two
// surfaces touch, but jump there: across the narrow gap between two touching strands of a cable
// they are antiparallel, Hoppe's cost 1 - |cos| is 0, and the tree that propagates the sign
// crosses the gap and turns a whole strand inside out (the pipe rack of bench_cylinders, clean full
// scan: one strand 99.8% against the exact normals). The PCA normals turn smoothly across the gap.
// With SheetSign::FromPlanes the orientation runs on the PCA normals, and each sheet normal takes
// the sign of its point's oriented PCA normal: the right one wherever the PCA normal is less than
// 90 degrees off.
#include <cstdint>
#include <vector>

#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"

namespace scalespace {

/// Which normals the orientation runs on when sheet normals are estimated.
enum class SheetSign {
  OwnTree,     // the sheet normals themselves
  FromPlanes,  // the PCA normals; each sheet normal takes its point's sign (file comment)
  /// Both, keeping the one whose normals the visibility rays find facing inward at fewer points
  /// (compareByRays; ties: OwnTree). Neither wins everywhere: a CAD part's thin blade keeps its
  /// sides apart only with its own tree, a rotor's rims only with the PCA signs.
  ByRays,
};

struct OrientedNormalsOptions {
  NormalEstimationOptions estimation;
  NormalOrientationOptions orientation;
  SheetSign sheetSign = SheetSign::OwnTree;
};

struct OrientedNormals {
  std::vector<Vec3> normals;  // unit, oriented
  /// Its `normals` moved to the field above; with SheetSign::FromPlanes its planeNormals come
  /// back oriented.
  NormalEstimationResult estimation;
  /// Of the normals the tree ran on: with SheetSign::FromPlanes its flippedCount counts PCA
  /// normals, and `reliable` also flags the sheet normals whose sign is a guess.
  NormalOrientationResult orientation;
  /// The sign source the normals have (with SheetSign::ByRays, the one kept), and with ByRays
  /// the rays' comparison of the two (first: the own tree, second: the PCA signs).
  SheetSign signSource = SheetSign::OwnTree;
  RayComparison rays;
};

/// Estimates and orients the normals of `points` with `index` (built on the same points).
/// With SheetSign::FromPlanes a point whose sheet and PCA normals make a |cos| under
/// NormalOrientationOptions::creaseThreshold is flagged unreliable: its sign is a guess.
/// Deterministic for any thread count. Throws as the two steps do.
OrientedNormals estimateOrientedNormals(const std::vector<Vec3>& points, const SpatialIndex& index,
                                        const OrientedNormalsOptions& options = {},
                                        const ProgressCallback& progress = {});

}  // namespace scalespace
