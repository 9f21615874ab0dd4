#pragma once
// Setting the boundary of a merged region (planes/RegionMerging.hpp) by distance to its plane
// rather than by normals (a departure from Sec. 2.3.1: docs/THESIS_NOTES.md, boundary refinement).
// A grown region is the set of points whose normal at t is within theta of its seed's, and its
// boundary is where the normals turn. A merged union has no such normal: its plane (a staircase's
// mean ramp) is not the plane of any of its pieces, so where it meets another surface its edge is
// wherever the robust fit let the other surface's normal win. At t = 0.8 m the vertical side of
// a 1.2 m-wide staircase takes the outer 0.2-0.3 m of every tread, points 0.1-0.3 m off that
// side's plane and a few cm off the ramp's: the union loses its edges and the side's plane no
// longer describes its points.
#include <cstdint>
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/RegionGrower.hpp"
#include "scalespace/planes/PlaneDescribes.hpp"
#include "scalespace/planes/RegionMerging.hpp"

namespace scalespace {

struct BoundaryRefinementOptions {
  /// A point of region A next (in the k-NN graph) to a point of a merged region B moves to B when
  /// it is nearer to B's least-squares plane than to A's and B's plane lies within
  /// maxRelativeDistance * t of it (0: no refinement).
  double maxRelativeDistance = 0.3;
  /// ... by more than minRelativeGain * t and noiseFactor times the sensor noise sigma: two
  /// regions of one surface (split by the step limit, a crease of less than theta, or the fit's
  /// rounding) have planes a little apart, and with no margin one would take all of the other.
  /// Noise must not shuffle the points along a crease between two planes equally near.
  double minRelativeGain = 0.05;
  /// Only a point farther than minRelativeOffset * t from its own region's plane moves: one that
  /// its plane describes (within the merging's RMS bound, RegionMergeOptions::maxRelativeRms)
  /// stays where it was grown.
  double minRelativeOffset = 0.1;
  double noiseFactor = 2.0;
  /// A point of a union (farther than minRelativeOffset * t from its plane) goes back to a
  /// neighbouring large grown region whose plane lies within largeRegionTolerance times that
  /// region's own RMS (or noiseFactor times the noise) of it: the union's pieces were grown by
  /// normals, so near a crease they hold points of the surface across it (the top of a
  /// staircase's side under its sawtooth edge), which lie on that surface's plane. The same
  /// rule as the merging's join (planes/PlaneDescribes.hpp). 0: unions only take.
  double largeRegionTolerance = kPlaneDescribesTolerance;
  /// After the moves, a union also takes the unlabelled points next to it (transitively) that its
  /// plane describes as well as its own points (within planeDescribesBound of its RMS, or the
  /// noise floor): the points of the small regions that the filter dropped where the union meets
  /// other surfaces (the top tread of a short staircase, where the kernel rounds the treads into
  /// the back face; the treads' ends next to its sides). Its own farthest point as the bound
  /// took a staircase's sides too. false: unlabelled points stay so.
  bool takeUnlabelled = true;
  /// ... but not a point whose own surface (the plane of its k-NN) turns more than this from the
  /// union's plane, unless its neighbours spread across that plane no more than the noise floor
  /// (where the noise exceeds the sampling, as on a scan's near floor, the k-NN plane is the
  /// noise's). Within the band of a staircase's mean ramp lies a diagonal strip of each of its
  /// vertical sides (at 90 degrees; treads and risers meet the ramp at its slope and at 90 minus
  /// it, so 75 keeps the risers of ramps steeper than 15 degrees). Such a point still passes the
  /// union's band on to the points beyond it (the top tread, which the kernel rounded into the
  /// back face, is reached only past the sides' strips). 90: no test (by distance alone).
  double fillMaxAngleDegrees = 75.0;
};

/// OptionError naming the field unless every bound is finite and >= 0.
void validate(const BoundaryRefinementOptions& options);

/// The regions of `segmentation` (over `positions`, adjacency from `knn`) with the boundaries of
/// its unions moved (`origins`, from mergeCoplanarRegions; empty: nothing moves). Unions take
/// points; they and the large grown regions give them; a small grown region next to a union keeps
/// its points (it was not merged, so it is a piece of another surface, a box's side under its
/// top). In each of a few passes every region's plane is fitted to its points; then, in rounds,
/// every point of a giving region next to a union takes the nearest plane among its own region's
/// and its neighbouring unions' (with the bounds above), all points of a round deciding on the
/// labels the round began with. A point only moves to a plane nearer than its own by a margin, so
/// the rounds end; a region of fewer than 3 points has no plane (its points go to any union in
/// reach).
/// Then each union takes, in rounds, the unlabelled points next to it that its plane describes
/// (takeUnlabelled); other unlabelled points stay unlabelled.
/// Regions keep their order, emptied ones are dropped, point
/// lists increasing. Deterministic, the same for any thread count.
/// `noiseRms` is the cloud's sensor noise (pointNoiseRms).
Segmentation refineRegionBoundaries(const std::vector<Vec3>& positions, const KnnGraph& knn,
                                    Segmentation segmentation,
                                    const std::vector<RegionOrigin>& origins, double t,
                                    double noiseRms, const BoundaryRefinementOptions& options = {});

}  // namespace scalespace
