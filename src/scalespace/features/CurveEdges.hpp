#pragma once
// Feature curves split into edges at their corners (not in the thesis, whose region growing keeps
// a connected set of creases of one sign as one curve, Sec. 3.4.1): a box's 12 edges are one
// convex curve there, 12 edges here.
//
// How: the points of a curve whose neighbours in it, within `radius`, spread along one line (the
// second eigenvalue of their covariance at most maxSpread times the first) are on an edge; the
// others are at a corner (where two or more edges meet, the neighbours spread along each: two
// straight arms at a right angle give 0.25 at the corner, whatever the radius). The band's own
// width counts little: 1.8 e wide, 0.05 at a radius of 4 e. The edges are
// the sets of edge points of one curve chained by links shorter than `linkDistance` between
// points whose lines agree; pieces shorter than radius / 2 are taken as corner points; each corner
// point then joins the edge it is nearest to through the graph (breadth first, ties to the lower
// edge id), or, cut off by a gap, the edge of its curve's nearest edge point. A curve without any
// edge point stays one edge. Last, adjacent edges along one line are joined again (on a scan a
// noisy band breaks the linearity test here and there along a straight edge), unless a third edge
// meets them there (a junction).
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct CurveEdgeOptions {
  double radius = 0;        // the neighbourhood of the linearity test (required, > 0)
  double maxSpread = 0.15;  // FeatureCurveOptions::edgeSpread
  /// Linear points this close whose lines agree within 20 degrees are on one edge, across gaps
  /// in the curve (required, > 0).
  double linkDistance = 0;
  /// Adjacent edges of a curve (points within linkDistance) whose lines agree within this angle
  /// and whose union's RMS distance to its line is at most mergeThickening times the larger of
  /// theirs are one edge (0: never joined).
  double mergeAngleDegrees = 20;
  double mergeThickening = 1.5;
};

struct CurveEdges {
  std::vector<int> edgeId;                 // per point, -1 where curveId is -1
  std::vector<int> curveOf;                // per edge, its curve
  std::vector<std::vector<Index>> points;  // per edge, increasing
};

/// Splits the curves given per point (`curveId`, -1 none) on the points' graph. Edges are numbered
/// by curve, then by their lowest point. Deterministic, the same for any thread count. Throws
/// OptionError when the sizes differ or the options are not finite and in range.
CurveEdges splitCurvesAtCorners(const std::vector<Vec3>& positions, const KnnGraph& graph,
                                const std::vector<int>& curveId, const CurveEdgeOptions& options);

}  // namespace scalespace
