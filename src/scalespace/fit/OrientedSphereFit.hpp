#pragma once
// Closed-form fit of an algebraic sphere to oriented samples (Eq. 1.7-1.9, Guennebaud 2008),
// evaluated in a frame centred at the evaluation point x (q = p - x; docs/THESIS_NOTES.md, frame
// centred at the evaluation point). One pass over the neighbours accumulates the weighted sums of
// 1, q, n, q.n, |q|^2 and, on request, their first and second derivatives with respect to x
// (through the weights only: the frame stays fixed at x) and with respect to t. The
// quotient/product rules (Jet.hpp) then give the derivatives of u_c, u_l, u_q, hence the complete
// gradient (Eq. 1.33) and Hessians of Eq. 1.34 (W2) and 1.36 (W3) of the scalar field
// f(y) = u_c(y) + u_l(y).(y - x) + u_q(y) |y - x|^2 at y = x.
#include <Eigen/Core>
#include <cstddef>

#include "scalespace/core/Types.hpp"
#include "scalespace/fit/AlgebraicSphere.hpp"
#include "scalespace/fit/NeighborColumns.hpp"
#include "scalespace/fit/SimdKernel.hpp"
#include "scalespace/fit/WeightKernel.hpp"

namespace scalespace {

/// Which spatial derivatives of the fit to compute (W1: None, W2: First, W3: Second).
enum class FitDerivatives { None = 0, First = 1, Second = 2 };

struct OrientedSphereFitResult {
  bool valid = false;
  int neighbors = 0;       // samples with non-zero weight
  double weightSum = 0;    // sum of the weights
  AlgebraicSphere sphere;  // frame centred at x
  /// Complete gradient of f at x (Eq. 1.33 with x := 0); equals u_l when derivatives are None.
  Vec3 gradient = Vec3::Zero();
  Mat3 hessianW2 = Mat3::Zero();   // Eq. 1.34 at x (needs First)
  Mat3 hessianW3 = Mat3::Zero();   // Eq. 1.36 at x (needs Second)
  Mat3 jacobianUl = Mat3::Zero();  // d u_l_i / d x_j (needs First)
  Vec3 gradUc = Vec3::Zero(), gradUq = Vec3::Zero();
  /// Scale derivatives d/dt of u_c, u_l, u_q at fixed x (only when requested).
  double dUcDt = 0, dUqDt = 0;
  Vec3 dUlDt = Vec3::Zero();
};

/// The sphere of precomputed sums without derivatives: what finish() gives for
/// FitDerivatives::None on the same sums, without a fit object (the robust passes' intermediate
/// fits, fit/LocalFit). `sums`: sum w, w q (3), w n (3), w q.n, w |q|^2 over `count` samples of
/// positive weight, frame centred at the fit's point; false where finish() is invalid.
bool sphereFromSums(const double* sums, int count, double t, int minNeighbors,
                    AlgebraicSphere& sphere);

class OrientedSphereFit {
 public:
  /// Starts a fit at x with support t. `scaleDerivatives` adds the d/dt sums.
  void begin(const Vec3& x, double t, FitDerivatives order, bool scaleDerivatives = false);
  /// Adds sample p with unit normal n; `extraWeight` multiplies the kernel weight (robust
  /// re-weighting; treated as a constant when differentiating).
  void add(const Vec3& p, const Vec3& n, double extraWeight = 1.0);
  /// add(p_k, n_k, extraWeight[k]) for every sample k of the columns, p_k = (qx, qy, qz)[k] and
  /// n_k = (nx, ny, nz)[k] (their d2 and weight are not read). The derivative pass reads the
  /// columns eight at a time (fit/DerivativeSums).
  void addColumns(const NeighborColumns& columns, const double* extraWeight);
  /// Solves Eq. 1.7-1.9 (and the derivatives). Invalid when fewer than minNeighbors samples
  /// have weight, when the positions are degenerate (all equal) or Delta <= 0. `kernel`
  /// (fit/SimdKernel.hpp): the second-order (W3) solve has an AVX-512 version.
  OrientedSphereFitResult finish(int minNeighbors, SimdKernel kernel = SimdKernel::Auto) const;

  const Vec3& center() const { return x_; }
  double support() const { return kernel_.t; }

 private:
  Vec3 x_ = Vec3::Zero();
  WeightKernel kernel_{1.0};
  FitDerivatives order_ = FitDerivatives::None;
  bool scale_ = false;
  int count_ = 0;
  /// sum over the samples of item_i * factor_j (fit/DerivativeSums.hpp): items 1, q, n, q.n,
  /// |q|^2; factors w, grad_x w (3), a and b q q^T (xx, yy, zz, xy, xz, yz) of hess_x w =
  /// a I + b q q^T, dw/dt. Column 0 is the plain fit's sums.
  double sums_[9][12] = {};
};

}  // namespace scalespace
