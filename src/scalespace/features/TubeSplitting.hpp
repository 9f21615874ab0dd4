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

struct ThinTube {
  std::vector<Index> points;  // sorted
  TubeFit tube;
};

/// The tubes a region (`points`, whose tube is `whole`) splits into: only a tube or a rough one
/// (TubeRejection::Rough), and only where its points' median curvature radius is below
/// maxRadiusRatio x whole.radius (one tube, whatever its noise, reads
/// its own radius and is never split), by splitByProposedAxes, again on each part whose own
/// curvature still sees thinner tubes (up to 3 times); kept when two or more parts are tubes
/// thinner than maxRadiusRatio x whole.radius and hold half of the points, else empty.
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
