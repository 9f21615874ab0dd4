#include "scalespace/core/AnalyticSurface.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "scalespace/core/Error.hpp"

namespace scalespace {
namespace {

// Geometry of the shapes (see the header).
const Vec3 kSphereCentre(0, 0, -1);
constexpr double kSaddleK1 = 2, kSaddleK2 = -1;
constexpr double kTorusMajor = 2, kTorusMinor = 0.5;
const Vec3 kTorusCentre(-2, 0, -0.5);
const Vec3 kEllipsoidAxes(1.5, 1, 0.75);
const Vec3 kEllipsoidCentre(0, 0, -0.75);

/// Uniform-by-area proposal covering at least the part of the surface inside the ball.
class Proposal {
 public:
  Proposal(SurfaceShape shape, const Vec3& centre, double radius)
      : shape_(shape), centre_(centre), radius_(radius) {
    if (shape_ == SurfaceShape::Sphere) {
      // Cap around the direction of the ball centre: a point within `radius` of the centre is
      // within radius + dist(centre, sphere) of the nearest sphere point (chord bound).
      const Vec3 d = centre - kSphereCentre;
      axis_ = d.norm() > 0 ? Vec3(d.normalized()) : Vec3::UnitZ();
      const double chord = radius + std::abs(d.norm() - 1);
      capCos_ = std::max(-1.0, 1 - chord * chord / 2);
    } else if (shape_ == SurfaceShape::Saddle) {
      const double m = std::max(std::abs(kSaddleK1), std::abs(kSaddleK2));
      const double far = std::max(std::abs(centre.x()), std::abs(centre.y())) + radius;
      maxArea_ = std::sqrt(1 + 2 * m * m * far * far);
    }
  }

  template <class Rng>
  Vec3 draw(Rng& rng) {
    std::uniform_real_distribution<double> u01(0, 1);
    switch (shape_) {
      case SurfaceShape::Sphere: {
        // Uniform on the cap: cos(theta) uniform (Archimedes), azimuth uniform.
        const double c = capCos_ + (1 - capCos_) * u01(rng);
        const double s = std::sqrt(std::max(0.0, 1 - c * c));
        const double phi = 2 * kPi * u01(rng);
        Vec3 a, b;
        frame(axis_, a, b);
        return kSphereCentre + c * axis_ + s * (std::cos(phi) * a + std::sin(phi) * b);
      }
      case SurfaceShape::Cylinder: {
        // Area element r dphi dy: phi and y uniform.
        const double phi = 2 * kPi * u01(rng) - kPi;
        const double y = centre_.y() + radius_ * (2 * u01(rng) - 1);
        return Vec3(std::sin(phi), y, std::cos(phi) - 1);
      }
      case SurfaceShape::Saddle: {
        // Area element sqrt(1 + |grad h|^2) dx dy: accept with that density over its maximum.
        for (;;) {
          const double x = centre_.x() + radius_ * (2 * u01(rng) - 1);
          const double y = centre_.y() + radius_ * (2 * u01(rng) - 1);
          const double hx = -kSaddleK1 * x, hy = -kSaddleK2 * y;
          if (u01(rng) * maxArea_ <= std::sqrt(1 + hx * hx + hy * hy)) {
            return Vec3(x, y, -(kSaddleK1 * x * x + kSaddleK2 * y * y) / 2);
          }
        }
      }
      case SurfaceShape::Torus: {
        // Area element r (R + r cos(theta)) dphi dtheta.
        for (;;) {
          const double theta = 2 * kPi * u01(rng);
          const double ring = kTorusMajor + kTorusMinor * std::cos(theta);
          if (u01(rng) * (kTorusMajor + kTorusMinor) > ring) continue;
          const double phi = 2 * kPi * u01(rng);
          return kTorusCentre +
                 Vec3(ring * std::cos(phi), ring * std::sin(phi), kTorusMinor * std::sin(theta));
        }
      }
      case SurfaceShape::Ellipsoid: {
        // Map of the unit sphere u -> A u scales area by |A^-T u| det A: accept proportionally.
        std::normal_distribution<double> g(0, 1);
        const double a = kEllipsoidAxes.x(), b = kEllipsoidAxes.y(), c = kEllipsoidAxes.z();
        const double maxScale = std::max({b * c, a * c, a * b});
        for (;;) {
          Vec3 u(g(rng), g(rng), g(rng));
          if (!(u.norm() > 0)) continue;
          u.normalize();
          const double scale = std::sqrt(std::pow(b * c * u.x(), 2) + std::pow(a * c * u.y(), 2) +
                                         std::pow(a * b * u.z(), 2));
          if (u01(rng) * maxScale <= scale) {
            return kEllipsoidCentre + kEllipsoidAxes.cwiseProduct(u);
          }
        }
      }
    }
    return Vec3::Zero();
  }

