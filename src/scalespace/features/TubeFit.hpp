#pragma once
// A tube fitted to a region of cylinder points (Sec. 3.5 leaves the regions unmodelled; users need
// the axis and the radius): its axis as a polyline (curved for a bent pipe), the radius along it
// (a tapering pipe), the RMS distance of the points to that tube, whether the axis is straight,
// and the tests that tell a tube from what only looks anisotropic at one scale.
//
// How: each point x with the scale's normal n and curvature kappa1 (features/LineAnisotropy)
// proposes the axis point x - n / kappa1. These are averaged in cells of the tube's size and
// chained by the longest path of their minimum spanning tree: the curved axis. The straight axis
// (direction: least-spread direction of the normals; centre: the point nearest to every normal
// line, refined by a geometric circle fit) is kept unless the curved one fits the points clearly
// better. The radius profile is the mean distance to the axis per axis vertex.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct TubeFitOptions {
  std::size_t minPoints = 30;
  /// The scale's curvature must be that of a tube, not of noise on a plane: |mean kappa1| t >=
  /// minCurvatureFactor (the line tracer's own flatness bound,
  /// CurvatureLineOptions::minAnisotropy).
  double minCurvatureFactor = 0.02;
  /// The points and their own normals must both turn around the axis by at least this: a
  /// half-pipe scan covers 180 degrees, a full pipe 360, while the two faces of a box edge,
  /// rounded by the fit into a tube of radius ~t at every scale, give two normal directions only.
  /// Counted in 15-degree bins, those two directions fill 120 degrees once noise or normals
  /// estimated over many neighbours smear them: every tube the pipe rack's box gave with
  /// estimated normals covered exactly 120 (bench_cylinders --estimate-normals: 13 and 3 false
  /// cylinders at 120, none at 135; the pipes and the real table scan's legs, 165, unchanged).
  double minArcDegrees = 135;
  /// A tube much thinner than the scale is not one the fits saw: its whole section lies in one
  /// support. Radius >= minRadiusFactor * t.
  double minRadiusFactor = 0.25;
  /// RMS distance to the tube (radius profile) <= maxRelativeRms * max(radius, t): relief smaller
  /// than the scale (the strands of a cable seen as one tube) is smoothed by the fits, so it is
  /// not held against the tube.
  double maxRelativeRms = 0.25;
  /// The input normals must take at least this many distinct directions around the axis (the
  /// exponential of the entropy of their azimuths in 2-degree bins; at most half the point count
  /// is asked of a small region). A tube's normals turn continuously (30 and more on every tube
  /// of the pipe rack, the table scan and libcgal-demo's meshes); a prism's sit on its faces:
  /// libcgal-demo's octahedron (16.0) and star (12.6), clean, were tubes of radius 1.32 and 0.087
  /// at one scale. A tessellated cylinder of 40 facets (pipe.off) gives 36-73. Noise spreads a
  /// prism's normals and hides its faces.
  double minNormalDirections = 24;
  /// And they must fill the arc: sectorFill, the effective number of 10-degree sectors their
  /// azimuths take (exponential of the histogram's entropy) over the arc's sectors, or the same
  /// with each sector of points weighted alike over the sectors the points cover (a tube sampled
  /// unevenly around its axis), the larger, >= minSectorFill. The arc of the first reading is
  /// the lower fill of two counts: the 15-degree bins the normals and the points fill, and per
  /// axis segment the span they take round the axis, gaps included. A tube's normals turn with
  /// its points; the faces of a box edge, rounded by the fits into a tube at a scale above them,
  /// lie all round the arc while their normals, however far noise or normals estimated over many
  /// neighbours smear them, crowd in two directions; a noisy prism's smeared face directions fill
  /// the bins they take, not the span with the gaps between them.
  double minSectorFill = 0.75;
  /// Off by default (1). When below 1, the positions about a straight axis must not hold a
  /// section shape fixed along it: a tube is turned down (Faceted) when more than this share of
  /// its points' spread about it is explained by the azimuth's harmonics 2-8 and that shape's
  /// RMS is above maxSectionShapeRms x the radius. A prism's faces, whose normals noise smears
  /// into a tube's, read so (bench/python/bench_cylinders_box_and_poles.py: a box on a floor,
  /// noise 5e-4-1e-3 of the diagonal, normals estimated over 20 neighbours: shares 0.23-0.77,
  /// shape RMS 0.08-0.25; with 0.2 about half its false tubes go, the poles beside it kept), as
  /// did the table legs of python3-pcl's table_scene_lms400, which it then loses (shares
  /// 0.25-0.68, shape RMS 0.06-0.09: their points sit 21.7 to 28.6 mm from the axis in a pattern
  /// fixed along it), and so does an oval tube. The noisy pipe rack's straight tubes and strand
  /// runs read up to 0.17; a curved axis is not tested (in the frame carried along it a twisted
  /// strand's run read 0.34).
  double maxSectionShapeShare = 1;
  /// The shape's RMS bound (sqrt(share) x the tube's RMS, over the radius): over a narrow arc the
  /// harmonics also follow a scan's smooth biases (the stereo mug of python3-pcl's
  /// table_scene_mug_stereo_textured: share 0.33 at RMS 0.05 r, 0.03 r of shape).
  double maxSectionShapeRms = 0.05;
  /// The normals must turn with the points: a tube is turned down (Faceted) when, with the
  /// points' azimuth cut into 10-degree sectors over the whole axis, the normals turn less than
  /// half as far as the points over more than maxFaceSectors neighbouring sectors, and the RMS of
  /// the sectors' mean lean from the radial is at least minFaceLeanDegrees. A prism's face keeps
  /// one normal over the sectors it spans. The box standing on a floor of
  /// bench/python/bench_cylinders_box_and_poles.py, whose normals noise smears until they fill
  /// the arc, read runs of 3-9 and leans of 14-25 degrees, the poles beside it runs of 0-1 and
  /// leans under 3.5. The bound is 15, not 12: the whole cable of the pipe rack's clean one-sided
  /// scan, which only that tube finds, reads a run of 4 and a lean of 14.5 (its strands, seen from
  /// one side, average into a flat top); seen all round they average out along the twist (1.5).
  /// python3-pcl's table_scene_lms400 legs read runs of 4-5 and leans of 14-18: they are square
  /// tubes with rounded corners (their points 20.7 mm from the axis at the faces' middles, 27 mm
  /// at the corners, the same along the leg).
  int maxFaceSectors = 2;
  double minFaceLeanDegrees = 15;
  /// The axis is straight unless the curved axis fits the points better: straight when the RMS
  /// about the straight axis is <= straightRmsRatio x that about the curved one (or within 2% of
  /// the radius of it).
  double straightRmsRatio = 1.5;
  /// ... and, when this is finite, only if the straight axis's radius is within this factor of
  /// the points' median curvature radius (1 / |kappa1|) or closer to it than the curved axis's.
  /// Off for a grown region, which may be a cable whose fits read its strands; features/
  /// TubeSplitting sets it for the parts it splits a region into (TubeSplitOptions).
  double maxRadiusDisagreement = std::numeric_limits<double>::infinity();
};

