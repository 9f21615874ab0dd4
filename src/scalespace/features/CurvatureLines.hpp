#pragma once
// Minimal-curvature lines on the APSS (Sec. 3.3): streamlines of the direction of the principal
// curvature of smaller magnitude, traced from Poisson-disk seeds by the projected Euler scheme of
// Eq. 3.2, q_{n+1} = phi(q_n + delta v_min(q_n)), phi the MLS projection (Eq. 1.12) and v_min read
// from the W3 shape operator (Eq. 1.38) at the projected point.
//
// What the thesis leaves open, decided here (docs/THESIS_NOTES.md, "Curvature lines"):
// - kappa1 is the principal curvature of larger magnitude, kappa2 the other (|kappa1| >= |kappa2|),
//   v_min the direction of kappa2. A direction field has no sign: each step keeps the sign that
//   continues the previous step (v . v_prev >= 0).
// - A line is traced both ways from its seed; each way stops at the first of: an invalid fit (too
//   few neighbours, degenerate), a near-umbilic point (StopReason::Umbilic), a turn sharper than
//   maxTurnDegrees in one step, a step that does not move (the projection pulled it back), a
//   projection that lands more than maxProjectionShift * delta from q_n + delta v (it left the
//   sheet: jumped across a crease or to a nearby sheet), coming within collisionFraction * delta
//   of a vertex of another line, meeting its own line (closing it when the line's two ends meet,
//   else a self collision), or maxSteps.
// - Coarse scales fit on the Poisson-disk level of the pyramid for that scale (Sec. 1.5.2): the
//   samples lie >= 2 alpha t apart, so a fit reads a bounded number of them whatever t.
// - Lines are what a sequential tracer gives (Kalogerakis 2009: seeds in a seeded random order,
//   each line traced until it meets an earlier one; a seed on an earlier line starts none), but
//   they are traced in batches whose steps are each one call of the shared fit driver
//   (fit/FitPoints), then cut where they meet an earlier line of their batch. The result does not
//   depend on the thread count.
#include <cstdint>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

struct CurvatureLineOptions {
  /// The scale t (support radius of the fits), > 0.
  double scale = 0;
  /// Seeds: Poisson-disk sample of the cloud with disk radius beta t, i.e. seeds >= 2 beta t
  /// apart (Sec. 3.3 and Sec. 1.5.2's convention for disk radii).
  double beta = 0.5;
  /// Step length delta = gamma t (Eq. 3.2).
  double gamma = 0.5;
  /// The fits: W3 with MLS projection by default (Eq. 1.12, 1.38). Must be an estimator with
  /// principal directions (W3, W2, Quadric, Jet) and mls on.
  FitOptions fit = defaultFitOptions();
  /// Pyramid disk radius alpha t (Sec. 1.5.2); 0 fits on every input point.
  double alpha = 0.1;
  /// Near-umbilic stop: the direction of kappa2 is not defined where |kappa1| ~ |kappa2|. A
  /// vertex is near-umbilic when (|kappa1| - |kappa2|) t < minAnisotropy (flat or spherical at
  /// this scale) or |kappa2| > (1 - minCurvatureGap) |kappa1|.
  double minAnisotropy = 0.02;
  double minCurvatureGap = 0.1;
  /// Stop a way at the border of the data (a scan's edge, a hole): where the centroid of the
  /// samples within t of the vertex is more than borderOffset t from it along the surface (half
  /// a disc puts it 0.42 t away; a full one near 0) and more than 4 sigma, sigma = t / (2 sqrt(n))
  /// the centroid's random wander over n samples inside the data. Beyond the border the APSS
  /// extrapolates and a one-sided neighbourhood biases the curvatures. 0 never stops there.
  double borderOffset = 0.2;
  /// Stop a way when one step turns by more than this (the field jumped: crossing an umbilic).
  double maxTurnDegrees = 45;
  /// Stop a way when the MLS projection moves the predicted point q_n + delta v by more than
  /// maxProjectionShift * delta: it did not follow the sheet of q_n (jumped across a crease or to
  /// another sheet within t). On a smooth sheet it moves it by about kappa delta^2 / 2, < 0.4 delta
  /// within the turn limit. With 1, no step is longer than 2 delta.
  double maxProjectionShift = 1;
  /// Stop a way within collisionFraction * delta of another line's vertex (lines of one scale
  /// stay apart; a seed next to an existing line makes no line).
  double collisionFraction = 0.5;
  /// (Not in the thesis) trace the seeds in decreasing |kappa1| t (the random order among
  /// equals) rather than in the random order: the lines on creases and ridges start first, so the
  /// lines beside them neither block their seeds nor cut them. false: the random order.
  bool curvedSeedsFirst = true;
  /// Most steps per way.
  int maxSteps = 2000;
  std::uint64_t seed = 1;

