#include "scalespace/viewer/ViewerRouter.hpp"

#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/viewer/RequestError.hpp"

namespace scalespace::viewer {

namespace {

const char* const kTokenPlaceholder = "%SCALESPACE_TOKEN%";

std::string pageWithToken(std::string html, const std::string& token) {
  for (std::size_t at = html.find(kTokenPlaceholder); at != std::string::npos;
       at = html.find(kTokenPlaceholder, at + token.size()))
    html.replace(at, std::char_traits<char>::length(kTokenPlaceholder), token);
  return html;
}

// The token is 32 hex digits: nothing in it needs escaping in HTML.
std::string missingPage(const std::string& reason) {
  std::string escaped;
  for (char c : reason) {
    if (c == '<')
      escaped += "&lt;";
    else if (c == '>')
      escaped += "&gt;";
    else if (c == '&')
      escaped += "&amp;";
    else
      escaped += c;
  }
  return "<!doctype html><meta charset=utf-8><title>scalespace view</title><p>" + escaped +
         "</p><p>The data endpoints (/api/...) work without the page.</p>";
}

}  // namespace

ViewerRouter::ViewerRouter(std::string token, PageAssets page,
                           std::vector<std::unique_ptr<ViewerLayer>> layers, nlohmann::json source)
    : page_(std::move(page)), layers_(std::move(layers)) {
  guard_.token = std::move(token);
  nlohmann::json manifest = {{"version", SCALESPACE_VERSION}, {"source", std::move(source)}};
  nlohmann::json names = nlohmann::json::array();
  for (const auto& layer : layers_) {
    names.push_back(layer->name());
    manifest[layer->name()] = layer->manifest();
  }
  manifest["layers"] = names;
  manifest_ = manifest.dump();
}

ViewerResponse ViewerRouter::dispatch(const ViewerRequest& request) const {
  const std::string& path = request.path;
  if (path == "/" || path == "/index.html") {
    requireMethod(request, "GET");
    if (!page_.missingReason.empty())
      return {200, "text/html; charset=utf-8", missingPage(page_.missingReason)};
    return {200, "text/html; charset=utf-8", pageWithToken(page_.indexHtml, guard_.token)};
  }
  if (path == "/app.js") {
    requireMethod(request, "GET");
    if (!page_.missingReason.empty()) throw RequestError(404, page_.missingReason);
    return {200, "text/javascript; charset=utf-8", page_.appJs};
  }
  if (path == "/api/manifest") {
    requireMethod(request, "GET");
    return jsonResponse(manifest_);
  }
  const std::string api = "/api/";
  if (path.compare(0, api.size(), api) == 0) {
    const std::size_t slash = path.find('/', api.size());
    if (slash != std::string::npos && path.find('/', slash + 1) == std::string::npos) {
      const std::string layerName = path.substr(api.size(), slash - api.size());
      for (const auto& layer : layers_)
        if (layer->name() == layerName) return layer->handle(path.substr(slash + 1), request);
    }
  }
  throw RequestError(404, "not found: " + path);
}

ViewerResponse ViewerRouter::route(const ViewerRequest& request) const {
  if (auto refused = refusal(request, guard_)) return *refused;
  if (!request.malformed.empty()) return errorResponse(400, "bad request: " + request.malformed);
  try {
    return dispatch(request);
  } catch (const RequestError& e) {
    return errorResponse(e.status(), e.what());
  } catch (const OptionError& e) {
    return errorResponse(400, e.what());
  } catch (const std::bad_alloc&) {
    return errorResponse(503, "out of memory for this request");
  } catch (const std::exception& e) {
    return errorResponse(500, e.what());
  }
}

}  // namespace scalespace::viewer
