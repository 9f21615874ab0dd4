#pragma once
// The crease through a point as the line where the planes of its two sides meet (not in the
// thesis): the cloud points near the point split into the crease's two sides (by the side their
// normal leans to across it, or by the side of it they lie on), a plane fitted to each side, the
// two planes intersected. On a sharp crease this is the
// edge itself, where the salient vertices of the APSS lie 0.2 to 0.4 e inside a convex edge
// (outside a concave one): the APSS rounds the edge at every scale.
#include <optional>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct CreaseLineOptions {
  /// The sides are the points within `reach` of the point.
  double reach = 0;
  /// Each side's points lie within maxRms (RMS) of its plane: else the sides are curved (a fillet,
  /// a corner's third face) and no line is returned.
  double maxRms = 0;
  /// The two planes turn by at least this many degrees (else it is no crease).
  double minTurnDegrees = 20;
  /// Each side holds at least this many points.
  int minSidePoints = 6;
  /// Some point lies within maxGap of the line: the two sides meet there. Where a narrow third
  /// face lies between them (the rim of a part thinner than the reach) their planes meet beyond
  /// it, half a spacing or more from any point (libcgal-demo's blade). 0: not checked.
  double maxGap = 0;
  /// Split the points by position rather than by their normals: by the side they lie on of the
  /// plane through `centre` that holds `along` and their mean normal, leaving out those within
  /// sideMargin of it. Near the crease the estimated normals blend the two sides (the
  /// neighbourhood that estimates them straddles it, more so under noise) and send points to the
  /// wrong side. Nine in ten of a side's normals must then lie within 60 degrees of its plane's
  /// (30 split by normals): blended ones pass, a corner's third face does not.
  bool splitByPosition = false;
  double sideMargin = 0;
};

struct CreaseLine {
  Vec3 point = Vec3::Zero();      // on the line, the nearest to the query point
  Vec3 direction = Vec3::Zero();  // unit
  double turnDegrees = 0;         // between the two sides' normals
};

/// Distance from x to the line through `point` along `unitDirection`.
double distanceToLine(const Vec3& x, const Vec3& point, const Vec3& unitDirection);

/// The crease near `x` running roughly along `along` (unit; e.g. the salient vertices' line):
/// the points of `positions` (with oriented unit `normals`, searched in `index`) within
/// options.reach of x are split by the sign of n . (along x m), m their mean normal, or with
/// options.splitByPosition by the side of the plane through `centre` (x when null) holding along
/// and m, and a plane is fitted to each side (least squares). None when a side is too small or not
/// flat, when the planes turn by less than minTurnDegrees or when their normals disagree with the
/// side's.
std::optional<CreaseLine> fitCreaseLine(const std::vector<Vec3>& positions,
                                        const std::vector<Vec3>& normals, const SpatialIndex& index,
                                        const Vec3& x, const Vec3& along,
                                        const CreaseLineOptions& options,
                                        const Vec3* centre = nullptr);

struct RimLineOptions {
  /// The sheet is the cloud points within `reach` of the centre.
  double reach = 0;
  /// Their covariance's smallest eigenvalue over its trace (surface variation) is at most this,
  /// and its middle one at least minSpread of the trace: they sample one sheet (the two faces of a
  /// part thinner than the reach included), not a volume nor a line.
  double maxVariation = 0.1;
  double minSpread = 0.05;
  /// The centre lies off their centroid, in the sheet's plane across `along`, by at least this
  /// share of the reach: the sheet stops beside it (core/SheetBorder reads 0.42 on a straight
  /// border, 0.17 half the radius inside it).
  double minBorderShare = 0.2;
  /// The sheet's outermost point across `along` lies at most maxInset outward of the centre (a
  /// centre beyond every point passes: the rim is then the outermost point).
  double maxInset = 0;
  int minPoints = 12;
};

/// The rim of a part thinner than the reach near `centre` (e.g. the salient vertices' mean), along
/// `along` (unit, within 45 degrees of the sheet's plane): the line through the sheet's outermost
/// point across `along`, in the sheet's mid-plane. Where a blade's two faces end in a narrow third
/// face, their planes meet beyond the rim, so fitCreaseLine finds no line there; the rim itself is
/// the sharp edge (both of its edges within a fraction of a spacing). None when the points are too
/// few, not one sheet, or do not stop beside the centre. RimLine::across is the unit direction in
/// the sheet's plane, outward: a point's inset from the rim is (rim.point - x) . across.
struct RimLine {
  Vec3 point = Vec3::Zero();      // on the rim, in the sheet's mid-plane
  Vec3 direction = Vec3::Zero();  // unit, along the rim
  Vec3 across = Vec3::Zero();     // unit, in the sheet's plane, outward
  Vec3 normal = Vec3::Zero();     // unit, the sheet's
};

/// Whether x lies on the sheet within `halfWidth` of the rim: inset from it by at most halfWidth,
/// out of the sheet's mid-plane by at most halfWidth (the faces of a thin part, not another
/// surface beside it) and not beyond it by more than halfWidth.
bool withinRim(const RimLine& rim, const Vec3& x, double halfWidth);

std::optional<RimLine> fitRimLine(const std::vector<Vec3>& positions, const SpatialIndex& index,
                                  const Vec3& centre, const Vec3& along,
                                  const RimLineOptions& options);

}  // namespace scalespace
