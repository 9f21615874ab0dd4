#pragma once
// Contract between the per-point fits (fit/) and the drivers that run them over a cloud
// (fit/CurvatureEstimation, scales/). One call estimates the differential quantities of the
// surface near x at scale t from the samples within distance t (Sec. 1.2.1, 1.4).
#include <memory>
#include <string>
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// Which estimator computes normals and curvatures (Sec. 1.4.3, Table 1.1 rows).
enum class EstimatorKind {
  W3,       // APSS + complete shape operator, Eq. 1.36-1.38 ("Sphere 3")
  W2,       // APSS + approximate shape operator, Eq. 1.35 ("Sphere 2", Ponca)
  W1,       // APSS + simple shape operator, Eq. 1.31 ("Sphere 1"): umbilic, k1 = k2 = H
  Plane,    // weighted PCA plane, H = 8d/t^2
  Mean,     // weighted barycentre + mean normal, H = 8d/t^2
  Quadric,  // PSS (Alexa 2001): weighted height-field quadric over the PCA plane
  Jet       // osculating jet of degree 2 (Cazals 2005), CGAL Monge fitting
};

/// "w3", "w2", "w1", "plane", "mean", "quadric", "jet"; parse throws OptionError on anything else.
const char* estimatorName(EstimatorKind kind);
EstimatorKind parseEstimator(const std::string& name);
/// W3, W2, W1 and Mean read the input normals; Plane, Quadric and Jet only use them for signs.
bool estimatorNeedsNormals(EstimatorKind kind);

struct FitOptions {
  EstimatorKind estimator = EstimatorKind::W3;
  /// MLS projection (Eq. 1.12): re-fit at the projected point until the step is below
  /// mlsTolerance * t or mlsMaxSteps fits were made (Sec. 1.4.3: 20 steps, 0.001 t).
  bool mls = false;
  int mlsMaxSteps = 20;
  double mlsTolerance = 1e-3;
  /// Robust re-weighting (RIMLS, Oztireli 2009): per fit, `robustIterations` re-weightings.
  /// Applies to the APSS estimators (W1, W2, W3) only; the baselines ignore it. Weights are
  /// w_t(q_i) exp(-(r_i / 0.2 t)^2) exp(-(|n_i - grad f/|grad f|| / 0.5)^2), r_i = f(p_i)/|grad f|
  /// (fit/LocalFit.cpp); the re-weighting factors are constants when differentiating (W2, W3).
  bool robust = false;
  int robustIterations = 5;
  /// Stop re-weighting early once no factor changes by more than this between two passes (the
  /// re-weighted fit has converged); 0 always makes robustIterations passes.
  double robustTolerance = 0;
  /// MLS hint: compute the derivatives at the first step already. When that step converges this
  /// saves a pass over the neighbours; when it does not, the derivatives are wasted. Drivers set
  /// it for points that converged at once in a similar fit (scales/: the previous scale).
  bool expectFirstStepConverged = false;
  /// Fits with fewer neighbours are invalid (docs/THESIS_NOTES.md, minimum of 6 neighbours).
  int minNeighbors = 6;
};

/// Everything one fit tells about the surface near the evaluation point. When valid is false the
/// numeric fields are zero (never NaN) and only `neighbors` is meaningful.
/// Where the quantities are evaluated: W2 and W3 at the (final) evaluation point with the complete
/// gradient (Eq. 1.33) as normal; W1 at the projection with the plain gradient (Eq. 1.29) as
/// normal and H = 2 u_q / sqrt(Delta) (Eq. 1.32). W1, Plane and Mean have no principal
/// curvatures: they report kMax = kMin = H and an arbitrary orthonormal tangent pair as directions.
/// With MLS the evaluation point is the last projected point (Eq. 1.12).
/// The GLS fields (tau, kappa, fitness, anisotropy, geometricVariation) are filled by the APSS
/// estimators only (zero for the baselines).
struct LocalFit {
  bool valid = false;
  int neighbors = 0;               // samples with non-zero weight in the last fit
  Vec3 projection = Vec3::Zero();  // where the point lands on the fitted surface (same frame as x)
  Vec3 normal = Vec3::Zero();      // unit, oriented like the input normals
  double meanCurvature = 0;        // H = (kMax + kMin)/2, > 0 on a sphere with outward normals
  double kMax = 0, kMin = 0;       // principal curvatures, kMax >= kMin
  Vec3 dirMax = Vec3::Zero(), dirMin = Vec3::Zero();  // unit, orthogonal, tangent
  // GLS parameters (Mellado 2012): u_c, u_l, u_q divided by sqrt(Delta) (Sec. 1.3.2).
  double tau = 0, kappa = 0;
  double fitness = 0;  // Delta of Eq. 1.11 (Pratt norm)
  /// 1 - |u_l| (Theorem 1, Eq. 1.20). With the kernel of Eq. 1.6 (not constant weights) it
  /// behaves like (H^2 - K) t^2 / 8 (measured and tested; Theorem 1 has / 4 for constant weights).
  double anisotropy = 0;
  /// nu = (dtau/dt)^2 + t^2 |deta/dt|^2 + t^4 (dkappa/dt)^2: Mellado 2012's geometric variation
  /// made dimensionless; zero where the fitted sphere does not change with t (spheres, planes).
  double geometricVariation = 0;
  int mlsSteps = 0;
};

/// Turns `fit` into an invalid result: zeros everywhere (never NaN) but the neighbour count.
inline void markInvalid(LocalFit& fit) {
  const int neighbors = fit.neighbors;
  fit = LocalFit{};
  fit.neighbors = neighbors;
}

/// The samples a fit reads: positions and normals (same frame as x) and an index over positions.
struct SurfaceSamples {
  const std::vector<Vec3>& positions;
  const std::vector<Vec3>& normals;  // may be empty only for estimators that do not need them
  const SpatialIndex& index;
};

struct FitScratch;  // fit/FitScratch.hpp, internal to fit/

/// Scratch memory that one thread reuses across fits (no allocation in the hot loop). What it
/// holds is private to fit/; a copy starts with empty scratch of its own.
class FitWorkspace {
 public:
  FitWorkspace();
  FitWorkspace(const FitWorkspace&);
  FitWorkspace(FitWorkspace&&) noexcept;
  FitWorkspace& operator=(const FitWorkspace&);
  FitWorkspace& operator=(FitWorkspace&&) noexcept;
  ~FitWorkspace();
  FitScratch& scratch() { return *scratch_; }

 private:
  std::unique_ptr<FitScratch> scratch_;
};

/// Estimates the differential quantities at x with support radius t: one fit, the slow path.
/// Many points: fitPoints (fit/FitPoints.hpp) walks them in spatial order and shares their
/// neighbour queries.
LocalFit fitAt(const Vec3& x, double t, const SurfaceSamples& samples, const FitOptions& options,
               FitWorkspace& workspace);

}  // namespace scalespace
