#pragma once
// (Not in the thesis.) A region grown over the concave junction where a tube stands on a surface,
// trimmed back to the tube. At the foot of a cylinder standing on a plane the scale's fits round
// the corner, the normals and the line directions there turn smoothly from the wall onto the
// plane, and Eq. 3.10 lets the wall's region run out onto the plane: a synthetic cylinder of
// radius 4 cm on a plane, estimated normals, came as one region with 5,214 wall and 3,820 plane
// points at t = 0.0079 and 8,974 and 6,906 at t = 0.0114, turned down as narrow-arc and flat.
// A tube curves one way all round while the junction curves the other way, and strongly: there
// kappa1 t read -1.4 against the wall's +0.35 (CylinderOptions::oneCurvatureSign cuts the
// growth there, but needs consistently oriented normals everywhere, and on real scans cut tubes).
// The regions turned down are trimmed, and the tubes of which enough points curve against them,
// where their trimmed points fit twice as well (TubeTrimOptions::tubeMinAgainstShare).
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct TubeTrimOptions {
  bool enabled = true;
  /// A point is kept when it curves the way most of the region does, by at least keepFraction x
  /// the median |kappa1| t of those: the wall of a tube curves evenly (t / r), the junction curves
  /// against it and a noisy support around zero, most of it by less than half the wall's.
  double keepFraction = 0.5;
  /// The trimmed points' tube is kept only if its radius is at least minRadiusScales x t. Trimmed
  /// of its flat faces, the region round a sharp edge is the band the scale's fits round into a
  /// tube of radius below t (the pipe rack's box edge, noisy, estimated normals: 0.048 at
  /// t = 0.073, arc 135), a tube of the scale, not of the shape; the cylinders standing on a
  /// plane came back at radius 3.5 t and more.
  double minRadiusScales = 1;
  /// A region accepted as a tube is trimmed too, where the trimmed points' tube fits at least
  /// twice as well (RMS over radius): at one scale the wall's region ran out onto the plane and
  /// its tube still passed, at radius 1.17 r with RMS 0.24 r. Only where at least this share of
  /// its points curve against it by keepFraction of its median (the junction): a tube without
  /// one, as most are, is left untried (each try is one more fit).
  double tubeMinAgainstShare = 0.05;
};

/// OptionError naming the field unless the options can run.
void validateTubeTrimOptions(const TubeTrimOptions& options);

/// The points of `points` (sorted indices) that curve the way most of them do, by at least
/// options.keepFraction x the median of those (kappa1 t beyond minCurvatureFactor; the sign of
/// kappa1 follows the normals' orientation, which Eq. 3.10's n_i . n_j > 1 - epsilon keeps
/// consistent within a region), and of those the largest part connected in `graph` (the lowest
/// index on ties): sorted, or empty when it holds fewer than minPoints or all of `points`, or
/// when fewer than minAgainstShare of `points` curve against the majority by that much.
std::vector<Index> trimToOneCurvatureSign(const KnnGraph& graph, const std::vector<float>& kappa1,
                                          const std::vector<Index>& points, double t,
                                          double minCurvatureFactor, std::size_t minPoints,
                                          const TubeTrimOptions& options = {},
                                          double minAgainstShare = 0);

}  // namespace scalespace
