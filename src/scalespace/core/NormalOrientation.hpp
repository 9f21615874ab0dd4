#pragma once
// Consistent orientation of unoriented normals (e.g. from estimateNormals()).
//
// MinimumSpanningTree [Hoppe 1992, §3.3]: the Riemannian graph is the symmetric k-nearest-neighbour
// graph (edge i-j when j is among the k nearest of i or i among those of j) with cost
// 1 - |n_i . n_j| (plus, not in Hoppe's paper, acrossWeight |n_i . d| |n_j . d| for the unit
// offset d between the two points: see NormalOrientationOptions::acrossWeight); a minimum spanning
// forest is built (Kruskal, edges sorted in parallel). In each
// connected component the seed is the point with the largest z (ties: smaller index), whose normal
// is oriented towards +z (the top of a scanned scene or of a closed object faces up and out); the
// orientation is then propagated from the seed along the tree, flipping a child when
// n_child . n_parent < 0. Not in Hoppe's paper: the component is then turned as a whole so that
// what is seen from above faces up: the highest point of each column of a 64 x 64 grid over its
// footprint votes with its normal's z where that normal is within 45 degrees of vertical (the
// highest point alone may be the rim of a wall or a pole, whose flat normal says nothing, or a
// noisy point); not where a viewpoint decides (faceViewpoint).
//
// Reliability (result.reliable[i] == 0) is documented per method:
//  - both: the input normal was flagged invalid (`valid` argument) or is not a finite non-zero
//    vector. Such points take no part in the graph; an invalid normal is flipped to agree with its
//    nearest neighbour that has a valid one (a non-finite normal is left as it is).
//  - MST: |n_child . n_parent| < creaseThreshold along the tree edge that oriented the point (a
//    sharp crease: the sign decision is a guess), or the point is alone in its component.
//  - Visibility (MST, not in Hoppe 1992; NormalOrientationOptions::visibility): after the
//    propagation the tree is cut at the edges where its sign decision is a guess (a crease,
//    |n_child . n_parent| < creaseThreshold, or an edge across a thin part, whose offset runs along
//    both normals), and each piece is flipped when rays cast from its points (core/OccupancyGrid)
//    leave the cloud on the side its normals point away from and are stopped on the other: the
//    inside of a closed surface, unless the graph edges that join it to the rest along one
//    surface agree with its sign (each counts as two of the rays' votes), or, on an open surface,
//    unless as many of its points see out on both sides as say it faces in (a floor a third
//    hidden by a pipe rack above it). Where both sides are open (a single scan of a scene, an
//    open sheet) or both closed (the inside of a room), the rays have no say and the tree's sign
//    stays. On a closed surface (a component of the graph where at most
//    5% of the points that cast rays see out on both sides: a CAD part, an object scanned all
//    round, a pipe floating above an open floor) the rays are trusted more: offsets along the
//    normals within the noise do not cut the tree, a piece whose rays disagree is split where they
//    do (unless the cloud is clean and flat-faced), a tenth of a piece's points voting against it
//    suffice, and fragments smaller than k points do not vouch for a neighbour's sign. Open scans
//    keep the cautious rules: there a floor under a table top looks like an inside (the real table
//    scan without its viewpoint, with the closed rules: 49.6% of the normals facing away from the
//    scanner, the scene split in two, against 84.9%, the scene turned as a whole). Components that
//    faced a viewpoint (faceViewpoint) cast no rays: a scan's line of sight is better evidence.
//  - Viewpoint: flipped so that n . (viewpoint - p) >= 0; unreliable when the view ray grazes the
//    surface, |cos(n, viewpoint - p)| < grazingThreshold, or p == viewpoint.
#include <cstdint>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

enum class OrientationMethod { MinimumSpanningTree, Viewpoint };

