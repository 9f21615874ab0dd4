#pragma once
// Analytic test surfaces with exact normals and curvatures: the ground truth of the fit tests,
// of Table 1.1 (bench/table_1_1.cpp) and of `scalespace generate`.
//
// Every shape is placed so that the origin lies on it with outward normal +z and principal
// directions along x and y (the docs/THESIS_NOTES.md reading of the Sec. 1.4.3 protocol):
//   sphere     radius 1, centre (0, 0, -1)                       kappa = (1, 1) everywhere
//   cylinder   radius 1, axis y through (0, 0, -1)               kappa = (1, 0)
//   saddle     z = -(2 x^2 - y^2) / 2 (normal up)                kappa = (2, -1) at the origin
//   torus      major radius 2, minor 0.5, axis z, centre (-2, 0, -0.5): the origin is the top of
//              the tube, kappa = (2, 0) there
//   ellipsoid  semi-axes (1.5, 1, 0.75), centre (0, 0, -0.75)    kappa = (0.75, 1/3) at the origin
// Each is the zero set of an implicit F that grows outwards; normals, curvatures and directions
// at any point come from the shape operator P^T hess F P / |grad F| (Eq. 1.28), with the
// convention of docs/THESIS_NOTES.md: outward normals, a sphere of radius r has H = kappa = +1/r.
#include <cstdint>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

enum class SurfaceShape { Sphere, Cylinder, Saddle, Torus, Ellipsoid };

/// "sphere", "cylinder", "saddle", "torus", "ellipsoid"; parse throws OptionError otherwise.
const char* surfaceShapeName(SurfaceShape shape);
SurfaceShape parseSurfaceShape(const std::string& name);

/// A point of an analytic surface with its exact differential quantities.
struct SurfacePoint {
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // unit, outward
  double meanCurvature = 0;    // (kMax + kMin) / 2
  double kMax = 0, kMin = 0;
  Vec3 dirMax = Vec3::Zero(), dirMin = Vec3::Zero();  // unit, orthogonal, tangent
};

/// Implicit function F of a shape (F < 0 inside, grad F outwards) and its derivatives.
double surfaceImplicit(SurfaceShape shape, const Vec3& p);
Vec3 surfaceImplicitGradient(SurfaceShape shape, const Vec3& p);
Mat3 surfaceImplicitHessian(SurfaceShape shape, const Vec3& p);

/// Exact normal and curvatures at p (p must lie on the surface).
SurfacePoint evaluateSurface(SurfaceShape shape, const Vec3& p);

/// `count` points drawn uniformly by area on the part of the surface inside the ball
/// (centre, radius), with a seeded generator (same seed, same points). Throws OptionError when
/// the ball misses the surface (or almost: after 1000 * count + 10^6 rejected proposals).
std::vector<SurfacePoint> sampleInBall(SurfaceShape shape, const Vec3& centre, double radius,
                                       std::size_t count, std::uint64_t seed = 1);

/// Adds isotropic Gaussian noise of standard deviation sigma to every coordinate (Sec. 1.4.3).
void addPositionNoise(std::vector<Vec3>& positions, double sigma, std::uint64_t seed);
/// Table 1.1 normal noise (docs/THESIS_NOTES.md, Table 1.1 protocol): rotates each normal about
/// the fixed unit `axis` by the angle |N(0, sigmaDegrees)| (a Gaussian truncated to positive
/// angles).
void addNormalRotationNoise(std::vector<Vec3>& normals, double sigmaDegrees, const Vec3& axis,
                            std::uint64_t seed);

struct SurfaceSampleOptions {
  SurfaceShape shape = SurfaceShape::Sphere;
  std::size_t count = 100000;
  /// Radius of the ball around the origin to sample; <= 0 samples the whole surface for the
  /// closed shapes (sphere, torus, ellipsoid) and a ball of radius 1 for the open ones.
  double ballRadius = 0;
  double positionNoise = 0;       // sigma_p (absolute units)
  double normalNoiseDegrees = 0;  // sigma_n, rotation about (x + y)/sqrt(2)
  std::uint64_t seed = 1;
};

/// A cloud with positions and (noisy) normals and the exact values as attribute columns
/// "mean_curvature", "k1", "k2" (float64, taken before any noise). Throws OptionError for a
/// zero count or negative noise.
PointCloud sampleSurface(const SurfaceSampleOptions& options);

}  // namespace scalespace
