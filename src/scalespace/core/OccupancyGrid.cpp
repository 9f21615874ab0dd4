#include "scalespace/core/OccupancyGrid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scalespace/core/Error.hpp"

namespace scalespace {

OccupancyGrid::OccupancyGrid(const std::vector<Vec3>& points, double cellSize,
                             std::size_t maxCells) {
  if (!(cellSize > 0) || !std::isfinite(cellSize))
    throw OptionError("OccupancyGrid: the cell size must be finite and > 0");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!(lo.x() <= hi.x())) return;  // no finite point: an empty grid
  const Vec3 extent = hi - lo;
  // Grow the cell until the padded grid fits: (extent / cell + 3)^3 cells at most.
  cell_ = cellSize;
  for (;;) {
    double cells = 1;
    for (int a = 0; a < 3; ++a) cells *= std::floor(extent[a] / cell_) + 3;
    if (cells <= double(std::max<std::size_t>(maxCells, 27))) break;
    cell_ *= 1.25;
  }
  origin_ = lo - Vec3::Constant(cell_);
  for (int a = 0; a < 3; ++a) dims_[a] = long(std::floor(extent[a] / cell_)) + 3;
  bits_.assign((std::size_t(dims_[0]) * dims_[1] * dims_[2] + 63) / 64, 0);
  for (const Vec3& p : points) {
    if (!p.allFinite()) continue;
    const Vec3 c = (p - origin_) / cell_;
    const std::size_t id =
        (std::size_t(c.z()) * dims_[1] + std::size_t(c.y())) * dims_[0] + std::size_t(c.x());
    bits_[id >> 6] |= std::uint64_t(1) << (id & 63);
  }
}

bool OccupancyGrid::occupiedCell(long x, long y, long z) const {
  if (x < 0 || y < 0 || z < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) return false;
  const std::size_t id = (std::size_t(z) * dims_[1] + std::size_t(y)) * dims_[0] + std::size_t(x);
  return (bits_[id >> 6] >> (id & 63)) & 1;
}

bool OccupancyGrid::occupied(const Vec3& p) const {
  if (bits_.empty() || !p.allFinite()) return false;
  const Vec3 c = (p - origin_) / cell_;
  return occupiedCell(long(std::floor(c.x())), long(std::floor(c.y())), long(std::floor(c.z())));
}

bool OccupancyGrid::escapes(const Vec3& from, const Vec3& direction, int surfaceCells) const {
  if (bits_.empty() || !from.allFinite() || !direction.allFinite()) return true;
  const Vec3 c = (from - origin_) / cell_;
  long cell[3], step[3];
  double tMax[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = long(std::floor(c[a]));
    const double d = direction[a];
    step[a] = d > 0 ? 1 : (d < 0 ? -1 : 0);
    if (step[a] == 0) {
      tMax[a] = tDelta[a] = std::numeric_limits<double>::infinity();
    } else {
      const double boundary = d > 0 ? double(cell[a] + 1) : double(cell[a]);
      tMax[a] = (boundary - c[a]) / d;
      tDelta[a] = 1.0 / std::abs(d);
    }
  }
  auto inside = [&] {
    for (int a = 0; a < 3; ++a)
      if (cell[a] < 0 || cell[a] >= dims_[a]) return false;
    return true;
  };
  bool leftSurface = false;
  int surfaceRun = 0;
  while (inside()) {
    const bool full = occupiedCell(cell[0], cell[1], cell[2]);
    if (!leftSurface) {
      if (!full) {
        leftSurface = true;
      } else if (++surfaceRun > surfaceCells) {
        return false;
      }
    } else if (full) {
      return false;
    }
    const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
    cell[a] += step[a];
    tMax[a] += tDelta[a];
  }
  return true;
}

int OccupancyGrid::escapingRays(const Vec3& p, const Vec3& unitNormal) const {
  const Vec3 u = unitNormal.unitOrthogonal();
  const Vec3 v = unitNormal.cross(u);
  const double c = std::cos(25.0 * M_PI / 180.0), s = std::sin(25.0 * M_PI / 180.0);
  const Vec3 rays[5] = {unitNormal, c * unitNormal + s * u, c * unitNormal - s * u,
                        c * unitNormal + s * v, c * unitNormal - s * v};
  int count = 0;
  for (const Vec3& r : rays) count += escapes(p, r, 3) ? 1 : 0;
  return count;
}

}  // namespace scalespace
