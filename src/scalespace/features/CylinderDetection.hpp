#pragma once
// Cylinders across scales (Sec. 3.5, and its future work of Sec. 3.6). At each scale t:
//   1. minimal-curvature lines (features/CurvatureLines), kept when regular (features/
//      LineRegularity, Eq. 3.5-3.7);
//   2. per point the linear anisotropy sigma of the nearby line tangents (features/LineAnisotropy,
//      Eq. 3.8-3.9);
//   3. regions grown on the k-NN graph (core/RegionGrower) between neighbours with
//      |sigma_i - sigma_j| < eps, |v_i . v_j| > 1 - eps and n_i . n_j > 1 - eps (Eq. 3.10), from
//      every point with sigma >= minAnisotropy (not in the thesis, which grows from every point:
//      without it the isotropic rest of the cloud forms regions too), most anisotropic first
//      (optionally, not in the thesis, only over points curving as the seed does:
//      oneCurvatureSign);
//   4. a tube fitted to each region (features/TubeFit), the regions that are no tube dropped;
//   5. (not in the thesis) a region turned down that ran over a concave junction onto the surface
//      a tube stands on is trimmed back to the points curving one way (features/TubeTrimming);
//      a region whose points' curvature reads tubes thinner than its own is
//      split by the axes they propose into those tubes (features/TubeSplitting: a noisy cable's
//      strands grown into one region), touching tubes whose union is still a tube merge (the
//      parts of one split region excepted), and each tube takes the free points lying on it next
//      to it (TubeCoverageOptions).
// Then, as the planes of Ch. 2, the tubes of consecutive scales with Jaccard index > 0.5 are
// linked into components with a birth and a death scale (core/RegionGraph).
#include <cstdint>
#include <vector>

#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/core/RegionGraph.hpp"
#include "scalespace/features/CurvatureLines.hpp"
#include "scalespace/features/LineRegularity.hpp"
#include "scalespace/features/TubeFit.hpp"
#include "scalespace/features/TubeSplitting.hpp"
#include "scalespace/features/TubeTrimming.hpp"

