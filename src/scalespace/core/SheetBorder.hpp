#pragma once
// How far a point sits at the border of the surface its neighbours sample: the offset of the
// neighbours' centroid from the point, in the plane of their best fit (PCA), over the radius.
// Inside a uniformly sampled sheet the neighbours surround the point and the share is about 0
// (noise: about 0.5 / sqrt(count)); on a straight border they fill a half disc and it is
// 4 / (3 pi) = 0.42; at a distance d inside the border it falls to 0.17 at d = r / 2 and to 0 at
// d = r. A surface folded back on itself more tightly than the noise (the rim of a blade thinner
// than a few noise sigmas) reads as a border too: its two sides are one noisy sheet.
#include <cstdint>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct SheetBorderOptions {
  double radius = 0;         // of the neighbourhood; must be > 0
  std::size_t minCount = 8;  // fewer neighbours (the point included) read 0: too few to tell
  /// Neighbours that do not lie near a plane read 0: no sheet, no border (a volume, a corner of
  /// three faces, a cap smaller than the radius). The surface variation lambda0 / (lambda0 +
  /// lambda1 + lambda2) is 1/3 in a ball; on a half disc of a sheet whose off-plane spread is a
  /// fifth of the radius (two sides merged by noise: bench_features' noisy blade) 0.125.
  double maxVariation = 0.2;
};

/// Per query, the border share above (0 where fewer than minCount points lie within the radius,
/// and where `skip` is given and non-zero). `index` holds `positions`. Identical for any thread
/// count.
std::vector<float> sheetBorderShare(const std::vector<Vec3>& positions, const SpatialIndex& index,
                                    const std::vector<Vec3>& queries,
                                    const SheetBorderOptions& options,
                                    const std::vector<std::uint8_t>& skip = {});

}  // namespace scalespace