 private:
  static void frame(const Vec3& n, Vec3& a, Vec3& b) {
    int axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    a = (Vec3::Unit(axis) - n(axis) * n).normalized();
    b = n.cross(a);
  }
  SurfaceShape shape_;
  Vec3 centre_;
  double radius_;
  Vec3 axis_ = Vec3::UnitZ();
  double capCos_ = -1;
  double maxArea_ = 1;
};

}  // namespace

const char* surfaceShapeName(SurfaceShape shape) {
  switch (shape) {
    case SurfaceShape::Sphere:
      return "sphere";
    case SurfaceShape::Cylinder:
      return "cylinder";
    case SurfaceShape::Saddle:
      return "saddle";
    case SurfaceShape::Torus:
      return "torus";
    case SurfaceShape::Ellipsoid:
      return "ellipsoid";
  }
  return "?";
}

SurfaceShape parseSurfaceShape(const std::string& name) {
  for (SurfaceShape s : {SurfaceShape::Sphere, SurfaceShape::Cylinder, SurfaceShape::Saddle,
                         SurfaceShape::Torus, SurfaceShape::Ellipsoid}) {
    if (name == surfaceShapeName(s)) return s;
  }
  throw OptionError("unknown surface '" + name +
                    "' (use one of sphere, cylinder, saddle, torus, ellipsoid)");
}

double surfaceImplicit(SurfaceShape shape, const Vec3& p) {
  switch (shape) {
    case SurfaceShape::Sphere:
      return (p - kSphereCentre).squaredNorm() - 1;
    case SurfaceShape::Cylinder:
      return p.x() * p.x() + (p.z() + 1) * (p.z() + 1) - 1;
    case SurfaceShape::Saddle:
      return p.z() + (kSaddleK1 * p.x() * p.x() + kSaddleK2 * p.y() * p.y()) / 2;
    case SurfaceShape::Torus: {
      // (|q|^2 + R^2 - r^2)^2 - 4 R^2 (qx^2 + qy^2): polynomial, positive outside the tube.
      const Vec3 q = p - kTorusCentre;
      const double R2 = kTorusMajor * kTorusMajor, r2 = kTorusMinor * kTorusMinor;
      const double s = q.squaredNorm() + R2 - r2;
      return s * s - 4 * R2 * (q.x() * q.x() + q.y() * q.y());
    }
    case SurfaceShape::Ellipsoid:
      return (p - kEllipsoidCentre).cwiseQuotient(kEllipsoidAxes).squaredNorm() - 1;
  }
  return 0;
}

Vec3 surfaceImplicitGradient(SurfaceShape shape, const Vec3& p) {
  switch (shape) {
    case SurfaceShape::Sphere:
      return 2 * (p - kSphereCentre);
    case SurfaceShape::Cylinder:
      return Vec3(2 * p.x(), 0, 2 * (p.z() + 1));
    case SurfaceShape::Saddle:
      return Vec3(kSaddleK1 * p.x(), kSaddleK2 * p.y(), 1);
    case SurfaceShape::Torus: {
      const Vec3 q = p - kTorusCentre;
      const double R2 = kTorusMajor * kTorusMajor, r2 = kTorusMinor * kTorusMinor;
      const double s = q.squaredNorm() + R2 - r2;
      return 4 * s * q - 8 * R2 * Vec3(q.x(), q.y(), 0);
    }
    case SurfaceShape::Ellipsoid: {
      const Vec3 q = p - kEllipsoidCentre;
      return 2 * q.cwiseQuotient(kEllipsoidAxes.cwiseProduct(kEllipsoidAxes));
    }
  }
  return Vec3::Zero();
}

Mat3 surfaceImplicitHessian(SurfaceShape shape, const Vec3& p) {
  switch (shape) {
    case SurfaceShape::Sphere:
      return 2 * Mat3::Identity();
    case SurfaceShape::Cylinder:
      return Vec3(2, 0, 2).asDiagonal();
    case SurfaceShape::Saddle:
      return Vec3(kSaddleK1, kSaddleK2, 0).asDiagonal();
    case SurfaceShape::Torus: {
      const Vec3 q = p - kTorusCentre;
      const double R2 = kTorusMajor * kTorusMajor, r2 = kTorusMinor * kTorusMinor;
      const double s = q.squaredNorm() + R2 - r2;
      Mat3 h = 8 * q * q.transpose() + 4 * s * Mat3::Identity();
      h(0, 0) -= 8 * R2;
      h(1, 1) -= 8 * R2;
      return h;
    }
    case SurfaceShape::Ellipsoid:
      return Vec3(2 * kEllipsoidAxes.cwiseProduct(kEllipsoidAxes).cwiseInverse()).asDiagonal();
  }
  return Mat3::Zero();
}

SurfacePoint evaluateSurface(SurfaceShape shape, const Vec3& p) {
  SurfacePoint sp;
  sp.position = p;
  const Vec3 g = surfaceImplicitGradient(shape, p);
  const Mat3 h = surfaceImplicitHessian(shape, p);
  const double gn = g.norm();
  sp.normal = g / gn;
  int axis = 0;
  sp.normal.cwiseAbs().minCoeff(&axis);
  const Vec3 u = (Vec3::Unit(axis) - sp.normal(axis) * sp.normal).normalized();
  const Vec3 v = sp.normal.cross(u);
  Eigen::Matrix<double, 3, 2> P;
  P << u, v;
  Eigen::Matrix2d W = P.transpose() * h * P / gn;  // Eq. 1.28
  W = 0.5 * (W + W.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(W);
  sp.kMin = eig.eigenvalues()(0);
  sp.kMax = eig.eigenvalues()(1);
  sp.meanCurvature = 0.5 * (sp.kMin + sp.kMax);
  sp.dirMin = (P * eig.eigenvectors().col(0)).normalized();
  sp.dirMax = sp.normal.cross(sp.dirMin);
  return sp;
}

std::vector<SurfacePoint> sampleInBall(SurfaceShape shape, const Vec3& centre, double radius,
                                       std::size_t count, std::uint64_t seed) {
  if (!(radius > 0) || !std::isfinite(radius)) {
    throw OptionError("sampling ball radius must be positive (got " + std::to_string(radius) + ")");
  }
  std::mt19937_64 rng(seed);
  Proposal proposal(shape, centre, radius);
  std::vector<SurfacePoint> out;
  out.reserve(count);
  const double r2 = radius * radius;
  const std::size_t maxRejections = 1000 * count + 1000000;
  std::size_t rejected = 0;
  while (out.size() < count) {
    const Vec3 p = proposal.draw(rng);
    if ((p - centre).squaredNorm() <= r2) {
      out.push_back(evaluateSurface(shape, p));
    } else if (++rejected > maxRejections) {
      throw OptionError(std::string("the sampling ball (radius ") + std::to_string(radius) +
                        ") barely meets the " + surfaceShapeName(shape) +
                        " (move it onto the surface or enlarge it)");
    }
  }
  return out;
}

void addPositionNoise(std::vector<Vec3>& positions, double sigma, std::uint64_t seed) {
  if (!(sigma > 0)) return;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, sigma);
  for (Vec3& p : positions) p += Vec3(g(rng), g(rng), g(rng));
}

void addNormalRotationNoise(std::vector<Vec3>& normals, double sigmaDegrees, const Vec3& axis,
                            std::uint64_t seed) {
  if (!(sigmaDegrees > 0)) return;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, sigmaDegrees * kPi / 180);
  const Vec3 a = axis.normalized();
  for (Vec3& n : normals) n = Eigen::AngleAxisd(std::abs(g(rng)), a) * n;
}

