#include "scalespace/viewer/ViewerLayer.hpp"

#include "scalespace/viewer/RequestError.hpp"

namespace scalespace::viewer {

void requireMethod(const ViewerRequest& request, const char* method) {
  if (request.method != method)
    throw RequestError(405, request.path + " answers " + method + " only");
}

}  // namespace scalespace::viewer