namespace scalespace {

/// (Not in the thesis.) After the region growing each tube takes the points of no tube next to it
/// that lie on its surface: within max(rmsFactor x its RMS, radiusFraction x its radius) of it,
/// their own normal within maxAngleDegrees of its radial direction.
struct TubeCoverageOptions {
  bool enabled = true;
  double rmsFactor = 3, radiusFraction = 0.05, maxAngleDegrees = 30;
};

/// (Not in the thesis.) A region turned down for its arc alone, whose normals still turn by
/// minArcDegrees around its axis, is a tube where it lives across scales: a component made of
/// such tubes only is kept if it is found at scales at least minPersistence steps apart (its span
/// from birth to death, bridged gaps included: at 12 scales python3-pcl's mug is found at levels 2
/// and 5 only: between them its region is missing or grows into what lies beside it) with radii
/// within maxRadiusSpread of one another (largest / smallest - 1), or whose points at every level
/// lie on its best-fitting tube (lowest RMS over radius) within
/// CylinderOptions::nestedLinkTolerance of its radius (median distance; a narrow arc's fitted
/// radius is loose, its points are not: the inner wall of python3-pcl's mug read 0.042, 0.033 and
/// 0.037 at three scales, its points within 2.7% of the 0.037 tube). One scan sees a cylinder from
/// one side: a mug on a table (python3-pcl's stereo scan) reads 75-120 degrees at six scales from t
/// = 0.008 to 0.027, with radii 0.036-0.045, under the 135 a single scale needs. The radius of a
/// tube that the scale makes, the fits rounding an edge, grows with t instead.
struct NarrowTubeOptions {
  bool enabled = true;
  double minArcDegrees = 75;
  /// The span, not the persistence: a chain kept for a span of 2 across a gap reports persistence
  /// 1 (CylinderComponent::persistence), so `--min-persistence 2` does not label it.
  int minPersistence = 2;
  double maxRadiusSpread = 0.15;
};

struct CylinderOptions {
  /// The scales, increasing. Empty: scaleCount log-spaced scales in [tMin, tMax].
  std::vector<double> scales;
  /// 12 (neighbouring scales 1.31 apart instead of 1.52 over the same range) finds
  /// bench_cylinders' twisted cable seen from one side whole at 6 of 6 seeds instead of 2 (it
  /// reads as one tube over a narrow band of scales), for 1.3-1.4 x the time, but on real scans it
  /// gives more single-scale components (python3-pcl's table scan 30 against 19, libcgal-demo's
  /// kitten 10 against 4) and a persistent tube over libcgal-demo's ball.ply; 10 loses the stereo
  /// mug's wall. So 8 (bench/README.md).
  int scaleCount = 8;
  /// 0: twice the median distance to the 10th nearest neighbour (the finest scale whose fits hold
  /// ~40 points) and a tenth of the bounding-box diagonal.
  double tMin = 0, tMax = 0;
  /// Scale set per level. The seeds in Sec. 3.3's random order (curvedSeedsFirst off): on a tube
  /// |kappa1| t is about t / r everywhere, so the most curved seeds are the noise's peaks, and the
  /// lines started there first broke the strands of a noisy cable (bench/README.md,
  /// bench_cylinders).
  CurvatureLineOptions lines = [] {
    CurvatureLineOptions options;
    options.curvedSeedsFirst = false;
    return options;
  }();
  LineFilterOptions filter;
  double epsilon = 0.1;  // Eq. 3.10
  /// (Not in the thesis; off by default.) A region keeps the sign of its seed's kappa1: a point
  /// whose kappa1 t has the other sign, beyond tube.minCurvatureFactor, does not join. A tube
  /// curves one way all round, the concave groove between two strands of a cable does not, and
  /// under noise Eq. 3.10 alone lets a region cross it where the scale's normals turn smoothly
  /// (bench_cylinders, noisy full scans of seeds 1-3: 4 of 9 strands found with it, 1 without).
  /// Off because the sign is only as good as the normals' orientation: on the real table scan
  /// (one-sided, noisy) kappa1 t is negative on 58% of a leg's points, which it then cut (49
  /// components, 46 at one scale only, against 31 and 27; bench/README.md).
  bool oneCurvatureSign = false;
  double minAnisotropy = 0.5;  // sigma of a region's points
  int graphNeighbors = 10;     // k of the k-NN graph (Sec. 2.3.1's 10)
  TubeFitOptions tube;
  /// (Not in the thesis.) A rough region is split by the axes its points propose: the strands of
  /// a noisy cable that Eq. 3.10 grew into one region across their contacts.
  TubeSplitOptions split;
  /// (Not in the thesis.) A region turned down as flat, rough, narrow-arc or faceted, and not
  /// split, or a tube partly curving against itself, is trimmed to its points curving one way
  /// (features/TubeTrimming) and fitted again: a cylinder standing on a plane, grown out onto the
  /// plane over their junction.
  TubeTrimOptions trim;
  NarrowTubeOptions narrow;
  TubeCoverageOptions coverage;
  double minJaccard = 0.5;  // Sec. 2.3.2
  /// A component bridges up to this many levels where its tube was not found (core/RegionGraph):
  /// the two walls of a thick pipe (libcgal-demo's pipe.off) join, over the rim, into one rough
  /// region at two middle scales and part again above them; without the bridge each wall was two
  /// components, the same tube reported twice. 0: the thesis' consecutive links only.
  int maxGapLevels = 2;
  /// (Not in the thesis.) Across such a gap the two tubes must agree in radius within this share
  /// of the larger: no region between them vouches for the link. The radius fitted to a real tube
  /// grows with the scale: a leg of python3-pcl's table scan reads 0.0275 at t = 0.030 and 0.0312
  /// at t = 0.055 (13%), its tube not found at the scale between; 0.1 left it two components at 12
  /// scales, 0.2 one. pipe.off (its walls joined over the rim at middle scales), bench_cylinders'
  /// rack (seeds 1-6) and libcgal-demo's other meshes at 8 scales keep their components with
  /// either; at 12 scales joint.off's tube of radius 0.34 is one component, as at 8, not three.
  double bridgeRadiusTolerance = 0.2;
  /// (Not in the thesis; 0: off.) Two tubes of linked levels (consecutive, or across a gap as
  /// above) whose regions do not pass the Jaccard rule but one of which holds more than minJaccard
  /// of the other's points, the smaller at least a quarter the size of the larger, also link when
  /// the smaller region's points lie on the larger one's tube: the median of their distances to
  /// its surface within this share of its radius (core/RegionGraph,
  /// RegionLinkOptions::nestedAllowed; the bridges' radius test does not apply, the points
  /// vouch instead). The same tolerance confirms narrow tubes (NarrowTubeOptions). A scale finds a
  /// piece of a tube that the next finds whole, or a narrow arc whose fitted radius is loose while
  /// its points are not (the mug of python3-pcl's mug scene: a wall of radius 0.040 read 0.055 over
  /// a 75-degree arc at one scale, whole at the next but one). A strand's points lie 17-18% of the
  /// radius off the whole cable's tube (median; the pipe rack at 300k points, exact normals).
  double nestedLinkTolerance = 0.1;
};

/// The normals `cylinders` estimates for a cloud without any (CLI, Python): sheet normals
/// (NormalEstimationOptions::sheetTolerance 0.05, as `features`) signed by the oriented PCA
/// normals (SheetSign::FromPlanes). Where two strands of a cable touch, the PCA plane of a point
/// near the contact is tilted through both strands and the grower runs across the contact on them
/// (bench_cylinders, clean full scan, estimated normals: 10% of the cable's PCA normals more than
/// 15 degrees off, two strands read as one at every scale); the sheet normals' own tree turned a
/// strand inside out.
OrientedNormalsOptions cylinderNormalOptions();

/// OptionError naming the field unless the options can run.
void validateCylinderOptions(const CylinderOptions& options);

struct CylinderLevel {
  double scale = 0;
  std::size_t lines = 0, regularLines = 0, regions = 0;  // regions: grown, and split parts
  /// How many regions each test of the tube fit turned down, indexed by TubeRejection (the
  /// narrow-arc regions kept as narrow tubes included).
  std::vector<std::size_t> rejections;
  /// The tubes of this level, same order as the graph's regions at this level.
  std::vector<TubeFit> tubes;
  /// Per tube, 1 where it is of a narrow arc (NarrowTubeOptions), kept for its component.
  std::vector<std::uint8_t> narrow;
  std::vector<float> anisotropy;  // per point, NaN where no regular line passes within t
  double seconds = 0;
};

/// Drops the narrow-arc tubes (CylinderLevel::narrow) of the components made of them alone that
/// span under options.minPersistence steps (bridged gaps included), or whose radii spread over
/// options.maxRadiusSpread unless every level's points lie on the chain's best-fitting tube within
/// onTubeTolerance (0: never; a narrow arc's fitted radius is loose, its points are not), from
/// `levels` and `regionLevels` alike; whether any was dropped (the graph is then stale).
/// `regionLevels` may be graph.levels: it is changed only after every component was read.
/// detectCylinders' step after linking, a piece of its own so that the rule can be checked on
/// chains built by hand. OptionError unless `levels` and `regionLevels` have one entry per graph
/// level, each with one tube, narrow flag and region per graph region, and `positions` is given
/// when onTubeTolerance > 0.
bool dropUnconfirmedNarrowTubes(const RegionGraph& graph, const NarrowTubeOptions& options,
                                const std::vector<Vec3>& positions, double onTubeTolerance,
                                std::vector<CylinderLevel>& levels,
                                std::vector<RegionLevel>& regionLevels);

struct CylinderComponent {
  int id = 0;
  int birthLevel = 0, deathLevel = 0;
  double birthScale = 0, deathScale = 0;
  int gapLevels = 0;    // levels between birth and death where it was not found (maxGapLevels)
  int persistence = 0;  // death - birth - gapLevels
  /// Of the levels where the component holds at least 80% of its largest set, the one whose tube
  /// fits best (lowest rms / radius; the lowest on ties): its tube is reported.
  int representativeLevel = 0;
  TubeFit tube;
};

struct CylinderDetection {
  std::vector<CylinderLevel> levels;
  RegionGraph graph;                          // regions = the tubes' points, per level
  std::vector<CylinderComponent> components;  // same ids as graph.components
  double seconds = 0;
  int scaleCount() const { return int(levels.size()); }
};

/// Runs the pipeline on a cloud with oriented normals. Throws OptionError on bad options or a
/// cloud without normals, Cancelled on request. Parallel; the result does not depend on the thread
/// count.
CylinderDetection detectCylinders(const PointCloud& cloud, const CylinderOptions& options,
                                  const ProgressCallback& progress = {});

/// The level whose scale is nearest to t on a log scale.
int nearestCylinderLevel(const CylinderDetection& detection, double t);

/// Per point, the component holding it at `level` if its persistence is >= minPersistence, else -1.
std::vector<int> cylinderLabelsAtLevel(const CylinderDetection& detection, int level,
                                       int minPersistence = 0);

/// Each component's persistence, by id (what core's label queries take with a PointMembership).
std::vector<int> cylinderPersistence(const CylinderDetection& detection);

/// Per point, the most persistent component (lower id on ties) with persistence >= minPersistence
/// holding it at any level, or -1 (Sec. 2.4.1's query for planes).
std::vector<int> cylinderLabelsByPersistence(const CylinderDetection& detection,
                                             int minPersistence = 0);

}  // namespace scalespace
