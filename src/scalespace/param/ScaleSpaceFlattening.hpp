#pragma once
// The scale-space flattening of Sec. 4.3: every point is projected onto the APSS of the cloud
// while the scale grows along a linear, per-point series (Eq. 1.39 with t_min the point's own
// spacing), each step fitting the *previous step's* points and normals, so that the cloud flows
// towards one algebraic sphere (or plane). The pyramid of Sec. 1.5.2 decimates the samples as the
// scale grows (each level a Poisson-disk subset of the previous one, drawn on the moved points).
// A last global algebraic-sphere fit with constant weights puts every point on one sphere or
// plane.
#include <cstdint>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/fit/AlgebraicSphere.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

/// The fit of each flattening step: the plain APSS (W1: only the projection and its normal are
/// needed) with MLS projection from the previous step's position, as the stack does.
FitOptions flatteningFitOptions();

struct FlatteningOptions {
  int scaleCount = 50;  // M (Sec. 4.3: 50 in every experiment)
  int K = 10;           // t_min of a point: the distance to its K-th nearest neighbour (Sec. 1.5.1)
  double tMax = 0;      // the last scale; 0: the bounding-box diagonal ("the global cloud size")
  double alpha = 0.1;   // pyramid disk radius r = alpha t (Sec. 1.5.2)
  FitOptions fit = flatteningFitOptions();
  std::uint64_t seed = 1;  // Poisson-disk visiting order
  int threads = 0;         // 0: all cores
};

/// OptionError naming the field unless 2 <= scaleCount <= kMaxScaleCount, 1 <= K <=
/// kMaxNeighborCount, tMax finite
/// and >= 0, alpha finite and >= 0, the fit options valid with fit.mls on.
void validateFlatteningOptions(const FlatteningOptions& options);

struct FlatteningStep {
  double tMedian = 0;       // median of the points' scales at this step
  std::size_t samples = 0;  // pyramid level size
  std::size_t invalid = 0;  // points whose fit failed (they kept their previous position)
  double meanMove = 0;      // mean distance moved, relative to the bounding-box diagonal
  double seconds = 0;
};

struct FlatteningResult {
  /// Every point on the global sphere (or plane), input order, same frame as the input, with
  /// the sphere's outward (normal-agreeing) unit normal there.
  std::vector<Vec3> positions, normals;
  /// The global fit, in a frame centred at `sphereOrigin` (AlgebraicSphere convention).
  AlgebraicSphere sphere;
  Vec3 sphereOrigin = Vec3::Zero();
  /// Steps whose fit failed at each point (it kept its previous position there).
  std::vector<std::uint16_t> failedSteps;
  std::vector<FlatteningStep> steps;
  double tMax = 0;        // the last scale
  double medianTMin = 0;  // median of the per-point first scales
  double diagonal = 0;    // of the input's bounding box
  /// Mean |p_M - S(p_M)| / diagonal: how far the flowed points were from the global sphere
  /// before the last projection (small when the flow converged).
  double residual = 0;
  double seconds = 0;
};

/// Runs the flattening on positions and oriented unit normals (same size, >= K + 1 points).
/// Throws OptionError on invalid options or inputs, Cancelled when `progress` asks to stop.
/// Identical results for any thread count.
FlatteningResult flattenScaleSpace(const std::vector<Vec3>& positions,
                                   const std::vector<Vec3>& normals,
                                   const FlatteningOptions& options = {},
                                   const ProgressCallback& progress = {});

/// The algebraic sphere fitted with constant weights to oriented samples (the last step of
/// Sec. 4.3), in a frame centred at their centroid (returned in `origin`). Falls back to the
/// least-squares plane when the sphere is invalid. Throws OptionError on fewer than 3 points.
AlgebraicSphere fitGlobalSphere(const std::vector<Vec3>& positions,
                                const std::vector<Vec3>& normals, Vec3& origin);

}  // namespace scalespace
