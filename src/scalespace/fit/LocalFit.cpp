#include "scalespace/fit/LocalFit.hpp"

#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/fit/JetFit.hpp"
#include "scalespace/fit/MeanFit.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/fit/PlaneFit.hpp"
#include "scalespace/fit/QuadricFit.hpp"
#include "scalespace/fit/ShapeOperator.hpp"

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

/// One APSS fit at y (with optional robust re-weighting) and its shape operator.
LocalFit fitSphere(const Vec3& y, double t, const SurfaceSamples& samples,
                   const FitOptions& options, FitWorkspace& ws) {
  const FitDerivatives order = options.estimator == EstimatorKind::W3   ? FitDerivatives::Second
                               : options.estimator == EstimatorKind::W2 ? FitDerivatives::First
                                                                        : FitDerivatives::None;
  OrientedSphereFit acc;
  acc.begin(y, t, order, true);
  for (const Neighbor& nb : ws.neighbors)
    acc.add(samples.positions[nb.index], samples.normals[nb.index]);
  OrientedSphereFitResult res = acc.finish(options.minNeighbors);
  if (options.robust) {
    const double sr2 = (kRobustSigmaR * t) * (kRobustSigmaR * t);
    const double sn2 = kRobustSigmaN * kRobustSigmaN;
    for (int it = 0; it < options.robustIterations && res.valid; ++it) {
      const AlgebraicSphere s = res.sphere;
      acc.begin(y, t, order, true);
      for (const Neighbor& nb : ws.neighbors) {
        const Vec3 q = samples.positions[nb.index] - y;
        const Vec3 g = s.gradient(q);
        const double gn = g.norm();
        if (!(gn > 0)) continue;
        const double r = s.value(q) / gn;
        const double dn = (samples.normals[nb.index] - g / gn).squaredNorm();
        const double rho = std::exp(-r * r / sr2) * std::exp(-dn / sn2);
        acc.add(samples.positions[nb.index], samples.normals[nb.index], rho);
      }
      // min 1: re-weighting may zero far outliers; the neighbour count check was done above.
      OrientedSphereFitResult next = acc.finish(1);
      next.neighbors = res.neighbors;
      if (!next.valid) break;
      res = next;
    }
  }
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

LocalFit fitOnce(const Vec3& y, double t, const SurfaceSamples& samples, const FitOptions& options,
                 FitWorkspace& ws) {
  samples.index.radiusSearch(y, t, ws.neighbors);
  switch (options.estimator) {
    case EstimatorKind::W3:
    case EstimatorKind::W2:
    case EstimatorKind::W1:
      return fitSphere(y, t, samples, options, ws);
    case EstimatorKind::Plane:
      return fitPlane(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Mean:
      return fitMean(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Quadric:
      return fitQuadric(y, t, ws.neighbors, samples, options.minNeighbors);
    case EstimatorKind::Jet:
      return fitJet(y, t, ws.neighbors, samples, options.minNeighbors);
  }
  return LocalFit{};
}

}  // namespace

LocalFit fitAt(const Vec3& x, double t, const SurfaceSamples& samples, const FitOptions& options,
               FitWorkspace& workspace) {
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
  Vec3 y = x;
  LocalFit fit;
  const int maxSteps = options.mls ? std::max(1, options.mlsMaxSteps) : 1;
  for (int step = 1; step <= maxSteps; ++step) {
    fit = fitOnce(y, t, samples, options, workspace);
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

}  // namespace scalespace