struct NormalOrientationOptions {
  OrientationMethod method = OrientationMethod::MinimumSpanningTree;
  std::size_t k = 10;             // neighbours of the Riemannian graph (MST)
  Vec3 viewpoint = Vec3::Zero();  // scanner position, same frame as the points (Viewpoint,
                                  // faceViewpoint)
  double creaseThreshold = 0.3;   // MST: |cos| below which the propagated sign is unreliable
  /// MST (not in Hoppe 1992): an edge whose offset runs along both normals, between the two sides
  /// of a thin part (parallel sheets facing each other, where Hoppe's cost is 0 and the
  /// propagation orients both sides alike), costs up to this much more, so the tree goes round
  /// through the part's rim. Off by default: it fixes thin parts on clean, dense samples but
  /// misleads the tree on noisy or sparse ones, where neighbours' offsets leave the tangent planes
  /// too (figures: bench/README.md, bench_features, "The normals' orientation on thin parts").
  /// 0: Hoppe's cost alone.
  double acrossWeight = 0.0;
  /// MST (not in Hoppe 1992): compare n_a with n_b reflected across the plane that bisects the
  /// edge a-b (perpendicular to d = p_b - p_a), q = n_a . n_b - 2 (n_a . d)(n_b . d) / |d|^2,
  /// instead of n_a . n_b: the cost is 1 - |q| and the propagation keeps q > 0. A surface
  /// symmetric about that plane carries its normal over exactly: two points of a sphere or of a
  /// circle, the two sides of a crease of any angle at equal distances, the two sides of a thin
  /// slab. Hoppe's sign assumes the normals turn by less than 90 degrees, so it turns one side of
  /// a crease sharper than that (a narrow V-groove, a knife edge) inside out, and the tree does
  /// not cut there (|cos| is large). Offsets along the normals within the noise (3 x the median
  /// off-plane spread, noiseOffset()) are taken as 0: between close neighbours on a noisy surface
  /// they say nothing. false: Hoppe's n_a . n_b.
  bool reflectAcrossBisector = false;
  /// MST: correct the tree's guesses by visibility (file comment). Hoppe's propagation alone
  /// orients both sides of a thin part alike and guesses at creases; CAD parts sampled without
  /// normals lose half their normals to it (bench_features: blade, rotor).
  bool visibility = true;
  /// MST, visibility: the side of the occupancy grid's cells in units of the median distance to
  /// the k-th neighbour. Smaller cells see thinner parts; larger ones let fewer rays slip through
  /// the gaps between samples. 0.7 sees both sides of a slab 2.5 spacings thick (1.0 does not);
  /// at 0.5 the rays leak through rotor's surface (bench_features) and its rims stay wrong.
  double visibilityCell = 0.7;
  double grazingThreshold = 0.05;  // Viewpoint: |cos| below which the sign is unreliable
  /// MST (not in Hoppe 1992): after the propagation, each piece of the tree (cut where its sign
  /// is a guess, as for the visibility correction) whose normals face away from `viewpoint` (a
  /// scanner's position; mean cosine below -0.1) is turned over, then each point still facing
  /// away beyond grazing (cosine below -0.1): a single scan's surfaces face the scanner, whatever
  /// its frame's z (the table scan of python3-pcl, in the sensor's frame: with +z seeds 85% of
  /// its normals faced away from the sensor, the floor's and the table top's pointing down; 4.1%
  /// with this, the grazing ones). Not where the viewpoint lies within a component's
  /// bounding box, nor anywhere when it lies farther from the cloud's box than the cloud's
  /// diagonal (a frame's origin, not a scanner). The visibility correction runs after it.
  bool faceViewpoint = false;
};

struct NormalOrientationResult {
  std::size_t flippedCount = 0;     // normals whose sign was changed
  std::size_t unreliableCount = 0;  // number of zeros in `reliable`
  std::size_t componentCount = 0;   // MST: connected components of the graph (0 for Viewpoint)
  std::size_t pieceCount = 0;       // MST, visibility: pieces of the cut tree
  std::size_t piecesFlipped = 0;    // MST, visibility: pieces the rays turned over
  /// MST, visibility: the components of the graph the rays found closed (at most 5% of the points
  /// that cast rays see out on both sides; file comment), and whether every component that cast
  /// rays is (an object scanned all round, a CAD part).
  std::size_t closedComponents = 0;
  bool closedSurface = false;
  /// MST, visibility: the largest share, over the components that cast rays, of their casting
  /// points that see out on both sides (0 when none cast). Measured (file comment of
  /// kClosedOpenShare): closed parts 0-0.5%, the noisy and clean blade (open at its root, rays
  /// through its thin rim) 7-9%, open scans 11-99%.
  double openShare = 0;
  std::vector<std::uint8_t> reliable;  // one per point, see the file comment
};

/// Two orientations of one cloud's normals compared by the visibility rays (not a step of the
/// orientation): at the points where their signs differ (a sample of them, every stride-th, about
/// `maxPoints`), how many of each the rays find facing inward (at least three more of the five
/// rays of the visibility pass escape behind the normal than in front). The points where the two
/// agree count alike for both and are not cast. Cells of
/// NormalOrientationOptions::visibilityCell times the median distance to the k-th neighbour (over
/// a sample of the points). The orientation with fewer inward is the one the rays contradict less.
/// Deterministic for any thread count. Throws OptionError on size mismatches or k < 1.
struct RayComparison {
  std::size_t differing = 0;  // points whose two normals point to opposite sides
  std::size_t sampled = 0;    // of those, the ones that cast rays
  std::size_t firstInward = 0, secondInward = 0;
};
RayComparison compareByRays(const std::vector<Vec3>& points, const std::vector<Vec3>& first,
                            const std::vector<Vec3>& second, const SpatialIndex& index,
                            const NormalOrientationOptions& options = {},
                            std::size_t maxPoints = 100000);

/// Orients `normals` (one per point, modified in place) with `index` built on `points`. `valid`
/// (empty = all valid) is e.g. NormalEstimationResult::valid. Deterministic for any thread count.
/// Throws OptionError on size mismatches or k < 1, Cancelled if `progress` returns false (the
/// normals are then left unchanged).
NormalOrientationResult orientNormals(const std::vector<Vec3>& points, std::vector<Vec3>& normals,
                                      const SpatialIndex& index,
                                      const NormalOrientationOptions& options = {},
                                      const std::vector<std::uint8_t>& valid = {},
                                      const ProgressCallback& progress = {});

/// Same, building the default index internally when the method needs one.
NormalOrientationResult orientNormals(const std::vector<Vec3>& points, std::vector<Vec3>& normals,
                                      const NormalOrientationOptions& options = {},
                                      const std::vector<std::uint8_t>& valid = {},
                                      const ProgressCallback& progress = {});

}  // namespace scalespace
