#pragma once
// Which cubic cells of space hold a point, and whether a ray leaves the cloud without meeting
// another surface: the visibility test that tells the outside of a closed surface from its
// inside (normal orientation, core/NormalOrientation).
#include <cstdint>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

class OccupancyGrid {
 public:
  /// One bit per cell of side `cellSize` over the points' bounding box, padded by one cell. The
  /// side grows when the grid would exceed `maxCells` cells. Non-finite points are left out.
  /// Requires cellSize > 0.
  OccupancyGrid(const std::vector<Vec3>& points, double cellSize, std::size_t maxCells);

  double cellSize() const { return cell_; }
  bool occupied(const Vec3& p) const;

  /// Walks the cells along the ray from `from` in the unit `direction` (Amanatides and Woo's
  /// traversal): first out of the run of occupied cells it starts in (the surface `from` lies on,
  /// at most `surfaceCells` cells deep, else it is blocked), then on until it leaves the
  /// grid (true: the ray escapes) or enters an occupied cell (false).
  bool escapes(const Vec3& from, const Vec3& direction, int surfaceCells) const;

  /// How many of the five rays of one side of a point escape (3 surface cells): along the unit
  /// normal and four tilted 25 degrees around it.
  int escapingRays(const Vec3& p, const Vec3& unitNormal) const;

  /// Whether at least three of the five rays escape on each side of the point: an open sheet, or
  /// a part thinner than the cells, not a side of a closed surface.
  bool seesOutBothSides(const Vec3& p, const Vec3& unitNormal) const {
    return escapingRays(p, unitNormal) >= 3 && escapingRays(p, -unitNormal) >= 3;
  }

 private:
  bool occupiedCell(long x, long y, long z) const;

  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1.0;
  long dims_[3] = {0, 0, 0};
  std::vector<std::uint64_t> bits_;
};

}  // namespace scalespace
