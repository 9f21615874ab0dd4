#pragma once
// "Quadric" baseline (PSS, Alexa 2001; Sec. 1.4.3): weighted least squares of a height field
// h(u, v) = a + b u + c v + d u^2 + e u v + f v^2 over the weighted PCA plane (same kernel, Eq.
// 1.6). Curvatures are those of the graph at the foot point of x (above x's (u, v)), signed so
// that the surface bends away from the reference normal (PCA normal oriented like the input
// normals) with positive curvature, i.e. a sphere with outward normals gets kappa = +1/r.
// Jet.hpp-free: a 6x6 normal system, no allocation.
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

LocalFit fitQuadric(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                    const SurfaceSamples& samples, int minNeighbors);

/// Principal curvatures and tangent directions of the graph z = h(u, v) at a point with
/// gradient (hu, hv) and Hessian [[huu, huv], [huv, hvv]], in the frame (e1, e2, n).
/// Curvature sign: positive when the graph bends away from n (sphere below with n outwards).
void graphCurvatures(double hu, double hv, double huu, double huv, double hvv, const Vec3& e1,
                     const Vec3& e2, const Vec3& n, LocalFit& fit);

}  // namespace scalespace
