#include "scalespace/viewer/CloudLayer.hpp"

#include <utility>
#include <vector>

#include "scalespace/viewer/AttributeRanges.hpp"
#include "scalespace/viewer/BinaryArrays.hpp"
#include "scalespace/viewer/RequestError.hpp"

namespace scalespace::viewer {

CloudLayer::CloudLayer(std::shared_ptr<const PointCloud> cloud, DisplaySample sample)
    : cloud_(std::move(cloud)), sample_(sample), attributes_(attributeRanges(*cloud_)) {}

nlohmann::json CloudLayer::manifest() const {
  Vec3 lo, hi;
  cloud_->bounds(lo, hi);
  const Vec3& o = cloud_->origin();
  return {{"point_count", sample_.pointCount},
          {"display_count", sample_.count()},
          {"display_order", "coarse_to_fine"},
          {"origin", {o.x(), o.y(), o.z()}},
          {"bounds", {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}}},
          {"has_normals", cloud_->hasNormals()},
          {"attributes", attributes_}};
}

ViewerResponse CloudLayer::handle(const std::string& endpoint, const ViewerRequest& request) const {
  auto vectors = [&](const std::vector<Vec3>& values) {
    return binaryResponse(sampledArray(sample_, values, [](std::string& out, const Vec3& v) {
      for (int d = 0; d < 3; ++d) appendFloat32(out, float(v[d]));
    }));
  };
  if (endpoint == "positions") {
    requireMethod(request, "GET");
    return vectors(cloud_->positions());
  }
  if (endpoint == "indices") {
    requireMethod(request, "GET");
    std::string out;
    out.reserve(sample_.count() * 4);
    for (std::size_t k = 0; k < sample_.count(); ++k) appendUint32(out, sample_[k]);
    return binaryResponse(std::move(out));
  }
  if (endpoint == "normals") {
    requireMethod(request, "GET");
    if (!cloud_->hasNormals()) throw RequestError(404, "the cloud has no normals");
    return vectors(cloud_->normals());
  }
  if (endpoint == "attribute") {
    requireMethod(request, "GET");
    const auto it = request.params.find("name");
    if (it == request.params.end()) throw RequestError(400, "parameter name: missing");
    const AttributeColumn* column = cloud_->findAttribute(it->second);
    if (!column)
      throw RequestError(404, "parameter name: the cloud has no attribute '" + it->second + "'");
    return binaryResponse(sampledArray(
        sample_, column->values, [](std::string& out, double v) { appendFloat32(out, float(v)); }));
  }
  throw RequestError(404, "no endpoint " + request.path);
}

}  // namespace scalespace::viewer
