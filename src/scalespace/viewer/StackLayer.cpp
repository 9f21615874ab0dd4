#include "scalespace/viewer/StackLayer.hpp"

#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/viewer/BinaryArrays.hpp"
#include "scalespace/viewer/RequestError.hpp"
#include "scalespace/viewer/RequestParams.hpp"

namespace scalespace::viewer {

namespace {

// The scalar quantities of a ScaleLayer, named as `scalespace export --scale` names its columns.
struct StackQuantity {
  const char* name;
  const char* description;
  float (*value)(const ScaleLayer&, std::size_t i);
  bool inCompact;  // stored by the compact encoding (gls_fitness is not: it reads as zeros)
};

#define SS_SCALAR(field) [](const ScaleLayer& L, std::size_t i) { return L.field[i]; }
const StackQuantity kQuantities[] = {
    {"curv_mean", "mean curvature H", SS_SCALAR(meanCurvature), true},
    {"curv_max", "principal curvature k_max", SS_SCALAR(kMax), true},
    {"curv_min", "principal curvature k_min", SS_SCALAR(kMin), true},
    {"gls_tau", "GLS tau", SS_SCALAR(tau), true},
    {"gls_kappa", "GLS kappa", SS_SCALAR(kappa), true},
    {"gls_fitness", "GLS fitness (Pratt norm)", SS_SCALAR(fitness), false},
    {"anisotropy", "1 - |u_l| (Eq. 1.20)", SS_SCALAR(anisotropy), true},
    {"geometric_variation", "GLS geometric variation nu", SS_SCALAR(geometricVariation), true},
    {"neighbors", "samples in the last fit",
     [](const ScaleLayer& L, std::size_t i) { return float(L.neighbors[i]); }, true},
    {"fit_valid", "1 if the fit is valid",
     [](const ScaleLayer& L, std::size_t i) { return float(L.valid[i]); }, true},
};
#undef SS_SCALAR
constexpr std::size_t kQuantityCount = sizeof kQuantities / sizeof kQuantities[0];

// The most quantities one series request may name (each at most once would do; repeats are
// allowed but bounded).
constexpr std::size_t kMaxSeriesQuantities = 4 * kQuantityCount;

}  // namespace

std::vector<std::string> StackLayer::quantityNames(StackEncoding encoding) {
  std::vector<std::string> names;
  for (const StackQuantity& q : kQuantities)
    if (encoding != StackEncoding::Compact || q.inCompact) names.emplace_back(q.name);
  return names;
}

StackLayer::StackLayer(std::shared_ptr<const ScaleStackReader> reader, DisplaySample sample)
    : reader_(std::move(reader)), sample_(sample) {
  if (sample_.pointCount != reader_->pointCount())
    throw OptionError("StackLayer: the display sample has " + std::to_string(sample_.pointCount) +
                      " points, the stack " + std::to_string(reader_->pointCount()));
  const bool compact = reader_->info().encoding == StackEncoding::Compact;
  for (std::size_t k = 0; k < kQuantityCount; ++k)
    if (!compact || kQuantities[k].inCompact) quantities_.push_back(k);
}

nlohmann::json StackLayer::manifest() const {
  const StackInfo& info = reader_->info();
  nlohmann::json quantities = nlohmann::json::array();
  for (std::size_t k : quantities_)
    quantities.push_back(
        {{"name", kQuantities[k].name}, {"description", kQuantities[k].description}});
  return {{"point_count", reader_->pointCount()},
          {"display_count", sample_.count()},
          {"scale_count", reader_->scaleCount()},
          {"scales", info.scales},
          {"encoding", stackEncodingName(info.encoding)},
          {"format_version", info.formatVersion},
          {"quantities", quantities}};
}

std::size_t StackLayer::quantityIndex(const std::string& name, const std::string& parameter) const {
  for (std::size_t k : quantities_)
    if (name == kQuantities[k].name) return k;
  std::string known;
  for (std::size_t k : quantities_)
    known += std::string(known.empty() ? "" : ", ") + kQuantities[k].name;
  throw RequestError(400, "parameter " + parameter + ": the stack has no quantity '" + name +
                              "' (it has " + known + ")");
}

ViewerResponse StackLayer::handle(const std::string& endpoint, const ViewerRequest& request) const {
  const std::size_t m = reader_->scaleCount(), n = reader_->pointCount();
  if (endpoint == "values") {
    requireMethod(request, "GET");
    const auto it = request.params.find("quantity");
    if (it == request.params.end()) throw RequestError(400, "parameter quantity: missing");
    const StackQuantity& q = kQuantities[quantityIndex(it->second, "quantity")];
    const auto j = intParam(request, "scale", 0, (long long)m - 1);
    if (!j) throw RequestError(400, "parameter scale: missing");
    const ScaleLayer layer = reader_->readScale(std::size_t(*j));
    std::string out;
    out.reserve(sample_.count() * 4);
    for (std::size_t k = 0; k < sample_.count(); ++k)
      appendFloat32(out, q.value(layer, sample_[k]));
    return binaryResponse(std::move(out));
  }
  if (endpoint == "series") {
    requireMethod(request, "GET");
    const auto i = intParam(request, "point", 0, (long long)n - 1);
    if (!i) throw RequestError(400, "parameter point: missing");
    std::vector<std::size_t> asked = quantities_;
    const auto it = request.params.find("quantities");
    if (it != request.params.end()) {
      asked.clear();
      const std::string& text = it->second;
      for (std::size_t start = 0;;) {
        const std::size_t comma = text.find(',', start);
        if (asked.size() == kMaxSeriesQuantities)
          throw RequestError(400, "parameter quantities: more than " +
                                      std::to_string(kMaxSeriesQuantities) + " names");
        asked.push_back(quantityIndex(
            text.substr(start, comma == std::string::npos ? comma : comma - start), "quantities"));
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
    }
    const ScaleLayer series = reader_->readPointSeries(std::size_t(*i));
    std::string out;
    out.reserve(asked.size() * m * 4);
    for (std::size_t k : asked)
      for (std::size_t j = 0; j < m; ++j) appendFloat32(out, kQuantities[k].value(series, j));
    return binaryResponse(std::move(out));
  }
  throw RequestError(404, "no endpoint " + request.path);
}

}  // namespace scalespace::viewer
