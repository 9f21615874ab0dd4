#include "scalespace/viewer/LinesLayer.hpp"

#include <limits>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/viewer/AttributeRanges.hpp"
#include "scalespace/viewer/BinaryArrays.hpp"
#include "scalespace/viewer/RequestError.hpp"

namespace scalespace::viewer {

namespace {
const char* const kLineIndex = "line_index";
}  // namespace

LinesLayer::LinesLayer(PolylineSet lines, const Vec3& origin)
    : lines_(std::move(lines)), origin_(origin) {
  validatePolylineSet(lines_, "LinesLayer");
  const std::size_t n = lines_.vertices.size();
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw OptionError("LinesLayer: " + std::to_string(n) +
                      " vertices do not fit the uint32 segment indices");
  lineIndex_.resize(n);
  for (std::size_t l = 0; l < lines_.lineCount(); ++l) {
    const std::size_t a = lines_.offsets[l], b = lines_.offsets[l + 1];
    for (std::size_t v = a; v < b; ++v) lineIndex_[v] = double(l);
    for (std::size_t v = a; v + 1 < b; ++v) {
      segments_.push_back(std::uint32_t(v));
      segments_.push_back(std::uint32_t(v + 1));
    }
    if (lines_.isClosed(l)) {
      segments_.push_back(std::uint32_t(b - 1));
      segments_.push_back(std::uint32_t(a));
    }
  }
  // line_index is sorted: its percentiles are entries at the percentile's rank (as
  // attributeRanges takes them).
  auto at = [&](double q) { return n ? lineIndex_[std::size_t(q * double(n - 1))] : 0.0; };
  attributes_ = nlohmann::json::array();
  attributes_.push_back({{"name", kLineIndex},
                         {"type", scalarTypeName(ScalarType::Int32)},
                         {"min", at(0)},
                         {"max", at(1)},
                         {"p02", at(0.02)},
                         {"p98", at(0.98)}});
  for (auto& a : attributeRanges(lines_.vertices))
    if (a["name"] != kLineIndex) attributes_.push_back(std::move(a));
}

nlohmann::json LinesLayer::manifest() const {
  std::size_t closed = 0;
  for (std::size_t l = 0; l < lines_.lineCount(); ++l) closed += lines_.isClosed(l) ? 1 : 0;
  nlohmann::json bounds = nullptr;
  if (lines_.vertices.size() > 0) {
    Vec3 lo, hi;
    lines_.vertices.bounds(lo, hi);
    const Vec3 shift = lines_.vertices.origin() - origin_;
    lo += shift;
    hi += shift;
    bounds = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  }
  return {{"vertex_count", lines_.vertices.size()},
          {"segment_count", segmentCount()},
          {"line_count", lines_.lineCount()},
          {"closed_count", closed},
          {"bounds", bounds},
          {"attributes", attributes_}};
}

ViewerResponse LinesLayer::handle(const std::string& endpoint, const ViewerRequest& request) const {
  const std::size_t n = lines_.vertices.size();
  if (endpoint == "positions") {
    requireMethod(request, "GET");
    const Vec3 shift = lines_.vertices.origin() - origin_;
    std::string out;
    out.reserve(12 * n);
    for (const Vec3& p : lines_.vertices.positions())
      for (int d = 0; d < 3; ++d) appendFloat32(out, float(p[d] + shift[d]));
    return binaryResponse(std::move(out));
  }
  if (endpoint == "segments") {
    requireMethod(request, "GET");
    std::string out;
    out.reserve(4 * segments_.size());
    for (std::uint32_t v : segments_) appendUint32(out, v);
    return binaryResponse(std::move(out));
  }
  if (endpoint == "attribute") {
    requireMethod(request, "GET");
    const auto it = request.params.find("name");
    if (it == request.params.end()) throw RequestError(400, "parameter name: missing");
    const std::vector<double>* values = nullptr;
    if (it->second == kLineIndex) {
      values = &lineIndex_;
    } else if (const AttributeColumn* column = lines_.vertices.findAttribute(it->second)) {
      values = &column->values;
    } else {
      throw RequestError(404, "parameter name: the lines have no attribute '" + it->second + "'");
    }
    std::string out;
    out.reserve(4 * n);
    for (double v : *values) appendFloat32(out, float(v));
    return binaryResponse(std::move(out));
  }
  throw RequestError(404, "no endpoint " + request.path);
}

}  // namespace scalespace::viewer
