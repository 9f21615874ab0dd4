#pragma once
// Merging adjacent regions of one scale whose union a plane describes (a departure from Sec.
// 2.3.1, whose regions are grown against the seed's normal alone: docs/THESIS_NOTES.md,
// coplanar merging). A staircase should be, at scales of a few steps, its mean ramp; but the
// robust fit keeps its treads flat at every scale, so the region growing never crosses a riser
// and each tread, narrower than the alpha-shape filter's 2t, is then dropped. The union of the
// treads and risers is what a plane describes within a fraction of t: merged before the filter,
// it is a region of its own. The same test joins a recessed window or a raised tile to its wall
// or roof once the scale is coarse enough to see them as one surface.
#include <cstdint>
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/RegionGrower.hpp"

namespace scalespace {

struct RegionMergeOptions {
  /// Two regions adjacent in the k-NN graph are merged when the RMS distance of the union's points
  /// to its least-squares plane is at most maxRelativeRms * t ... (0: no merging, the thesis)
  double maxRelativeRms = 0.1;
  /// ... and no point of the union lies farther than maxRelativeDeviation * t from that plane
  /// (bounded through the bounding boxes, along their own planes' axes, of the grown regions that
  /// make the union, and checked on the points where those boxes exceed it): a box standing on
  /// the ground is never its plane's outlier.
  double maxRelativeDeviation = 0.3;
  /// Nothing is merged where maxRelativeRms * t is below noiseFactor times the sensor noise sigma
  /// (t < 50 sigma with the defaults): there the fit's normals scatter beyond the growing's angle
  /// and the small regions are fragments of noise, which merged would split a flat floor into
  /// many planes.
  double noiseFactor = 5.0;
  /// A union narrower than this fraction of t (the shorter side of its box in its plane) is undone:
  /// the slivers that the robust fit leaves along a crease would make a bevel that no surface has.
  double minRelativeWidth = 1.0;
  /// A union whose plane is within parallelDegrees of the plane of a large grown region next to it,
  /// and whose centroid lies within maxRelativeDeviation * t of that plane, is undone when that
  /// region does not take it (below): it is the region's own surface cut off by the growing's step
  /// limit (a floor's far corner among clutter, the rounded rim of a table top), not a second
  /// plane.
  /// 0: such unions stay.
  double parallelDegrees = 5.0;
};

/// What a region of the merged segmentation is: a grown region smaller than the filter's area
/// (left alone: none of its neighbours made a plane with it), a grown region large enough to
/// stand alone, or the union of several small ones.
enum class RegionOrigin : std::uint8_t { small, large, merged };

/// OptionError naming the field unless the bounds and noiseFactor are finite and >= 0 and
/// parallelDegrees is in [0, 90).
void validate(const RegionMergeOptions& options);

/// The regions of `segmentation` (over `positions`, adjacency from `knn`) merged pairwise, the
/// pair whose union has the smallest RMS first, while a pair passes both tests and both are made
/// of small grown regions: the in-plane area of each one's box is below `smallArea`, the area
/// that the filter asks of a region at this scale. Only pieces that the filter would drop are
/// joined; a region that stands alone is left as grown (a wall does not take its windows, nor a
/// roof its tiles: they are faces at the scales where they are regions). A union (not a single
/// small region) then joins a large region next to it whose own plane describes it within the
/// same bounds and as well as the large region's own points (RMS within 1.25 times theirs, or
/// twice the noise): a staircase whose lower steps grew as one region is one ramp; a union parallel
/// to a large region next to it that the region does not take is undone (parallelDegrees). Regions
/// of the result are ordered by their first grown region, point lists increasing, labels updated.
/// Sequential and deterministic (same result for any thread count). `noiseRms` is the cloud's
/// sensor noise (pointNoiseRms). When `origins` is given, it receives each resulting region's
/// origin, or is left empty where nothing could merge at this scale.
Segmentation mergeCoplanarRegions(const std::vector<Vec3>& positions, const KnnGraph& knn,
                                  Segmentation segmentation, double t, double smallArea,
                                  double noiseRms, const RegionMergeOptions& options = {},
                                  std::vector<RegionOrigin>* origins = nullptr);

}  // namespace scalespace
