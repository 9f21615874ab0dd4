#include "scalespace/fit/QuadricFit.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "scalespace/fit/PlaneFit.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

void graphCurvatures(double hu, double hv, double huu, double huv, double hvv, const Vec3& e1,
                     const Vec3& e2, const Vec3& n, LocalFit& fit) {
  // First fundamental form I = Id + grad h grad h^T, second II = -hess h / sqrt(1 + |grad h|^2)
  // (minus: curvature positive when the graph bends away from n); shape operator I^-1 II.
  const Eigen::Vector2d g(hu, hv);
  const double s = std::sqrt(1 + g.squaredNorm());
  Eigen::Matrix2d I = Eigen::Matrix2d::Identity() + g * g.transpose();
  Eigen::Matrix2d II;
  II << huu, huv, huv, hvv;
  II *= -1 / s;
  // Symmetric form: with L = chol(I), eigenvalues of L^-1 II L^-T equal those of I^-1 II.
  Eigen::LLT<Eigen::Matrix2d> llt(I);
  const Eigen::Matrix2d L = llt.matrixL();
  const Eigen::Matrix2d Li = L.inverse();
  Eigen::Matrix2d S = Li * II * Li.transpose();
  S = 0.5 * (S + S.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(S);
  const Eigen::Vector2d vMin = Li.transpose() * eig.eigenvectors().col(0);
  const Eigen::Vector2d vMax = Li.transpose() * eig.eigenvectors().col(1);
  const Vec3 tu = e1 + hu * n, tv = e2 + hv * n;  // tangent vectors of the graph
  fit.kMin = eig.eigenvalues()(0);
  fit.kMax = eig.eigenvalues()(1);
  fit.meanCurvature = 0.5 * (fit.kMin + fit.kMax);
  fit.normal = (n - hu * e1 - hv * e2).normalized();
  fit.dirMin = (vMin(0) * tu + vMin(1) * tv).normalized();
  fit.dirMax = fit.normal.cross(fit.dirMin);  // I-orthogonal eigenvectors are orthogonal in 3D
  if (fit.dirMax.dot(vMax(0) * tu + vMax(1) * tv) < 0) fit.dirMax = -fit.dirMax;
}

LocalFit fitQuadric(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                    const SurfaceSamples& samples, int minNeighbors) {
  LocalFit fit;
  const WeightedCovariance cov = weightedCovariance(x, t, nbrs, samples);
  fit.neighbors = cov.count;
  if (cov.count < minNeighbors) return fit;
  const PcaFrame frame = pcaFrame(cov);
  if (!frame.valid) return fit;
  // Weighted normal equations of the height field in the PCA frame centred at the barycentre,
  // coordinates scaled by 1/t for conditioning.
  const WeightKernel kernel(t);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  const double inv = 1 / t;
  for (const Neighbor& nb : nbrs) {
    const double w = WeightKernel::value(kernel.ratio(nb.distSq));
    if (!(w > 0)) continue;
    const Vec3 q = (samples.positions[nb.index] - x - cov.mean) * inv;
    const double u = q.dot(frame.e1), v = q.dot(frame.e2), h = q.dot(frame.normal);
    Eigen::Matrix<double, 6, 1> m;
    m << 1, u, v, u * u, u * v, v * v;
    A.noalias() += w * m * m.transpose();
    rhs.noalias() += (w * h) * m;
  }
  Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(A);
  if (ldlt.info() != Eigen::Success) return fit;
  const Eigen::Matrix<double, 6, 1> c = ldlt.solve(rhs);
  if (!c.allFinite() || !(ldlt.rcond() > 1e-12)) return fit;
  // Foot point above x: x's (u, v) in the scaled frame.
  const Vec3 xq = -cov.mean * inv;
  const double u = xq.dot(frame.e1), v = xq.dot(frame.e2);
  const double h = c(0) + c(1) * u + c(2) * v + c(3) * u * u + c(4) * u * v + c(5) * v * v;
  // Derivatives in unscaled units: h_phys(U) = t h(U / t) -> grad unchanged, Hessian / t.
  const double hu = c(1) + 2 * c(3) * u + c(4) * v;
  const double hv = c(2) + c(4) * u + 2 * c(5) * v;
  graphCurvatures(hu, hv, 2 * c(3) * inv, c(4) * inv, 2 * c(5) * inv, frame.e1, frame.e2,
                  frame.normal, fit);
  fit.projection = x + cov.mean + t * (u * frame.e1 + v * frame.e2 + h * frame.normal);
  fit.valid = std::isfinite(fit.kMax) && std::isfinite(fit.kMin) && fit.normal.allFinite() &&
              fit.projection.allFinite();
  if (!fit.valid) markInvalid(fit);
  return fit;
}

}  // namespace scalespace