/// Why a region is no tube (None: it is one; Merged: it joined a touching tube,
/// features/TubeMerging; Split: a rough region whose points went to the tubes of the axes they
/// propose, features/TubeSplitting). Split is the last.
enum class TubeRejection : std::uint8_t {
  None,
  TooSmall,
  Flat,
  NarrowArc,
  Thin,
  Rough,
  Faceted,
  Merged,
  Split
};
const char* tubeRejectionName(TubeRejection rejection);

struct TubeFit {
  TubeRejection rejection = TubeRejection::TooSmall;
  bool isTube() const { return rejection == TubeRejection::None; }
  std::vector<Vec3> axis;     // polyline, >= 2 vertices (when the fit got that far)
  std::vector<double> radii;  // radius at each axis vertex
  double radius = 0;          // mean distance of the points to the axis
  double rms = 0;             // RMS of (distance to the axis - radius profile there)
  bool straight = false;
  Vec3 direction = Vec3::UnitX();  // the straight axis: unit direction, and a point on it
  Vec3 centre = Vec3::Zero();
  double straightRadius = 0;  // radius of the straight fit
  double arcDegrees = 0;  // the arc around the axis covered by both the points and their normals
  double normalDirections = 0;   // TubeFitOptions::minNormalDirections' measure
  double sectorFill = 0;         // TubeFitOptions::minSectorFill's measure
  double sectionShapeShare = 0;  // TubeFitOptions::maxSectionShapeShare's measure
  double normalLean = 0;         // TubeFitOptions::minFaceLeanDegrees' measure
  int faceSectors = 0;           // TubeFitOptions::maxFaceSectors' measure
  double length = 0;             // of the axis polyline
  std::size_t pointCount = 0;
};

