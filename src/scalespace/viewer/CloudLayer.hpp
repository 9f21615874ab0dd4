#pragma once
// The cloud itself: positions (float32, relative to the cloud's origin, which the manifest gives),
// normals and every attribute column, at the display sample's points (DisplaySample.hpp: coarse
// to fine, every prefix even over the cloud).
//   GET /api/cloud/indices              uint32 per displayed point: its index in the cloud
//   GET /api/cloud/positions            float32 x y z per point
//   GET /api/cloud/normals              float32 nx ny nz per point (404 without normals)
//   GET /api/cloud/attribute?name=NAME  float32 per point
#include <memory>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/viewer/DisplaySample.hpp"
#include "scalespace/viewer/ViewerLayer.hpp"

namespace scalespace::viewer {

class CloudLayer : public ViewerLayer {
 public:
  CloudLayer(std::shared_ptr<const PointCloud> cloud, DisplaySample sample);
  std::string name() const override { return "cloud"; }
  /// point_count, display_count, display_order, origin, bounds (relative), has_normals and per
  /// attribute its name, type, min, max and 2nd/98th percentiles (a colour bar's robust range).
  nlohmann::json manifest() const override;
  ViewerResponse handle(const std::string& endpoint, const ViewerRequest& request) const override;

 private:
  std::shared_ptr<const PointCloud> cloud_;
  DisplaySample sample_;
  nlohmann::json attributes_;  // computed once: percentiles cost a pass over each column
};

}  // namespace scalespace::viewer
