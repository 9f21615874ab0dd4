#pragma once
// Shape operator of an implicit surface (Eq. 1.28): W = P^T (hess f / |grad f|) P with P an
// orthonormal tangent basis of grad f. Its eigenvalues are the principal curvatures; with grad f
// pointing outwards a sphere of radius r gets kappa = +1/r (Eq. 1.32; docs/THESIS_NOTES.md, sign
// convention). W1 (Eq. 1.31), W2 (Eq. 1.35) and W3 (Eq. 1.38) differ only in the gradient and
// Hessian passed.
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct PrincipalCurvatures {
  bool valid = false;
  Vec3 normal = Vec3::Zero();                         // grad f / |grad f|
  double kMax = 0, kMin = 0;                          // kMax >= kMin
  double mean = 0;                                    // (kMax + kMin) / 2
  Vec3 dirMax = Vec3::Zero(), dirMin = Vec3::Zero();  // unit, orthogonal, tangent
};

/// A right-handed orthonormal pair (u, v) orthogonal to the unit vector n (u x v = n).
void tangentBasis(const Vec3& n, Vec3& u, Vec3& v);

/// Eigen-decomposition of the symmetrised W = P^T H P / |g| (Eq. 1.28). Invalid (all zero) when
/// g is zero or anything is not finite.
PrincipalCurvatures shapeOperatorCurvatures(const Vec3& gradient, const Mat3& hessian);

}  // namespace scalespace
