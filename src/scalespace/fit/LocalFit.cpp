#include "scalespace/fit/LocalFit.hpp"

#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/fit/FitScratch.hpp"
#include "scalespace/fit/JetFit.hpp"
#include "scalespace/fit/MeanFit.hpp"
#include "scalespace/fit/NeighborColumns.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/fit/PlaneFit.hpp"
#include "scalespace/fit/QuadricFit.hpp"
#include "scalespace/fit/RobustLanes.hpp"
#include "scalespace/fit/ShapeOperator.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

const char* estimatorName(EstimatorKind kind) {
  switch (kind) {
    case EstimatorKind::W3:
      return "w3";
    case EstimatorKind::W2:
      return "w2";
    case EstimatorKind::W1:
      return "w1";
    case EstimatorKind::Plane:
      return "plane";
    case EstimatorKind::Mean:
      return "mean";
    case EstimatorKind::Quadric:
      return "quadric";
    case EstimatorKind::Jet:
      return "jet";
  }
  return "?";
}

EstimatorKind parseEstimator(const std::string& name) {
  for (EstimatorKind k :
       {EstimatorKind::W3, EstimatorKind::W2, EstimatorKind::W1, EstimatorKind::Plane,
        EstimatorKind::Mean, EstimatorKind::Quadric, EstimatorKind::Jet}) {
    if (name == estimatorName(k)) return k;
  }
  throw OptionError("unknown estimator '" + name +
                    "' (use one of w3, w2, w1, plane, mean, quadric, jet)");
}

bool estimatorNeedsNormals(EstimatorKind kind) {
  return kind == EstimatorKind::W3 || kind == EstimatorKind::W2 || kind == EstimatorKind::W1 ||
         kind == EstimatorKind::Mean;
}