PointCloud sampleSurface(const SurfaceSampleOptions& options) {
  if (options.count == 0) throw OptionError("sample count must be at least 1");
  if (!(options.positionNoise >= 0) || !(options.normalNoiseDegrees >= 0)) {
    throw OptionError("noise levels must be >= 0");
  }
  const bool closed = options.shape == SurfaceShape::Sphere ||
                      options.shape == SurfaceShape::Torus ||
                      options.shape == SurfaceShape::Ellipsoid;
  // A ball of radius 10 around the origin contains every closed shape entirely.
  const double radius = options.ballRadius > 0 ? options.ballRadius : (closed ? 10.0 : 1.0);
  const std::vector<SurfacePoint> pts =
      sampleInBall(options.shape, Vec3::Zero(), radius, options.count, options.seed);
  std::vector<Vec3> positions(pts.size()), normals(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    positions[i] = pts[i].position;
    normals[i] = pts[i].normal;
  }
  addPositionNoise(positions, options.positionNoise, options.seed + 1);
  addNormalRotationNoise(normals, options.normalNoiseDegrees, Vec3(1, 1, 0), options.seed + 2);
  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  cloud.setNormals(std::move(normals));
  // Columns are created first and looked up afterwards: addAttribute may reallocate the list.
  cloud.addAttribute("mean_curvature", ScalarType::Float64);
  cloud.addAttribute("k1", ScalarType::Float64);
  cloud.addAttribute("k2", ScalarType::Float64);
  auto* ch = cloud.findAttribute("mean_curvature");
  auto* c1 = cloud.findAttribute("k1");
  auto* c2 = cloud.findAttribute("k2");
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ch->values[i] = pts[i].meanCurvature;
    c1->values[i] = pts[i].kMax;
    c2->values[i] = pts[i].kMin;
  }
  return cloud;
}

}  // namespace scalespace
