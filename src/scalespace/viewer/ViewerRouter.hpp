#pragma once
// Every request of the viewer goes through route(): the guard (Host, token), then a fixed set of
// paths — the page (/, /index.html, /app.js), the manifest (/api/manifest) and the layers'
// endpoints (/api/<layer>/<endpoint>). Anything else is a 404: no path is ever mapped to a file.
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scalespace/viewer/PageAssets.hpp"
#include "scalespace/viewer/RequestGuard.hpp"
#include "scalespace/viewer/ViewerLayer.hpp"

namespace scalespace::viewer {

class ViewerRouter {
 public:
  /// `source`: what was opened (path, kind), shown by the page; copied into the manifest.
  ViewerRouter(std::string token, PageAssets page, std::vector<std::unique_ptr<ViewerLayer>> layers,
               nlohmann::json source);
  /// The port the server bound, which the Host check compares with. Call before serving.
  void setPort(int port) { guard_.port = port; }
  int port() const { return guard_.port; }
  const std::string& token() const { return guard_.token; }

  /// Never throws: errors of layers become 4xx answers (RequestError, OptionError), anything
  /// unexpected a 500 with its message.
  ViewerResponse route(const ViewerRequest& request) const;

 private:
  ViewerResponse dispatch(const ViewerRequest& request) const;

  GuardSettings guard_;
  PageAssets page_;
  std::vector<std::unique_ptr<ViewerLayer>> layers_;
  std::string manifest_;  // serialised once: the layers' manifests do not change
};

}  // namespace scalespace::viewer
