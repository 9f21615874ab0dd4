#pragma once
// What the thesis names as the main limitation of its parametrization (Sec. 4.3, 4.5), detected
// point by point:
//  - folds: where the local map from the surface to the domain reverses orientation with respect
//    to the majority of the points. The local map is the weighted least-squares linear map A_i
//    taking the tangent-plane offsets of the point's 3D neighbours to their domain offsets
//    (LocalMapSample); a fold is det A_i of the minority's sign.
//  - overlaps: points that land close in the domain but are far apart on the surface: among the
//    point's nearest neighbours in the domain, one lies farther in 3D than `overlapFactor` times
//    what the local map allows (domain distance / smallest singular value of A_i, and at least
//    the 3D neighbourhood's radius).
// A surface that is not of genus 0 (a torus) cannot be mapped without them: many flagged points
// are the message that the map is not one-to-one.
#include <cstdint>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/param/ParamDomain.hpp"

namespace scalespace {

struct MapDefectOptions {
  int neighbors = 16;        // 3D neighbours of the local map
  int domainNeighbors = 8;   // domain neighbours checked for overlaps
  double overlapFactor = 4;  // how much farther than the local map allows
  /// A local map whose singular values differ by more than this ratio is too degenerate to tell
  /// an orientation (its points are nearly collinear in 3D or in the domain): no verdict.
  double maxConditionNumber = 1e4;
};

/// OptionError naming the field unless neighbors >= 3, domainNeighbors >= 1, overlapFactor > 1
/// and maxConditionNumber > 1 (finite).
void validateMapDefectOptions(const MapDefectOptions& options);

struct MapDefects {
  std::vector<std::uint8_t> fold, overlap;  // per point, 1 = flagged
  /// Per point: sqrt|det A_i|, the local map's area scale (domain length per 3D length), 0 where
  /// the map had no verdict.
  std::vector<float> localScale;
  /// Per point: the ratio of A_i's singular values, largest over smallest, the exact conformal
  /// distortion of the local map (1: circles stay circles, 2: twice stretched one way); 0 where
  /// the map had no verdict. Eq. 4.3 compares the anisotropies of two neighbourhood ellipses
  /// instead, which under-reads a stretch where the 3D neighbourhood is itself anisotropic.
  std::vector<float> stretch;
  double medianStretch = 0, p90Stretch = 0;  // over the points with a verdict
  std::size_t folds = 0, overlaps = 0, undetermined = 0;
  int majoritySign = 1;  // orientation of most local maps
};

/// Checks the map of `positions` (the input cloud, with oriented `normals` or none) to `domain`
/// (same order). Throws OptionError on sizes that differ or invalid options; Cancelled through
/// `progress`. Identical results for any thread count.
MapDefects findMapDefects(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                          const DomainMap& domain, const MapDefectOptions& options = {},
                          const ProgressCallback& progress = {});

}  // namespace scalespace