/// The tests of a fitted tube (fitTube's last step), in order: TooSmall, NarrowArc, Thin, Rough,
/// Faceted, else None; on its measures (length, arc, radius, RMS, normal directions, sector
/// fill, section shape, point count) at scale t.
TubeRejection judgeTube(const TubeFit& fit, double t, const TubeFitOptions& options);

/// Fits the tube of `points` (indices into positions / normals / the scale fields). `normals` are
/// the input's oriented normals; `scaleNormals` and `kappa1` those of scale t
/// (LineAnisotropyField).
TubeFit fitTube(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                const std::vector<Vec3>& scaleNormals, const std::vector<float>& kappa1,
                const std::vector<Index>& points, double t, const TubeFitOptions& options = {});

/// The nearest point of a polyline (>= 2 vertices, kept by reference) to query points.
class AxisLocator {
 public:
  struct Projection {
    std::size_t segment = 0;  // from vertex segment to segment + 1
    double along = 0;         // in [0, 1] on the segment
    double distance = 0;
  };
  explicit AxisLocator(const std::vector<Vec3>& axis);
  ~AxisLocator();
  Projection project(const Vec3& p) const;

 private:
  static constexpr std::size_t kBruteForceVertices = 16;
  const std::vector<Vec3>& axis_;
  std::unique_ptr<SpatialIndex> index_;
};

/// A fitted tube's surface (tube.axis of >= 2 vertices; the tube is kept by reference).
class TubeSurface {
 public:
  explicit TubeSurface(const TubeFit& tube);
  /// Distance from p to the surface (distance to the axis minus the radius profile at the nearest
  /// axis point; negative inside) and, in `radial`, the unit direction from that axis point to p.
  double residual(const Vec3& p, Vec3* radial = nullptr) const;

 private:
  const TubeFit& tube_;
  AxisLocator locator_;
};

/// Whether the mean radii of two tubes differ by at most `tolerance` times the larger one.
bool radiiAgree(const TubeFit& a, const TubeFit& b, double tolerance);

/// The median over `points` (indices into positions) of |TubeSurface::residual| over the tube's
/// mean radius: how well points fitted elsewhere lie on `tube` (0 for no points, infinity for a
/// tube without an axis or radius). Every point counts up to 4096, then an even stride of them.
double medianRelativeResidual(const std::vector<Vec3>& positions, const std::vector<Index>& points,
                              const TubeFit& tube);

/// The share of b's axis vertices that lie beside a's axis: their nearest point on it is not one
/// of its ends, within 3 radii (the larger tube's). Two strands side by side: about 1 both ways;
/// two pieces of one tube end to end: about 0.
double shareBeside(const TubeFit& a, const TubeFit& b);

/// OptionError naming the field unless every option is finite and in range.
void validateTubeFitOptions(const TubeFitOptions& options);

}  // namespace scalespace
