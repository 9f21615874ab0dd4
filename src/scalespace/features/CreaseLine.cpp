#include "scalespace/features/CreaseLine.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scalespace/core/PointMoments.hpp"

namespace scalespace {

namespace {

struct SidePlane {
  Vec3 centroid = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // unit, oriented as the side's normals
  bool flat = false;
};

/// Plane of one side's points by weighted least squares, the weights (1 - (d / reach)^2)^2 of
/// their distance d to the query point, so that a curved face gives its tangent plane near the
/// crease rather than a chord; oriented as their mean normal. Flat when the weighted RMS is within
/// maxRms and nine in ten of the side's normals lie within normalAngleDegrees of it.
SidePlane fitSide(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                  const std::vector<Neighbor>& side, double reach, double maxRms,
                  double normalAngleDegrees) {
  SidePlane plane;
  Vec3 meanNormal = Vec3::Zero();
  double total = 0;
  std::vector<double> weight(side.size());
  for (std::size_t k = 0; k < side.size(); ++k) {
    const double u = 1 - side[k].distSq / (reach * reach);
    weight[k] = u * u;
    total += weight[k];
    plane.centroid += weight[k] * positions[side[k].index];
    meanNormal += normals[side[k].index];
  }
  if (!(total > 0)) return plane;
  plane.centroid /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < side.size(); ++k) {
    const Vec3 d = positions[side[k].index] - plane.centroid;
    covariance += weight[k] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  plane.normal = eigen.eigenvectors().col(0);
  if (plane.normal.dot(meanNormal) < 0) plane.normal = -plane.normal;
  const double rms = std::sqrt(std::max(0.0, eigen.eigenvalues()(0)) / total);
  // Nine in ten of its normals within normalAngleDegrees of the plane's: one face, not the two
  // faces of a part thinner than the reach, whose points can fit one plane between them.
  std::size_t along = 0;
  for (const Neighbor& nb : side)
    along += normals[nb.index].dot(plane.normal) >= std::cos(normalAngleDegrees * M_PI / 180.0);
  plane.flat = rms <= maxRms && 10 * along >= 9 * side.size();
  return plane;
}

}  // namespace

double distanceToLine(const Vec3& x, const Vec3& point, const Vec3& unitDirection) {
  const Vec3 offset = x - point;
  return (offset - offset.dot(unitDirection) * unitDirection).norm();
}

std::optional<CreaseLine> fitCreaseLine(const std::vector<Vec3>& positions,
                                        const std::vector<Vec3>& normals, const SpatialIndex& index,
                                        const Vec3& x, const Vec3& along,
                                        const CreaseLineOptions& options, const Vec3* centre) {
  std::vector<Neighbor> found;
  index.radiusSearch(x, options.reach, found);
  if (found.size() < std::size_t(2 * options.minSidePoints)) return std::nullopt;
  // In index order: the same sums whatever order the search returns.
  std::sort(found.begin(), found.end(),
            [](const Neighbor& a, const Neighbor& b) { return a.index < b.index; });
  Vec3 mean = Vec3::Zero();
  for (const Neighbor& nb : found) mean += normals[nb.index];
  const Vec3 across = along.cross(mean);
  if (!(across.norm() > 1e-9 * std::max(1.0, mean.norm()))) return std::nullopt;
  std::vector<Neighbor> sides[2];
  if (options.splitByPosition) {
    const Vec3 unitAcross = across.normalized();
    const Vec3 origin = centre ? *centre : x;
    for (const Neighbor& nb : found) {
      const double side = (positions[nb.index] - origin).dot(unitAcross);
      if (std::abs(side) > options.sideMargin) sides[side >= 0 ? 1 : 0].push_back(nb);
    }
  } else {
    for (const Neighbor& nb : found)
      sides[normals[nb.index].dot(across) >= 0 ? 1 : 0].push_back(nb);
  }
  if (sides[0].size() < std::size_t(options.minSidePoints) ||
      sides[1].size() < std::size_t(options.minSidePoints))
    return std::nullopt;
  // Split by position, normals blended across the crease (45 degrees off on a right angle) must
  // not fail their side; a corner's third face (90 degrees off) still does.
  const double normalAngle = options.splitByPosition ? 60.0 : 30.0;
  const SidePlane a =
      fitSide(positions, normals, sides[0], options.reach, options.maxRms, normalAngle);
  const SidePlane b =
      fitSide(positions, normals, sides[1], options.reach, options.maxRms, normalAngle);
  if (!a.flat || !b.flat) return std::nullopt;
  const Vec3 direction = a.normal.cross(b.normal);
  const double sine = direction.norm();
  const double turn = std::atan2(sine, a.normal.dot(b.normal)) * 180.0 / M_PI;
  if (turn < options.minTurnDegrees) return std::nullopt;
  CreaseLine line;
  line.direction = direction / sine;
  line.turnDegrees = turn;
  // The point of both planes nearest x: both plane equations and the foot of x along the line.
  Eigen::Matrix3d system;
  system.row(0) = a.normal.transpose();
  system.row(1) = b.normal.transpose();
  system.row(2) = line.direction.transpose();
  const Vec3 rhs(a.normal.dot(a.centroid), b.normal.dot(b.centroid), line.direction.dot(x));
  line.point = system.colPivHouseholderQr().solve(rhs);
  if (!line.point.allFinite()) return std::nullopt;
  if (options.maxGap > 0) {
    const bool met = std::any_of(found.begin(), found.end(), [&](const Neighbor& nb) {
      return distanceToLine(positions[nb.index], line.point, line.direction) <= options.maxGap;
    });
    if (!met) return std::nullopt;
  }
  return line;
}

std::optional<RimLine> fitRimLine(const std::vector<Vec3>& positions, const SpatialIndex& index,
                                  const Vec3& centre, const Vec3& along,
                                  const RimLineOptions& options) {
  std::vector<Neighbor> found;
  index.radiusSearch(centre, options.reach, found);
  if (found.size() < std::size_t(std::max(options.minPoints, 3))) return std::nullopt;
  // In index order: the same sums whatever order the search returns.
  std::sort(found.begin(), found.end(),
            [](const Neighbor& a, const Neighbor& b) { return a.index < b.index; });
  PointMoments moments;
  for (const Neighbor& nb : found) moments.add(positions[nb.index]);
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(moments.covariance());
  const double trace = eigen.eigenvalues().sum();
  if (!(trace > 0) || eigen.eigenvalues()(0) > options.maxVariation * trace ||
      eigen.eigenvalues()(1) < options.minSpread * trace)
    return std::nullopt;
  RimLine rim;
  rim.normal = eigen.eigenvectors().col(0);
  // Along the salient vertices' direction, averaged over several scales: steadier than the
  // centroid's offset, which follows the sampling of a few dozen points.
  const Vec3 direction = along - along.dot(rim.normal) * rim.normal;
  if (!(direction.norm() > std::sqrt(0.5))) return std::nullopt;  // `along` leaves the sheet
  rim.direction = direction.normalized();
  rim.across = rim.normal.cross(rim.direction);
  // Outward: from the centroid towards the centre, which lies at the sheet's border.
  double inset = (centre - moments.mean).dot(rim.across);
  if (inset < 0) {
    rim.across = -rim.across;
    inset = -inset;
  }
  if (inset < options.minBorderShare * options.reach) return std::nullopt;
  double outermost = -std::numeric_limits<double>::infinity();
  for (const Neighbor& nb : found)
    outermost = std::max(outermost, (positions[nb.index] - centre).dot(rim.across));
  if (outermost > options.maxInset) return std::nullopt;
  rim.point =
      centre + outermost * rim.across + (moments.mean - centre).dot(rim.normal) * rim.normal;
  return rim;
}

bool withinRim(const RimLine& rim, const Vec3& x, double halfWidth) {
  const Vec3 offset = rim.point - x;
  return std::abs(offset.dot(rim.across)) <= halfWidth &&
         std::abs(offset.dot(rim.normal)) <= halfWidth;
}

}  // namespace scalespace