  static FitOptions defaultFitOptions() {
    FitOptions fit;
    fit.estimator = EstimatorKind::W3;
    fit.mls = true;
    return fit;
  }
};

/// Why one way of a line ended.
enum class LineStop : std::uint8_t {
  InvalidFit,     // too few neighbours or a degenerate fit
  Umbilic,        // |kappa1| ~ |kappa2|: no minimal direction
  Turn,           // turned more than maxTurnDegrees in one step
  Stalled,        // the projection undid the step (moved < delta / 10)
  Border,         // reached the border of the data (borderOffset)
  Collision,      // reached another line
  Loop,           // met its own line where the line's two ends meet: the line is closed
  Jump,           // the projection landed more than maxProjectionShift * delta from the step
  SelfCollision,  // met its own line away from its other end (e.g. a spiral): the line is open
  MaxSteps
};
const char* lineStopName(LineStop stop);

struct CurvatureLineVertex {
  Vec3 position = Vec3::Zero();  // on the APSS (projected), same frame as the cloud
  Vec3 tangent = Vec3::Zero();   // unit v_min, oriented along the line
  Vec3 normal = Vec3::Zero();
  double kappa1 = 0;              // principal curvature of larger magnitude (signed: > 0 convex)
  double kappa2 = 0;              // the other
  double geometricVariation = 0;  // nu of the fit (LocalFit::geometricVariation)
};

struct CurvatureLine {
  std::vector<CurvatureLineVertex> vertices;  // in order along the line
  Index seed = 0;                             // input point the line started from
  LineStop stopBackward = LineStop::MaxSteps, stopForward = LineStop::MaxSteps;
  // The last vertex joins the first: a way met its own line and the two ends are within
  // (1 + 2 collisionFraction) delta (2 delta by default), so the closing edge is no longer.
  bool closed = false;
  double length() const;
};

struct CurvatureLineSet {
  double scale = 0;
  std::vector<CurvatureLine> lines;  // lines of >= 2 vertices, in tracing order
  std::size_t seeds = 0;             // seeds drawn
  std::size_t samples = 0;           // pyramid samples the fits read
  std::size_t fits = 0;
  /// How many ways ended for each reason (indexed by LineStop).
  std::vector<std::size_t> stops;
  /// |kappa1| at every projected seed with a minimal direction (valid fit, not near-umbilic): an
  /// area-uniform sample of the curved part of the surface at this scale (the feature curves take
  /// its percentiles).
  std::vector<double> seedKappa1;
  double seconds = 0;
};

/// OptionError naming the field unless the options can run (scale, beta, gamma > 0 and finite,
/// an estimator with principal directions and mls, thresholds in range).
void validateCurvatureLineOptions(const CurvatureLineOptions& options);

/// The pyramid samples for scale t (alpha > 0): a Poisson-disk subset of the input points with
/// separation 2 alpha t, all points when alpha = 0.
std::vector<Index> lineSamples(const std::vector<Vec3>& positions, double alpha, double t,
                               std::uint64_t seed);

/// Traces the minimal-curvature lines of `cloud` (oriented normals required) at one scale.
/// Throws OptionError on bad options or a cloud without normals, Cancelled on request.
CurvatureLineSet traceCurvatureLines(const PointCloud& cloud, const CurvatureLineOptions& options,
                                     const ProgressCallback& progress = {});

}  // namespace scalespace