namespace {

// RIMLS re-weighting constants (Oztireli, Guennebaud, Gross 2009, "Feature preserving point set
// surfaces based on non-linear kernel regression"): the kernel weight of sample i is multiplied by
//   exp(-(r_i / sigma_r)^2) * exp(-(|n_i - grad f(p_i)/|grad f(p_i)|| / sigma_n)^2)
// with r_i = f(p_i)/|grad f(p_i)| the (first-order) distance of p_i to the current sphere. The
// paper recommends sigma_n in [0.5, 1.5]; sigma_r is a fraction of the support size here.
constexpr double kRobustSigmaR = 0.2;  // times t
constexpr double kRobustSigmaN = 0.5;

/// Gathers the samples within t of y into ws.columns (offsets q = p - y, normals, kernel
/// weights): the robust passes read them several times. Reads the driver's prefetched samples
/// when they cover the ball, else queries the index.
void gatherNeighbors(const Vec3& y, double t, const SurfaceSamples& samples, FitScratch& ws) {
  if (ws.cache.covers(samples, y, t)) {
    ++ws.cache.hits;
    gatherWithin(ws.cache.samples(), y, t, ws.columns);
    return;
  }
  ++ws.cache.misses;
  samples.index.radiusSearch(y, t, ws.neighbors);
  const WeightKernel kernel(t);
  ws.columns.clear();
  for (const Neighbor& nb : ws.neighbors) {
    const Vec3 q = samples.positions[nb.index] - y;
    ws.columns.push(q, samples.normals[nb.index],
                    WeightKernel::value(kernel.ratio(q.squaredNorm())));  // Eq. 1.6
  }
}

/// One accumulation over the gathered neighbours with re-weighting factors `rho` (frame centred
/// at y, so the offsets are the positions).
OrientedSphereFitResult spherePass(double t, const FitScratch& ws, const std::vector<double>& rho,
                                   FitDerivatives order, bool scaleDerivatives, int minNeighbors) {
  OrientedSphereFit acc;
  acc.begin(Vec3::Zero(), t, order, scaleDerivatives);
  acc.addColumns(ws.columns, rho.data());
  return acc.finish(minNeighbors);
}

/// The sphere of the kernel weights alone, without derivatives (what spherePass gives for
/// FitDerivatives::None and factors 1), with its sums.
OrientedSphereFitResult kernelSphere(double t, const FitScratch& ws, int minNeighbors,
                                     SphereSums& sums) {
  kernelWeightedSums(ws.columns, sums);
  OrientedSphereFitResult res;
  res.neighbors = sums.used;
  res.weightSum = sums.s[0];
  res.valid = sphereFromSums(sums.s, sums.used, t, minNeighbors, res.sphere);
  res.gradient = res.sphere.ul;
  return res;
}

bool isAlgebraicSphere(EstimatorKind kind) {
  return kind == EstimatorKind::W3 || kind == EstimatorKind::W2 || kind == EstimatorKind::W1;
}

FitDerivatives derivativesOf(EstimatorKind kind) {
  return kind == EstimatorKind::W3   ? FitDerivatives::Second
         : kind == EstimatorKind::W2 ? FitDerivatives::First
                                     : FitDerivatives::None;
}

/// ws.weights, filled with 1 when empty (robustSphere leaves it empty for the kernel-only fit).
const std::vector<double>& factorsOf(FitScratch& ws) {
  if (ws.weights.empty()) ws.weights.assign(ws.columns.size(), 1.0);
  return ws.weights;
}

/// The pass whose result is reported again, with the spatial derivatives the estimator needs
/// and the scale derivatives (nu), on the factors left in ws.weights.
OrientedSphereFitResult reportedPass(double t, const FitOptions& options, FitScratch& ws,
                                     int neighbors) {
  OrientedSphereFitResult res =
      spherePass(t, ws, factorsOf(ws), derivativesOf(options.estimator), true, 1);
  res.neighbors = neighbors;
  return res;
}

/// The (robust) APSS sphere at y over the gathered neighbours. Only the sums of the weights feed
/// the next re-weighting, so every pass is made without derivatives except, when `reported` is
/// set, the last one (redone with derivatives if a re-weighting failed and an earlier pass is
/// kept). On return ws.weights holds the factors of the returned fit (empty: all 1).
OrientedSphereFitResult robustSphere(double t, const FitOptions& options, FitScratch& ws,
                                     bool reported) {
  const int passes = options.robust ? std::max(0, options.robustIterations) : 0;
  const FitDerivatives order = derivativesOf(options.estimator);
  // Empty: every factor is 1 (the kernel-only fit); filled only where a pass reads them
  // (factorsOf): filling them for every fit showed in the profile.
  ws.weights.clear();
  bool full = reported && passes == 0;
  if (full) return spherePass(t, ws, factorsOf(ws), order, true, options.minNeighbors);
  SphereSums sums;
  OrientedSphereFitResult res = kernelSphere(t, ws, options.minNeighbors, sums);
  if (passes == 0) return res;
  const double invSr2 = 1 / ((kRobustSigmaR * t) * (kRobustSigmaR * t));
  const double invSn2 = 1 / (kRobustSigmaN * kRobustSigmaN);
  // With no tolerance, the change of the factors is not measured: stopping when it is exactly 0
  // would give the same fit (equal factors make equal sums). The pass whose fit is redone with
  // derivatives needs only its factors.
  const bool track = options.robustTolerance > 0;
  for (int it = 0; it < passes && res.valid; ++it) {
    const bool last = reported && it + 1 == passes;
    const ReweightOutput output = track  ? ReweightOutput::All
                                  : last ? ReweightOutput::FactorsOnly
                                         : ReweightOutput::Sums;
    // Converged: the next fit would be (nearly) the current one.
    const double change = reweight(res.sphere, invSr2, invSn2, ws.columns, ws.weights,
                                   ws.trialWeights, sums, SimdKernel::Auto, output);
    if (change <= options.robustTolerance) break;
    // min 1: re-weighting may zero far outliers; the neighbour count check was done above.
    if (last) {
      OrientedSphereFitResult next = spherePass(t, ws, ws.trialWeights, order, true, 1);
      if (!next.valid) break;
      next.neighbors = res.neighbors;
      res = next;
      full = true;
    } else {
      // An intermediate pass: only the sphere feeds the next re-weighting (what finish() would
      // give for these sums without derivatives, at a fraction of its cost).
      // Without the count (ReweightOutput::Sums), s0 > 0 exactly when a sample has weight.
      const int count = track ? sums.used : sums.s[0] > 0 ? 1 : 0;
      AlgebraicSphere next;
      if (!sphereFromSums(sums.s, count, t, 1, next)) break;
      res.sphere = next;
      res.gradient = next.ul;
      res.weightSum = sums.s[0];
      full = false;
    }
    std::swap(ws.weights, ws.trialWeights);
  }
  if (res.valid && reported && !full) res = reportedPass(t, options, ws, res.neighbors);
  return res;
}

/// Differential quantities of a (robust) APSS fit made at y (W1, W2, W3 and the GLS fields).
LocalFit sphereQuantities(const OrientedSphereFitResult& res, const Vec3& y, double t,
                          const FitOptions& options) {
  LocalFit fit;
  fit.neighbors = res.neighbors;
  if (!res.valid) return fit;
  const AlgebraicSphere& s = res.sphere;
  const Vec3 proj = s.project(Vec3::Zero());
  fit.projection = y + proj;
  const double delta = s.discriminant();
  const double sd = std::sqrt(delta);
  fit.fitness = delta;
  fit.anisotropy = 1 - s.ul.norm();  // Theorem 1, Eq. 1.20 (unit input normals)
  fit.tau = s.uc / sd;
  fit.kappa = 2 * s.uq / sd;
  // Scale derivatives of tau, eta, kappa (GLS, Mellado 2012) by the quotient rule on the d/dt
  // sums; nu = (dtau/dt)^2 + t^2 |deta/dt|^2 + t^4 (dkappa/dt)^2 is their dimensionless sum of
  // squares (zero on a sphere or a plane, where the fitted primitive does not change with t).
  const double dDelta = 2 * s.ul.dot(res.dUlDt) - 4 * (res.dUqDt * s.uc + s.uq * res.dUcDt);
  const double dSd = dDelta / (2 * sd);
  const double dTau = (res.dUcDt * sd - s.uc * dSd) / delta;
  const Vec3 dEta = (res.dUlDt * sd - s.ul * dSd) / delta;
  const double dKappa = 2 * (res.dUqDt * sd - s.uq * dSd) / delta;
  fit.geometricVariation =
      dTau * dTau + t * t * dEta.squaredNorm() + t * t * t * t * dKappa * dKappa;
  PrincipalCurvatures pc;
  if (options.estimator == EstimatorKind::W1) {
    // Eq. 1.31 at the projection: the normal is the plain gradient (Eq. 1.29) there and
    // H = 2 u_q / sqrt(Delta) (Eq. 1.32); umbilic, so the directions are an arbitrary pair.
    const Vec3 g = s.gradient(proj);
    if (!(g.norm() > 0)) return fit;
    pc.valid = true;
    pc.normal = g.normalized();
    pc.kMax = pc.kMin = pc.mean = fit.kappa;
    tangentBasis(pc.normal, pc.dirMax, pc.dirMin);
  } else {
    // W2 (Eq. 1.35) / W3 (Eq. 1.38) at y with the complete gradient (Eq. 1.33).
    pc = shapeOperatorCurvatures(
        res.gradient, options.estimator == EstimatorKind::W3 ? res.hessianW3 : res.hessianW2);
  }
  if (!pc.valid) return fit;
  fit.normal = pc.normal;
  fit.kMax = pc.kMax;
  fit.kMin = pc.kMin;
  fit.meanCurvature = pc.mean;
  fit.dirMax = pc.dirMax;
  fit.dirMin = pc.dirMin;
  fit.valid = true;
  return fit;
}

/// APSS estimators with optional MLS (Eq. 1.12): intermediate steps only need the projection,
/// so derivatives are computed once, at the step that is reported. The steps start at x with
/// number `firstStep` (fitAtBatch goes on alone from there); `given`, when set, is that step's
/// robust sphere made already without derivatives, with its neighbours in ws.columns and its
/// factors in ws.weights.
LocalFit fitSphereMls(const Vec3& x, double t, const SurfaceSamples& samples,
                      const FitOptions& options, FitScratch& ws,
                      const OrientedSphereFitResult* given = nullptr, int firstStep = 1) {
  const int maxSteps = options.mls ? std::max(1, options.mlsMaxSteps) : 1;
  Vec3 y = x;
  for (int step = firstStep;; ++step) {
    const bool lastStep = step >= maxSteps;
    const bool isGiven = step == firstStep && given;
    // A reported step's sphere comes with its derivatives.
    bool reported = false;
    OrientedSphereFitResult res;
    if (isGiven) {
      res = *given;
    } else {
      gatherNeighbors(y, t, samples, ws);
      reported = lastStep || (step == 1 && options.expectFirstStepConverged);
      res = robustSphere(t, options, ws, reported);
    }
    if (res.valid && !lastStep) {
      const Vec3 projection = y + res.sphere.project(Vec3::Zero());
      if ((projection - y).norm() >= options.mlsTolerance * t) {
        y = projection;
        continue;
      }
      // Converged: this step is reported.
    }
    if (res.valid && !reported) res = reportedPass(t, options, ws, res.neighbors);
    LocalFit fit;
    fit.neighbors = res.neighbors;
    if (res.valid) fit = sphereQuantities(res, y, t, options);
    fit.mlsSteps = step;
    if (!fit.valid) markInvalid(fit);  // (mlsSteps 0 too, as for every invalid fit)
    return fit;
  }
}

/// The baselines: one fit at y over the neighbours within t.
LocalFit fitBaseline(const Vec3& y, double t, const SurfaceSamples& samples,
                     const FitOptions& options, FitScratch& ws) {
  samples.index.radiusSearch(y, t, ws.neighbors);
  switch (options.estimator) {
    case EstimatorKind::Plane:
      return fitPlane(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Mean:
      return fitMean(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Quadric:
      return fitQuadric(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Jet:
      return fitJet(y, t, ws.neighbors, samples, options.minNeighbors);
    default:
      break;
  }
  return LocalFit{};
}

}  // namespace

FitWorkspace::FitWorkspace() : scratch_(std::make_unique<FitScratch>()) {}
FitWorkspace::FitWorkspace(const FitWorkspace&) : FitWorkspace() {}
FitWorkspace::FitWorkspace(FitWorkspace&&) noexcept = default;
FitWorkspace& FitWorkspace::operator=(const FitWorkspace&) { return *this; }
FitWorkspace& FitWorkspace::operator=(FitWorkspace&&) noexcept = default;
FitWorkspace::~FitWorkspace() = default;

LocalFit fitAt(const Vec3& x, double t, const SurfaceSamples& samples, const FitOptions& options,
               FitWorkspace& workspace) {
  FitScratch& ws = workspace.scratch();
  if (!(t > 0) || !std::isfinite(t)) {
    throw OptionError("fit scale t must be a positive finite number (got " + std::to_string(t) +
                      ")");
  }
  if (estimatorNeedsNormals(options.estimator) &&
      samples.normals.size() != samples.positions.size()) {
    throw OptionError(std::string("estimator '") + estimatorName(options.estimator) +
                      "' needs one normal per point (estimate normals first, or use plane, "
                      "quadric or jet)");
  }
  if (!x.allFinite()) return LocalFit{};
  if (isAlgebraicSphere(options.estimator)) {
    return fitSphereMls(x, t, samples, options, ws);
  }
  Vec3 y = x;
  LocalFit fit;
  const int maxSteps = options.mls ? std::max(1, options.mlsMaxSteps) : 1;
  for (int step = 1; step <= maxSteps; ++step) {
    fit = fitBaseline(y, t, samples, options, ws);
    fit.mlsSteps = step;
    if (!fit.valid) {
      markInvalid(fit);
      return fit;
    }
    // Eq. 1.12: iterate x <- phi(x) until the step is below tolerance * t; the last fit is the
    // one made at the (converged) projected point, where the curvatures are reported.
    if (!options.mls || step == maxSteps) break;
    const double move = (fit.projection - y).norm();
    if (move < options.mlsTolerance * t) break;
    y = fit.projection;
  }
  if (options.mls && fit.mlsSteps > 1 &&
      (options.estimator == EstimatorKind::Plane || options.estimator == EstimatorKind::Mean)) {
    // At the converged point x lies on its own plane (d = 0), so H = 8 d / t^2 would vanish.
    // With MLS, d is the signed displacement from the original x to the converged point along
    // the final normal (our reading of "Plane (MLS)" / "Mean (MLS)" in Table 1.1).
    const double d = (x - fit.projection).dot(fit.normal);
    fit.meanCurvature = fit.kMax = fit.kMin = 8 * d / (t * t);
  }
  return fit;
}

void fitAtBatch(const Vec3* xs, std::size_t count, double t, const SurfaceSamples& samples,
                const FitOptions& options, FitWorkspace& workspace, LocalFit* out) {
  FitScratch& ws = workspace.scratch();
  if (count > kFitBatch) throw OptionError("fitAtBatch takes at most 8 points at once");
  bool lanes = count > 1 && isAlgebraicSphere(options.estimator) && options.robust &&
               options.robustIterations > 0 && !(options.robustTolerance > 0) &&
               avx512Available() && t > 0 && std::isfinite(t) &&
               samples.normals.size() == samples.positions.size();
  for (std::size_t l = 0; l < count && lanes; ++l) lanes = xs[l].allFinite();
  if (!lanes) {
    for (std::size_t l = 0; l < count; ++l) out[l] = fitAt(xs[l], t, samples, options, workspace);
    return;
  }
  const int maxSteps = options.mls ? std::max(1, options.mlsMaxSteps) : 1;
  const double invSr2 = 1 / ((kRobustSigmaR * t) * (kRobustSigmaR * t));
  const double invSn2 = 1 / (kRobustSigmaN * kRobustSigmaN);
  Vec3 y[kFitBatch];
  std::size_t pending[kFitBatch];  // the points still projecting, in order
  std::size_t left = count;
  for (std::size_t l = 0; l < count; ++l) y[l] = xs[l], pending[l] = l;
  // The MLS steps side by side while at least two points are left, one lane per point; a point
  // that is done (invalid, converged or at the last step) is finished alone (its derivatives).
  for (int step = 1; left >= 2; ++step) {
    const NeighborColumns* fits[kFitBatch];
    for (std::size_t s = 0; s < left; ++s) {
      gatherNeighbors(y[pending[s]], t, samples, ws);
      std::swap(ws.columns, ws.batchColumns[s]);
      fits[s] = &ws.batchColumns[s];
    }
    ws.interleaved.assign(fits, int(left));
    LaneSphere spheres[kFitBatch];
    robustSpheresInLanes(ws.interleaved, t, options.robustIterations, options.minNeighbors, invSr2,
                         invSn2, spheres, ws.batchFactors);
    std::size_t kept = 0;
    for (std::size_t s = 0; s < left; ++s) {
      const std::size_t l = pending[s];
      const AlgebraicSphere& sphere = spheres[s].sphere;
      if (spheres[s].valid && step < maxSteps) {
        const Vec3 projection = y[l] + sphere.project(Vec3::Zero());
        if ((projection - y[l]).norm() >= options.mlsTolerance * t) {
          y[l] = projection;
          pending[kept++] = l;
          continue;
        }
      }
      std::swap(ws.columns, ws.batchColumns[s]);
      std::swap(ws.weights, ws.batchFactors[s]);
      OrientedSphereFitResult res;
      res.valid = spheres[s].valid;
      res.neighbors = spheres[s].neighbors;
      res.sphere = sphere;
      res.gradient = sphere.ul;
      out[l] = fitSphereMls(y[l], t, samples, options, ws, &res, step);
    }
    // The lanes kept keep their order (s' <= s): their columns are gathered again next step.
    left = kept;
    if (left == 1) {
      const std::size_t l = pending[0];
      out[l] = fitSphereMls(y[l], t, samples, options, ws, nullptr, step + 1);
      left = 0;
    }
  }
}

}  // namespace scalespace
