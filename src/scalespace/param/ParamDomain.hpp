#pragma once
// The parameter domain of a flattened cloud (Sec. 4.3): the global algebraic sphere the points
// converged to gives either sphere coordinates (a unit vector, longitude and latitude) or plane
// coordinates (u, v).
//
// Which domain (DomainKind::Auto): the thesis takes what the flow gives, a plane or a sphere
// (its fountain, "quite planar", lands on a sphere of high radius). A disk-like surface on a
// sphere of high radius is still best read in a plane, so Auto looks at the cap the points
// cover: a plane when they fit in a cap of angular radius <= DomainOptions::maxPlaneCapDegrees
// (or the fit is a plane), else the sphere.
//
// Plane coordinates of points on a sphere: the stereographic projection from the centre of the
// largest empty cap (conformal and one-to-one; the points nearest the hole spread the most),
// scaled to be isometric at the opposite point. Of points on a plane: orthonormal coordinates.
// In both, (u, v, normal) is right-handed with the flowed normals, and u follows the world x axis
// as seen in the domain (the world y axis where x is along the normal).
#include <string>
#include <vector>

#include "scalespace/core/Types.hpp"
#include "scalespace/param/ScaleSpaceFlattening.hpp"

namespace scalespace {

using Vec2 = Eigen::Vector2d;

enum class DomainKind { Auto, Plane, Sphere };
/// "auto", "plane", "sphere"; parse throws OptionError naming the accepted values.
const char* domainKindName(DomainKind kind);
DomainKind parseDomainKind(const std::string& name);

struct DomainOptions {
  DomainKind kind = DomainKind::Auto;
  double maxPlaneCapDegrees = 80;  // Auto: plane when the points fit in a cap this wide
};

struct DomainMap {
  DomainKind kind = DomainKind::Plane;  // Plane or Sphere: what was chosen
  bool globalFitIsPlane = false;        // the last fit of Sec. 4.3 was a plane
  Vec3 centre = Vec3::Zero();           // sphere centre (global fit not a plane)
  double radius = 0;                    // sphere radius (0 when the fit is a plane)
  /// The angular radius of the smallest cap around `capAxis` holding every point, and the
  /// angular radius of the largest cap holding none (sampled directions, about 2 degrees).
  Vec3 capAxis = Vec3::UnitZ();
  double capDegrees = 0, emptyCapDegrees = 0;
  /// Plane coordinates (kind Plane), one per point.
  std::vector<Vec2> uv;
  /// Unit vectors from the centre (kind Sphere), one per point; longitude in (-180, 180] and
  /// latitude in [-90, 90] degrees about the world z axis.
  std::vector<Vec3> direction;
  std::vector<double> longitude, latitude;
  /// Plane: the frame of the plane coordinates (the exact plane's, or the stereographic one).
  Vec3 planeOrigin = Vec3::Zero(), planeU = Vec3::UnitX(), planeV = Vec3::UnitY();
  Vec3 pole = Vec3::Zero();  // stereographic pole (Plane from a sphere), unit
  double stereographicScale = 0;
  /// +1 when the flowed normals point away from the sphere's centre, -1 towards it: the
  /// orientation of the tangent bases of localOffset.
  double orientation = 1;
  std::vector<std::string> warnings;  // e.g. a sphere domain asked for points on a plane

  std::size_t size() const { return kind == DomainKind::Plane ? uv.size() : direction.size(); }
  /// Where point j lands seen from point i, in domain length units: a 2D offset in the plane, or
  /// in the sphere's tangent plane at i (basis e1 x e2 = direction[i]) times the radius.
  Vec2 localOffset(std::size_t i, std::size_t j) const;
  /// A point in 3D that holds the domain position of point i, for neighbour searches in the
  /// domain: (u, v, 0), or the unit vector times the radius.
  Vec3 embedded(std::size_t i) const;
};

/// Reads the flattened points of `flat` in the domain. Throws OptionError on an invalid
/// maxPlaneCapDegrees (must be in (0, 180)).
DomainMap mapToDomain(const FlatteningResult& flat, const DomainOptions& options = {});

/// The same from parameters read back from a file: plane coordinates or unit vectors (the other
/// empty). Throws OptionError unless exactly one is given, all finite.
DomainMap domainFromCoordinates(const std::vector<Vec2>& uv, const std::vector<Vec3>& direction);

}  // namespace scalespace
