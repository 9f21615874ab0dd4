#pragma once
// One kind of result shown by the viewer (the cloud, planes; later lines, features, cylinders,
// parametrizations): its part of the manifest and its endpoints under /api/<name>/. A new kind of
// result is a new layer class; the router and the server do not change.
#include <nlohmann/json.hpp>
#include <string>

#include "scalespace/viewer/ViewerHttp.hpp"

namespace scalespace::viewer {

class ViewerLayer {
 public:
  virtual ~ViewerLayer() = default;
  /// The URL segment and manifest key: "cloud", "planes".
  virtual std::string name() const = 0;
  /// What the page needs to know before asking for data (counts, names, scales).
  virtual nlohmann::json manifest() const = 0;
  /// The answer for /api/<name()>/<endpoint>. Throws RequestError (404 for an unknown endpoint,
  /// 405 for a wrong method, 400 for bad parameters); may be called from several threads at once.
  virtual ViewerResponse handle(const std::string& endpoint,
                                const ViewerRequest& request) const = 0;
};

/// RequestError(405) unless request.method is `method`.
void requireMethod(const ViewerRequest& request, const char* method);

}  // namespace scalespace::viewer
