#pragma once
// Polylines (`scalespace lines`, io/Polylines.hpp) drawn as line segments over the cloud:
//   GET /api/lines/positions            float32 x y z per vertex, relative to the origin given
//                                       (the cloud layer's, so that lines and points line up)
//   GET /api/lines/segments             uint32 pairs (vertex a, vertex b), one per segment: each
//                                       line's consecutive vertices, and last -> first when closed
//                                       (as many segments as the PLY file has edges)
//   GET /api/lines/attribute?name=NAME  float32 per vertex; NAME an attribute column of the
//                                       vertices (scale, k1, line_id, ...) or line_index (the
//                                       line's number in file order)
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scalespace/io/Polylines.hpp"
#include "scalespace/viewer/ViewerLayer.hpp"

namespace scalespace::viewer {

class LinesLayer : public ViewerLayer {
 public:
  /// `lines` as readPolylines returns them (OptionError naming the PolylineSet field when
  /// malformed); `origin`: what the served positions are relative to.
  LinesLayer(PolylineSet lines, const Vec3& origin);
  std::string name() const override { return "lines"; }
  /// vertex_count, segment_count, line_count, closed_count, bounds (relative to the origin) and
  /// per attribute (line_index first) its name, type, min, max, p02, p98.
  nlohmann::json manifest() const override;
  ViewerResponse handle(const std::string& endpoint, const ViewerRequest& request) const override;

  std::size_t segmentCount() const { return segments_.size() / 2; }

 private:
  PolylineSet lines_;
  Vec3 origin_;
  std::vector<std::uint32_t> segments_;  // 2 per segment
  std::vector<double> lineIndex_;        // per vertex
  nlohmann::json attributes_;
};

}  // namespace scalespace::viewer
