#include "scalespace/core/OrientedNormals.hpp"

#include <cmath>
#include <utility>

namespace scalespace {

OrientedNormals estimateOrientedNormals(const std::vector<Vec3>& points, const SpatialIndex& index,
                                        const OrientedNormalsOptions& options,
                                        const ProgressCallback& progress) {
  OrientedNormals out;
  out.estimation = estimateNormals(points, index, options.estimation, progress);
  out.normals = std::move(out.estimation.normals);
  out.estimation.normals.clear();
  std::vector<Vec3>& planes = out.estimation.planeNormals;
  if (options.sheetSign == SheetSign::OwnTree || planes.empty()) {
    out.orientation = orientNormals(points, out.normals, index, options.orientation,
                                    out.estimation.valid, progress);
    return out;
  }
  // SheetSign::ByRays: the sheet normals' own tree on a copy, kept below if the rays prefer it.
  std::vector<Vec3> ownTree;
  NormalOrientationResult ownTreeOrientation;
  if (options.sheetSign == SheetSign::ByRays) {
    ownTree = out.normals;
    ownTreeOrientation =
        orientNormals(points, ownTree, index, options.orientation, out.estimation.valid, progress);
  }
  out.orientation =
      orientNormals(points, planes, index, options.orientation, out.estimation.valid, progress);
  const double guess = options.orientation.creaseThreshold;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double c = planes[i].dot(out.normals[i]);
    if (c < 0) out.normals[i] = -out.normals[i];
    if (std::abs(c) < guess && out.orientation.reliable[i]) {
      out.orientation.reliable[i] = 0;
      ++out.orientation.unreliableCount;
    }
  }
  out.signSource = SheetSign::FromPlanes;
  if (options.sheetSign == SheetSign::ByRays) {
    out.rays = compareByRays(points, ownTree, out.normals, index, options.orientation);
    if (out.rays.firstInward <= out.rays.secondInward) {
      out.normals = std::move(ownTree);
      out.orientation = std::move(ownTreeOrientation);
      out.signSource = SheetSign::OwnTree;
    }
  }
  return out;
}

}  // namespace scalespace
