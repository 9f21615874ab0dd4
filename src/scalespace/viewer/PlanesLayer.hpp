#pragma once
// A `scalespace planes` result: the query tools of Sec. 2.4 answered by planes/PlaneQueries, the
// very functions `scalespace segment` calls, so that the page shows what segment would write.
//   GET  /api/planes/components   float64 records, one per component, fields in the manifest
//   GET  /api/planes/labels?min_persistence=P | ?level=J | ?components=1,2   int32 per point
//        (labelsByPersistence, labelsAtScale at the level's scale, labelsOfComponents)
//   POST /api/planes/brush        body: uint32 indices -> JSON ranking (rankByBrush, Eq. 2.2)
//   POST /api/planes/similar?component=C[&birth_tolerance=&death_tolerance=&area_tolerance=
//        &angle=][&domain=all]  body: uint32 domain indices -> JSON ids (findSimilar)
//   POST /api/planes/export?<labels query>&format=ply|csv  the cloud with segment's plane_id and
//        colours, written atomically (writeCloud) as a new file in the export folder -> JSON path
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/viewer/DisplaySample.hpp"
#include "scalespace/viewer/ViewerLayer.hpp"

namespace scalespace::viewer {

struct PlanesLayerOptions {
  std::string exportDirectory;  // where exports go (must exist)
  /// Files an export must never replace (the input cloud, the result's files); exports are new
  /// files anyway, this guards against a race with a file appearing under the chosen name.
  std::vector<std::string> protectedPaths;
};

class PlanesLayer : public ViewerLayer {
 public:
  /// `model` as segment uses it: plane offsets relative to the cloud's origin. `cloud` is the
  /// cloud the model was computed on (same point count).
  PlanesLayer(PlaneModel model, std::shared_ptr<const PointCloud> cloud, DisplaySample sample,
              PlanesLayerOptions options);
  std::string name() const override { return "planes"; }
  nlohmann::json manifest() const override;
  ViewerResponse handle(const std::string& endpoint, const ViewerRequest& request) const override;

  /// Field names of the /components records, in order.
  static const std::vector<std::string>& componentFields();

 private:
  std::vector<int> labels(const ViewerRequest& request, std::string* description) const;
  ViewerResponse brush(const ViewerRequest& request) const;
  ViewerResponse similar(const ViewerRequest& request) const;
  ViewerResponse exportLabels(const ViewerRequest& request) const;

  PlaneModel model_;
  std::shared_ptr<const PointCloud> cloud_;
  DisplaySample sample_;
  PlanesLayerOptions options_;
  mutable std::mutex exportMutex_;  // one export at a time: name choice and write
};

}  // namespace scalespace::viewer
