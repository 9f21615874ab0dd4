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
  return out;
}

}  // namespace scalespace
