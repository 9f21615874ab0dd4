#pragma once
// (Not in the thesis.) A region that holds several tubes side by side, split by the axes its
// points propose. Under noise the scale's normals turn smoothly across the groove where two
// strands of a cable touch, Eq. 3.10 lets a region run across it, and the strands of a noisy
// cable came as one rough region at the scales where each strand alone is a tube
// (bench_cylinders). Each point x with the scale's normal n and curvature kappa1 proposes the
// axis point x - n / kappa1 (the same whichever way n points: kappa1 turns with it); the
// proposals of one tube crowd along its axis, those of touching strands along axes two radii
// apart, and the points near a contact, whose fits span both strands, scatter between them.
#include <vector>

#include "scalespace/core/Types.hpp"
#include "scalespace/features/TubeFit.hpp"

namespace scalespace {

struct TubeSplitOptions {
  bool enabled = true;
  /// The proposals are counted in cells of cellFactor x the region's median curvature radius
  /// (1 / |kappa1|), and a cell's density is the count over it and its 26 neighbours: at 0.2 the
  /// density reads 0.6 radius across, and the axes of two touching strands, two radii apart, stay
  /// apart; coarser cells let the contacts' proposals fill the space between the axes
  /// (docs/THESIS_NOTES.md, "Regions split by the axes their points propose").
  double cellFactor = 0.2;
  /// The density levels tried: minDensity, 2 minDensity, ... up to densitySteps x minDensity,
  /// in units of the density of the cell that holds the median proposal (cells by decreasing
  /// density). The first level at which the dense cells' components (26 neighbours) give two or
  /// more holding minShare of the proposals each splits the region: the contacts' scattered
  /// proposals are sparser than any axis's.
  double minDensity = 0.25;
  int densitySteps = 4;
  double minShare = 0.05;
  /// Dense cells whose centres lie within linkRadius x the median curvature radius (and at least
  /// the 26 neighbours) are one part: one tube's proposals, spread round its axis by the
  /// curvature's error, stay one part; the axes of two touching strands are two radii apart.
  double linkRadius = 0.5;
  /// A region is split only where its points' median curvature radius is below maxRadiusRatio x
  /// its tube's radius (the fits see thinner tubes than the region: the strands, at a scale below
  /// the whole cable's), and it gives its points only to parts whose tubes are that thin
  /// (features/CylinderDetection).
  double maxRadiusRatio = 0.6;
  /// Two parts of the same radius that lie end to end are joined into one (when their union is
  /// still a tube) where one axis continues the other (continuesAxis): their nearest ends at most
  /// maxJoinGap x that radius apart, each ahead of the other's end within maxJoinOffset x the
  /// radius (+ half the distance ahead) of the line along which that axis leaves its tube. That
  /// is one strand cut across where its proposals thin out (3.7 radii apart on the noisy pipe
  /// rack); a scan from one side sees the strands of a cable in turn, each piece beginning where
  /// another ends but two radii aside, and a curved axis would bridge them.
  double maxJoinGap = 5;
  double maxJoinOffset = 1;
  /// The parts' tubes take the straight axis only where its radius is within this factor of the
  /// part's median curvature radius, or closer to it than the curved axis's
  /// (TubeFitOptions::maxRadiusDisagreement): a run of a twisted strand seen from one side lies
  /// on the cable's envelope too, a straight tube of twice its radius over a narrow arc.
  double partRadiusDisagreement = 1.5;
  /// The parts' tubes need their normals to turn by this much around the axis
  /// (TubeFitOptions::minArcDegrees, 135 for a grown region): the strands of a cable scanned from
  /// one side hide one another's flanks, and each is seen over less than the half-pipe's 180.
  double partMinArcDegrees = 105;
};

/// The parts of `points` (indices into positions and the scale fields of scale t) whose proposals
/// fall on distinct axes: one vector per axis holding at least max(minPoints, minShare) of the
/// proposals, sorted; the points of sparse cells, of smaller axes or too flat to propose
/// (|kappa1| t < minCurvatureFactor) are in none. Fewer than two parts: the region is one tube or
/// none, and it is returned empty. Deterministic: cells anchored at the proposals' lower corner,
/// parts in the order of their first cell.
std::vector<std::vector<Index>> splitByProposedAxes(
    const std::vector<Vec3>& positions, const std::vector<Vec3>& scaleNormals,
    const std::vector<float>& kappa1, const std::vector<Index>& points, double t,
    double minCurvatureFactor, std::size_t minPoints, const TubeSplitOptions& options = {});

/// Whether b's axis continues a's: their nearest ends at most maxGap apart, and each end ahead
/// of the other, within maxOffset (+ half the distance ahead) of the line along which the other
/// axis leaves its tube, measured over its last directionReach (false for an axis of fewer than
/// two vertices). Two pieces of one strand pass; the runs of two strands that a scan from one
/// side sees in turn, each beginning where another ends but beside it, do not.
bool continuesAxis(const TubeFit& a, const TubeFit& b, double maxGap, double maxOffset,
                   double directionReach = 0);

/// Whether two parts of one split region may be pieces of one strand, to be joined: radii within
/// 25% of the larger, neither beside the other (shareBeside, at most half of an axis), and one
/// axis continuing the other (continuesAxis: within options.maxJoinGap and maxJoinOffset x the
/// larger radius, the ends' directions over 2 radii). splitIntoThinnerTubes joins its parts by
/// it, and features/TubeMerging merges the touching tubes of one split by it.
bool mayBeOneStrand(const TubeFit& a, const TubeFit& b, const TubeSplitOptions& options = {});

struct ThinTube {
  std::vector<Index> points;  // sorted
  TubeFit tube;
};

/// The tubes a region (`points`, whose tube is `whole`) splits into: only a tube, a rough one or
/// one over a narrow arc (a cable seen from one side), and only where its points' median
/// curvature radius is below maxRadiusRatio x whole.radius (one tube, whatever its noise, reads
/// its own radius and is never split), by splitByProposedAxes, again on each part whose own
/// curvature still sees thinner tubes (up to 3 times: two strands' runs side by side); the final
/// parts fitted with the part options (partRadiusDisagreement, partMinArcDegrees) and joined
/// where one continues another (continuesAxis, over the last 2 radii of each axis); kept when two
/// or more parts are tubes thinner than maxRadiusRatio x whole.radius and hold half of the
/// points, else empty.
/// `normals` are the input's, `scaleNormals` and kappa1 those of scale t.
std::vector<ThinTube> splitIntoThinnerTubes(const std::vector<Vec3>& positions,
                                            const std::vector<Vec3>& normals,
                                            const std::vector<Vec3>& scaleNormals,
                                            const std::vector<float>& kappa1,
                                            const std::vector<Index>& points, const TubeFit& whole,
                                            double t, const TubeFitOptions& tube,
                                            const TubeSplitOptions& options = {});

/// OptionError naming the field unless the options can run.
void validateTubeSplitOptions(const TubeSplitOptions& options);

}  // namespace scalespace
