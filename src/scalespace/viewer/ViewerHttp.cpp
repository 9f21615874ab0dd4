#include "scalespace/viewer/ViewerHttp.hpp"

#include <utility>

namespace scalespace::viewer {

ViewerResponse errorResponse(int status, const std::string& message) {
  return {status, "text/plain; charset=utf-8", message + "\n"};
}

ViewerResponse jsonResponse(std::string json) { return {200, "application/json", std::move(json)}; }

ViewerResponse binaryResponse(std::string bytes) {
  return {200, "application/octet-stream", std::move(bytes)};
}

}  // namespace scalespace::viewer
