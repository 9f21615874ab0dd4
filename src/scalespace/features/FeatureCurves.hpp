#pragma once
// Feature curves by multi-scale voting of salient minimal-curvature lines (Sec. 3.4.1):
//   1. minimal-curvature lines (features/CurvatureLines) at `scaleCount` scales spread linearly
//      over [e, 3 e], e the mean spacing (see FeatureCurveOptions::spacing);
//   2. salient vertices: |kappa1| > (1 - salientThreshold) K, K the 90th percentile of |kappa1| at
//      that scale over the seeds with a minimal direction (docs/THESIS_NOTES.md, "Salient filter",
//      for this reading of the thesis' "||kappa1| - K| / K > 0.5"), and |kappa1| t >=
//      max(minSalientCurvature, noiseSalientFactor sigma / e), sigma the cloud's noise; the
//      relative bound capped at |kappa1| t = salientBoundCap;
//   3. each salient vertex votes for the target points (cloud points or mesh vertices) within e,
//      with weight (1 - (d/e)^2)^2, signed by kappa1 (convex +, concave -);
//   4. regions grow on the target graph (k-NN graph or mesh edges) over the points whose votes
//      exceed v = voteThreshold * V_max in magnitude, between points of the same sign;
//   4b. (not in the thesis) points farther than bandHalfWidth * e from the centreline fitted to the
//      salient vertices within centrelineReach * e leave the band before the regions grow; where
//      the cloud points within creaseReach * e form two flat sides, points farther than
//      creaseHalfWidth * e from the line where their planes meet (features/CreaseLine);
//   5. (not in the thesis) regions smaller than minCurveExtent * e across are dropped: specks of
//      one to a few points where a line grazed a corner; then regions of the same sign within
//      joinGap * e of each other are joined (the gaps where lines stop at corners).
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/features/CurvatureLines.hpp"
#include "scalespace/io/MeshFormat.hpp"

