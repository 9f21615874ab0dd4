#include "scalespace/param/ParamDomain.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {
namespace {

constexpr double kDegrees = 180 / kPi;

/// A unit vector orthogonal to `axis` along the world x axis (y when x is nearly along it).
Vec3 firstAxis(const Vec3& axis) {
  const Vec3 x = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (x - x.dot(axis) * axis).normalized();
}

/// A tangent basis (e1, e2) at the unit vector d with e1 x e2 = sign * d.
void tangentBasis(const Vec3& d, double sign, Vec3& e1, Vec3& e2) {
  e1 = firstAxis(d);
  e2 = sign * d.cross(e1);
}

/// The largest cap free of `directions` (unit vectors), searched over ~10^4 directions of a
/// Fibonacci lattice (neighbouring lattice directions about 2 degrees apart): its centre and
/// angular radius in degrees.
void largestEmptyCap(const std::vector<Vec3>& directions, Vec3& centre, double& degrees) {
  const auto index = makeSpatialIndex(directions);
  const int count = 10000;
  const double golden = kPi * (3 - std::sqrt(5.0));
  std::vector<Neighbor> nearest;
  degrees = -1;
  for (int k = 0; k < count; ++k) {
    const double z = 1 - (2 * k + 1) / double(count);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 d(r * std::cos(golden * k), r * std::sin(golden * k), z);
    index->knnSearch(d, 1, nearest);
    const double chord = std::sqrt(nearest.front().distSq);
    const double angle = 2 * std::asin(std::min(1.0, chord / 2)) * kDegrees;
    if (angle > degrees) {
      degrees = angle;
      centre = d;
    }
  }
}

}  // namespace

const char* domainKindName(DomainKind kind) {
  switch (kind) {
    case DomainKind::Auto:
      return "auto";
    case DomainKind::Plane:
      return "plane";
    case DomainKind::Sphere:
      return "sphere";
  }
  return "?";
}

DomainKind parseDomainKind(const std::string& name) {
  if (name == "auto") return DomainKind::Auto;
  if (name == "plane") return DomainKind::Plane;
  if (name == "sphere") return DomainKind::Sphere;
  throw OptionError("unknown domain '" + name + "' (expected auto, plane or sphere)");
}

Vec2 DomainMap::localOffset(std::size_t i, std::size_t j) const {
  if (kind == DomainKind::Plane) return uv[j] - uv[i];
  Vec3 e1, e2;
  tangentBasis(direction[i], orientation, e1, e2);
  const Vec3 d = (direction[j] - direction[i]) * (radius > 0 ? radius : 1.0);
  return Vec2(d.dot(e1), d.dot(e2));
}

Vec3 DomainMap::embedded(std::size_t i) const {
  if (kind == DomainKind::Plane) return Vec3(uv[i].x(), uv[i].y(), 0);
  return direction[i] * (radius > 0 ? radius : 1.0);
}

DomainMap mapToDomain(const FlatteningResult& flat, const DomainOptions& options) {
  if (!(options.maxPlaneCapDegrees > 0 && options.maxPlaneCapDegrees < 180))
    throw OptionError("DomainOptions::maxPlaneCapDegrees must be in (0, 180)");
  const std::size_t n = flat.positions.size();
  DomainMap map;
  const AlgebraicSphere& sphere = flat.sphere;
  map.globalFitIsPlane =
      !(sphere.uq != 0) || sphere.isPlane(flat.diagonal) || sphere.radius() > 1e4 * flat.diagonal;
  if (map.globalFitIsPlane) {
    // Orthonormal coordinates in the plane, (u, v, normal) right-handed.
    const Vec3 normal = sphere.ul.normalized();
    map.kind = DomainKind::Plane;
    map.planeU = firstAxis(normal);
    map.planeV = normal.cross(map.planeU);
    map.planeOrigin = flat.sphereOrigin + sphere.project(Vec3::Zero());
    map.capAxis = normal;
    map.uv.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 d = flat.positions[i] - map.planeOrigin;
      map.uv[i] = Vec2(d.dot(map.planeU), d.dot(map.planeV));
    }
    if (options.kind == DomainKind::Sphere)
      map.warnings.push_back(
          "the points converged to a plane, not a sphere: they are given plane coordinates");
    return map;
  }

  map.centre = flat.sphereOrigin + sphere.center();
  map.radius = sphere.radius();
  // The gradient points along the flowed normals: outwards where u_q > 0 (Eq. 1.32).
  map.orientation = sphere.uq > 0 ? 1 : -1;
  std::vector<Vec3> directions(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 d = flat.positions[i] - map.centre;
    directions[i] = d.norm() > 0 ? Vec3(d.normalized()) : Vec3::UnitZ();
  }
  Vec3 hole;
  largestEmptyCap(directions, hole, map.emptyCapDegrees);
  map.capAxis = -hole;
  map.capDegrees = 0;
  for (const Vec3& d : directions)
    map.capDegrees =
        std::max(map.capDegrees, std::acos(std::clamp(d.dot(map.capAxis), -1.0, 1.0)) * kDegrees);

  map.kind = options.kind;
  if (map.kind == DomainKind::Auto)
    map.kind =
        map.capDegrees <= options.maxPlaneCapDegrees ? DomainKind::Plane : DomainKind::Sphere;

  if (map.kind == DomainKind::Sphere) {
    map.direction = std::move(directions);
    map.longitude.resize(n);
    map.latitude.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& d = map.direction[i];
      map.longitude[i] = std::atan2(d.y(), d.x()) * kDegrees;
      map.latitude[i] = std::asin(std::clamp(d.z(), -1.0, 1.0)) * kDegrees;
    }
    return map;
  }

  // Stereographic projection from the hole's centre P onto the plane tangent at -P, scaled by
  // the radius: isometric at -P (u = 2R x / (1 - z) in the frame (e1, e2, P)).
  map.pole = hole;
  map.planeU = firstAxis(hole);
  map.planeV = map.orientation * map.planeU.cross(hole);
  map.planeOrigin = map.centre - map.radius * hole;
  map.stereographicScale = 2 * map.radius;
  if (map.emptyCapDegrees < 5)
    map.warnings.push_back(
        "the points cover the whole sphere: in the plane domain the points nearest the pole "
        "spread far out (the sphere domain keeps them)");
  map.uv.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& d = directions[i];
    // 1 - z = |d - P|^2 / 2, exact where z is near 1.
    const double oneMinusZ = std::max((d - hole).squaredNorm() / 2, 1e-12);
    map.uv[i] = map.stereographicScale / oneMinusZ * Vec2(d.dot(map.planeU), d.dot(map.planeV));
  }
  return map;
}

DomainMap domainFromCoordinates(const std::vector<Vec2>& uv, const std::vector<Vec3>& direction) {
  if (uv.empty() == direction.empty())
    throw OptionError("a parametrization has either plane coordinates or sphere directions");
  DomainMap map;
  if (!uv.empty()) {
    for (const Vec2& p : uv)
      if (!p.allFinite()) throw OptionError("the plane coordinates hold NaN or Inf");
    map.kind = DomainKind::Plane;
    map.uv = uv;
    return map;
  }
  map.kind = DomainKind::Sphere;
  map.radius = 1;
  map.direction.reserve(direction.size());
  for (const Vec3& d : direction) {
    if (!d.allFinite() || !(d.norm() > 0))
      throw OptionError("the sphere directions hold NaN, Inf or zero vectors");
    map.direction.push_back(d.normalized());
  }
  return map;
}

}  // namespace scalespace
