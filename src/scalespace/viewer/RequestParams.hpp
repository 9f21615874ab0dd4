#pragma once
// Strict parsing of query parameters and binary bodies: anything but the exact expected form is a
// RequestError(400) naming the parameter, so a malformed request never reaches the library.
#include <optional>
#include <string>
#include <vector>

#include "scalespace/core/Types.hpp"
#include "scalespace/viewer/ViewerHttp.hpp"

namespace scalespace::viewer {

/// The integer parameter `name` in [lo, hi], or nothing when absent.
std::optional<long long> intParam(const ViewerRequest& request, const std::string& name,
                                  long long lo, long long hi);
/// The finite number `name`, or `fallback` when absent.
double doubleParam(const ViewerRequest& request, const std::string& name, double fallback);
/// "1,2,3" -> {1, 2, 3}: at most `maxCount` integers in [lo, hi]; nothing when absent.
std::optional<std::vector<int>> intListParam(const ViewerRequest& request, const std::string& name,
                                             int lo, int hi, std::size_t maxCount);
/// The body as little-endian uint32 point indices, each < pointCount.
std::vector<Index> indicesFromBody(const std::string& body, std::size_t pointCount);
/// The body as little-endian uint32 component ids, each < componentCount (a selection too long
/// for a URL).
std::vector<int> componentIdsFromBody(const std::string& body, std::size_t componentCount);

}  // namespace scalespace::viewer