namespace scalespace {

/// NormalEstimationOptions::sheetTolerance of the normals that `features` estimates for a cloud
/// without any (CLI, Python): at a crease the plane of the side a point is on, so that the fits
/// there do not mix both sides (bench_features: the clean CAD models' per-curve recall 0.85 ->
/// 0.91; docs/THESIS_NOTES.md, "Feature curves").
constexpr double kFeatureSheetNormals = 0.05;

/// The normals `features` estimates for a cloud without any (CLI, Python): sheet normals of
/// `sheetTolerance` (0: PCA), oriented by their own tree or signed by the oriented PCA normals,
/// whichever the visibility rays find facing inward at fewer points (SheetSign::ByRays). Neither
/// wins on every part: bench_features' clean blade (a thin part) needs the own tree (MCC 0.936
/// against 0.695), its rotor the PCA signs (0.871 against 0.822); the rays pick both. The
/// propagation compares reflected normals (NormalOrientationOptions::reflectAcrossBisector): a
/// crease sharper than 90 degrees keeps its two sides apart (bench_features' creases model, a
/// V-groove of 150 degrees: 2.9% -> 0.8% of the normals against the mesh's, per-curve recall 0.86
/// -> 1.00).
OrientedNormalsOptions featureNormalOptions(double sheetTolerance = kFeatureSheetNormals);

struct FeatureCurveOptions;
struct FeatureCurveResult;

/// The share of a nearly closed cloud's fold points that must see out on both sides for `auto`
/// to keep them (FeatureCurveOptions::foldSeeThroughShare): the two cases measured there read
/// 72-85% and 0%.
constexpr double kFoldSeeThroughShare = 0.5;

/// Whether the orientation of those normals found the cloud open, but only just: its rays see out
/// on both sides at under 15% of the points of every component (NormalOrientationResult::
/// openShare). Over the closed parts' 0.5% and under most open scans (libcgal-demo's oni 11%,
/// spheres 17%, building 18%, the table scan 38%): a thin part whose rim, or an opening, lets a
/// few rays through (bench_features' blade, open at its root: 8.4-9.5%; a box with a hole 0.7-0.8
/// wide in its top: 6.5-11%).
bool nearlyClosed(const NormalOrientationResult& orientation);

/// `features`' `auto` for FeatureCurveOptions::foldBorders, from the orientation of the normals
/// it estimated: on where the rays found every component closed; on a nearly closed cloud, on
/// with foldSeeThroughShare = kFoldSeeThroughShare (the borders found must be the rims of a part
/// thinner than the noise, not the edges of an opening); else off.
void chooseFoldBorders(FeatureCurveOptions& options, const NormalOrientationResult& orientation);

/// Where `auto` looked for folds on a nearly closed cloud and the borders it found were the edges
/// of an opening (FeatureCurveResult::foldSeeThrough under the bound, none kept): the message
/// saying that `turnOn` (a flag, a keyword) would take them as folds all the same. Empty
/// elsewhere.
std::string foldBordersHint(const NormalOrientationResult& orientation,
                            const FeatureCurveResult& result, std::string_view turnOn);

struct FeatureCurveOptions {
  /// The unit e of the scales and of the vote radius. 0: the mean over the cloud of the distance
  /// to the spacingNeighbors-th nearest neighbour (the thesis uses the median edge length of a
  /// mesh input; callers with a mesh pass it here).
  double spacing = 0;
  int spacingNeighbors = 16;
  int scaleCount = 5;
  double minScaleFactor = 1, maxScaleFactor = 3;  // scales in [1 e, 3 e]
  /// Line tracing at each scale (scale is set per scale; the rest is used as given).
  CurvatureLineOptions lines;
  double salientPercentile = 0.9;  // K
  double salientThreshold = 0.5;
  /// (Not in the thesis, docs/THESIS_NOTES.md "Salient filter") K of every scale is that of the
  /// finest scale in units of 1 / t: K_s = K_0 t_0 / t_s. The thesis takes K per scale; at the
  /// coarse scales the bands of strong edges widen and smooth curved parts (|kappa1| t = t / R)
  /// raise K t, so a weaker crease is salient at the fine scales only and fails minVotingScales
  /// (figures: bench/README.md, bench_features). false: the thesis.
  bool salientBoundFromFinest = true;
  /// (Not in the thesis) a salient vertex also has |kappa1| t >= minSalientCurvature: curved on
  /// the scale of the support, whatever K is. Sensor noise gives every vertex of a flat face some
  /// curvature, and where noise makes most of the curvature K follows it; a crease's |kappa1| t is
  /// of order 1 at every scale (its curvature is 1 / t). 0 keeps the thesis' rule alone.
  double minSalientCurvature = 0.6;
  /// (Not in the thesis, docs/THESIS_NOTES.md "Salient filter") the relative bound (1 -
  /// salientThreshold) K t never exceeds salientBoundCap: a vertex with |kappa1| t >= the cap (and
  /// the floors above) is salient whatever K is. K is set by a cloud's strongest edges, so on a
  /// part with 150-degree edges a 30-degree crease (|kappa1| t 0.71-0.83 over e..3e) stayed under
  /// 0.5 K t = 1.2 at every scale. A vertex the cap lets in must be the most curved across the
  /// nearby lines of either sign (ridgeOnly): the fits beside a convex edge read a concave
  /// curvature on its flanks. bench_features' creases model, clean: MCC 0.816 -> 0.872,
  /// per-curve recall 0.71 -> 0.86; the noisy models are bounded by the noise floor.
  /// 0 turns it off (the thesis' relative bound).
  double salientBoundCap = 0.7;
  /// (Not in the thesis) and |kappa1| t >= noiseSalientFactor * sigma / e, sigma the cloud's
  /// sensor noise (surfaceNoiseRms, scales/PointNoise.hpp): a noise-aware floor for
  /// minSalientCurvature. Noise of
  /// sigma gives flat faces a |kappa1| t that grows with sigma / e, and at 1e-3 of the diagonal
  /// (sigma / e about 0.13 on bench_features' models) it passes 0.6 all over them. On clean samples
  /// sigma is about 0 and the floor stays minSalientCurvature. bench_features, 11 models, noisy:
  /// MCC 0.741 with 8 instead of 0.656 with 0, the clean figures unchanged. 0 turns it off.
  double noiseSalientFactor = 8;
  /// (Not in the thesis) keep only the salient vertices that are the most curved across the
  /// lines near them (within t): the line on the crease, not those flanking it. On the 9-model
  /// bench_features sweep: MCC 0.801 instead of 0.748 clean, 0.626 instead of 0.589 noisy;
  /// per-curve recall 0.71 instead of 0.78.
  bool ridgeOnly = true;
  double voteRadiusFactor = 1;  // votes reach points within voteRadiusFactor * e
  double voteThreshold = 0.05;  // v = voteThreshold * V_max
  /// (Not in the thesis) a point joins a curve only when vertices of at least this many scales
  /// voted for it: a crease is salient at every scale, sensor noise mostly at the finest ones.
  /// 1 keeps the thesis' rule. With 3 (and minSalientCurvature 0.6) bench_features labels 16.7%
  /// of its noisy clouds instead of 52% (MCC 0.589 instead of 0.269) and the clean ones as well
  /// (MCC 0.748 instead of 0.739).
  int minVotingScales = 3;
  /// (Not in the thesis) a point stays in a curve only when it lies within bandHalfWidth * e of
  /// the curve's centreline there: a line fitted to the salient vertices (of the point's sign)
  /// within centrelineReach * e. The vote balls of single vertices, each a little off the crease,
  /// make a band wider than the vote radius; the vertices of all scales over 3 e average to the
  /// crease. The centreline runs on the APSS, inside a convex edge (outside a concave one) by 0.2
  /// to 0.4 e at these scales, so a point e from the edge lies about 0.8-0.9 e from it; 0.9 keeps
  /// more of short edges that lie next to others (docs/THESIS_NOTES.md, "Feature band"). 0 turns
  /// it off (the thesis).
  double centrelineReach = 3;
  double bandHalfWidth = 0.9;
  /// Where the vertices within reach do not lie along a line (the largest eigenvalue of their
  /// covariance under this share of its trace: corners) the point is kept.
  double centrelineLinearity = 0.8;
  /// (Not in the thesis) where the cloud points within creaseReach * e of a point form two flat
  /// sides (RMS to their planes within max(creaseFlatness * e, 2 sigma), sigma the noise) that
  /// turn by 20 degrees or more, the line where their planes meet (features/CreaseLine) replaces
  /// the centreline, and the point stays within creaseHalfWidth * e of it: the sharp edge itself,
  /// which the centreline on the APSS misses by 0.2-0.4 e. Curved sides (fillets, corners) keep
  /// the centreline. 0 turns it off.
  double creaseReach = 2;
  double creaseHalfWidth = 1;
  double creaseFlatness = 0.1;
  /// (Not in the thesis) where no crease line is found and the cloud points within creaseReach *
  /// e of the salient vertices form one sheet that stops beside them (features/CreaseLine,
  /// fitRimLine), the band is the sheet within creaseHalfWidth * e of its outermost point: the
  /// rim of a part thinner than the reach, whose faces' planes meet beyond it.
  bool rimLines = true;
  /// The two sides are the points on either side of the plane through the centreline holding
  /// their mean normal, leaving out those within max(0, creaseSideMargin * e - creaseSideNoise *
  /// sigma) of it (clean: 0.3 e, where the APSS's rounding of the edge leaves the sides; under
  /// noise 1e-3 of the diagonal, sigma = 0.1-0.4 e: none). false: by their normals' side
  /// (features/CreaseLine), which blend across the crease (bench_features, 11 models, MCC clean
  /// 0.933 -> 0.936, noisy 0.779 -> 0.782; docs/THESIS_NOTES.md, "Crease sides by position").
  bool creaseSidesByPosition = true;
  double creaseSideMargin = 0.3;
  double creaseSideNoise = 3;
  /// Regions whose points span less than minPieceExtent times e (bounding-box diagonal) are
  /// dropped before the joining below (specks of 1-4 points where a line grazed a corner), and
  /// the curves spanning less than minCurveExtent times e after it: a short piece that joins a
  /// crease stays, one that joins nothing is a speck (bench_features, 11 models: 1 -> 3 raised
  /// the mean MCC 0.898 -> 0.900 clean and 0.771 -> 0.778 noisy, per-curve recall the same; the
  /// real table scan 1,811 -> 540 curves). 0 keeps every region (the thesis).
  double minPieceExtent = 1;
  double minCurveExtent = 3;
  /// (Not in the thesis) curves of the same sign whose points come within joinGap * e of each
  /// other are one curve: lines stop short of corners, so the votes leave gaps where creases meet
  /// and the region growing cut one connected set of creases (what the thesis calls a curve) into
  /// pieces. 0 keeps the pieces.
  double joinGap = 1.5;
  /// (Not in the thesis) each curve is also split into edges at its corners (features/CurveEdges):
  /// a point is on an edge when its curve neighbours within edgeReach * e spread along a line (the
  /// second eigenvalue of their covariance <= edgeSpread times the first). Two straight arms at a
  /// right angle give 0.25 at the corner; a straight band 1.8 e wide 0.05 at a reach of 4 e. A
  /// linear spread of the whole trace failed on a coarse mesh, whose band (an edge's vertices
  /// and those beside it on both faces) spreads in two directions across. 0: no split.
  double edgeReach = 4;
  double edgeSpread = 0.15;
  /// (Not in the thesis) adjacent edges of a curve whose lines agree within this angle (degrees)
  /// are joined again where no third edge meets them (CurveEdgeOptions::mergeAngleDegrees): a
  /// scan's noisy band breaks the linearity test here and there along a straight edge. 0: never.
  double edgeRejoinAngle = 20;
  /// (Not in the thesis) set when the cloud samples a closed surface, a solid's boundary
  /// (`features` and Python's features() set it where the visibility rays of the normals they
  /// estimate find every component closed, and with foldSeeThroughShare where they find the
  /// cloud nearly closed: chooseFoldBorders). A closed surface has no border, so a point where its
  /// neighbours within foldReach * e fill one side only (core/SheetBorder share >= foldBorderShare)
  /// is on a fold: the rim of a part thinner than the noise, whose two sides the points no longer
  /// tell apart and whose lines then see one open sheet with no crease. Such points join the convex
  /// curves. On an open surface (a scan, a ground square) the border is where the sampling stops,
  /// not a feature, so false leaves it out. bench_features' noisy creases model (V creases of 150
  /// degrees): MCC 0.792 -> 0.825 (docs/THESIS_NOTES.md, "Folds thinner than the noise").
  bool foldBorders = false;
  /// Over 2 e (about 64 neighbours) the voids of a random sample read as borders; over 3 e (144)
  /// by chance with odds of about exp(-18).
  double foldReach = 3;
  /// 0.42 on a straight border, 0.27 at 0.3 reach inside, 0.17 at half the reach
  /// (core/SheetBorder.hpp): 0.25 keeps the points within about e of the fold, the width the votes
  /// give a crease.
  double foldBorderShare = 0.25;
  /// (Not in the thesis; 0: off.) With foldBorders, keep the fold points only when at least this
  /// share of them see out on both sides (of the five rays each way around their normal, three
  /// escape; core/OccupancyGrid, cells of foldRayCell e). The rim of a part thinner than the
  /// noise is an open sheet there; the edge of an opening in a closed surface has the surface
  /// behind it. Measured at 0.8 e: bench_features' blade 85% clean, 72% noisy; a box with a
  /// square hole 0.7-0.9 wide in its top, 20k and 100k points, clean and noisy: 0 of 92-1,451.
  /// `auto` sets it on a nearly closed cloud (chooseFoldBorders).
  double foldSeeThroughShare = 0;
  /// The side of the rays' cells, x e: the blade's borders see out on both sides at 72-85% with
  /// 0.8, 56-60% with 0.55, 92-95% with 1.1; the holed box's at 0%, 0-2% and 0%.
  double foldRayCell = 0.8;
  /// k of the k-NN graph the regions grow on (point inputs).
  int graphNeighbors = 10;
  /// Also return the salient vertices and, per target point, the scales that voted for it
  /// (FeatureCurveResult::voterScales, salient*): for diagnosing a missed curve. Off, they are
  /// freed with the rest of the work; they grow with the points.
  bool keepVotingDetail = false;
};

struct FeatureCurve {
  std::vector<Index> points;    // target points, increasing
  int convexity = 0;            // +1 convex, -1 concave
  double length = 0;            // estimated: the MST of a Poisson-disk thinning at 2 e
  std::uint32_t scaleMask = 0;  // bit s set when scale s voted for one of its points
};

/// A curve's part between corners (FeatureCurveOptions::edgeReach).
struct FeatureEdge {
  std::vector<Index> points;  // target points, increasing
  int curve = 0;
  double length = 0;  // as FeatureCurve::length
};

struct FeatureCurveScale {
  double scale = 0;
  double salientBound = 0;  // K
  /// The bound the line vertices' |kappa1| passed at this scale: max(min((1 - salientThreshold) K,
  /// salientBoundCap / t), salientCurvatureFloor / t).
  double vertexBound = 0;
  std::size_t lines = 0, vertices = 0, salientVertices = 0;
};

struct FeatureCurveResult {
  double spacing = 0;
  double noiseRms = 0;  // sigma (surfaceNoiseRms, scales/PointNoise.hpp); 0 when not needed
  /// The floor on |kappa1| t of salient vertices: max(minSalientCurvature, noiseSalientFactor *
  /// noiseRms / spacing).
  double salientCurvatureFloor = 0;
  std::vector<FeatureCurveScale> scales;
  std::vector<double> votes;  // per target point
  /// Only with FeatureCurveOptions::keepVotingDetail (else empty): per target point, bit s set
  /// when a salient vertex of scale s voted for it; the salient vertices that voted: position (the
  /// cloud's frame), scale index, sign of kappa1.
  std::vector<std::uint32_t> voterScales;
  std::vector<Vec3> salientPositions;
  std::vector<std::uint8_t> salientScales;
  std::vector<std::int8_t> salientSigns;
  std::vector<int> curveId;  // per target point, -1 none
  std::vector<std::int8_t>
      convexity;  // per target point: +1 / -1 in a convex / concave curve, else 0
  std::vector<FeatureCurve> curves;
  std::vector<int> edgeId;  // per target point, -1 none (in no curve)
  std::vector<FeatureEdge> edges;
  double maxVote = 0;  // V_max
  /// Points labelled as on a fold only (FeatureCurveOptions::foldBorders), before the curves
  /// shorter than minCurveExtent are dropped.
  std::size_t foldPoints = 0;
  /// With FeatureCurveOptions::foldSeeThroughShare: the share of the fold points found that see
  /// out on both sides (none kept when under the bound); -1 when not measured or none found
  /// (then none kept either).
  double foldSeeThrough = -1;
  /// Whether the borders were looked for and taken as folds: FeatureCurveOptions::foldBorders,
  /// and the see-through test off or passed (not when it found no border to test).
  bool foldsApplied = false;
  /// The salient line vertices of every scale, for drawing: positions and their scale index.
  std::vector<CurvatureLineSet> lineSets;
  double seconds = 0;
};

/// OptionError naming the field unless the options can run.
void validateFeatureCurveOptions(const FeatureCurveOptions& options);

/// The mean distance to the k-th nearest other point (the default spacing e).
double meanKthNeighborDistance(const std::vector<Vec3>& positions, int k);

/// Feature curves of a cloud with oriented normals, labelling the cloud's own points (regions on
/// its k-NN graph).
FeatureCurveResult detectFeatureCurves(const PointCloud& cloud, const FeatureCurveOptions& options,
                                       const ProgressCallback& progress = {});

/// The same with the votes cast on `targets` (e.g. mesh vertices, in the cloud's frame) and the
/// regions grown on `targetGraph` (e.g. the mesh edges: buildMeshEdgeGraph).
FeatureCurveResult detectFeatureCurves(const PointCloud& cloud, const FeatureCurveOptions& options,
                                       const std::vector<Vec3>& targets,
                                       const KnnGraph& targetGraph,
                                       const ProgressCallback& progress = {});

struct MeshFeatureCurves {
  FeatureCurveResult curves;  // per mesh vertex, in the mesh's order
  /// The area samples the lines ran on: the lines' positions are relative to samples.origin().
  PointCloud samples;
  /// The spacing was taken from the mesh and is over 5% of its diagonal: Sec. 3.4.1's protocol is
  /// made for dense meshes (5k-215k vertices); on a coarse one the scales [e, 3e] are as large as
  /// its faces.
  bool coarse = false;
};

/// Sec. 3.4.1's protocol on a triangle mesh: samplesPerVertex x (vertex count) samples by area
/// with interpolated normals (face normals on triangles at a crease of 30 degrees or more,
/// docs/THESIS_NOTES.md), e = the median edge length when options.spacing is 0, votes cast on the
/// vertices and curves grown on the mesh edges. Throws OptionError for bad options or
/// samplesPerVertex outside [1, 10000].
MeshFeatureCurves detectMeshFeatureCurves(const TriangleMesh& mesh, FeatureCurveOptions options,
                                          std::size_t samplesPerVertex = 100,
                                          const ProgressCallback& progress = {});

/// The median edge length of a mesh (the thesis' e for mesh inputs, Sec. 3.4.1).
double medianEdgeLength(const TriangleMesh& mesh);

/// The undirected edge graph of a triangle mesh over `vertexCount` vertices (each neighbour once,
/// increasing), in KnnGraph's compressed rows.
KnnGraph buildMeshEdgeGraph(std::size_t vertexCount,
                            const std::vector<std::array<Index, 3>>& triangles);

}  // namespace scalespace
