#include "scalespace/viewer/PlanesLayer.hpp"

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/viewer/BinaryArrays.hpp"
#include "scalespace/viewer/RequestError.hpp"
#include "scalespace/viewer/RequestParams.hpp"

namespace scalespace::viewer {

namespace fs = std::filesystem;

namespace {
constexpr std::size_t kMaxListedComponents = 100000;
}

PlanesLayer::PlanesLayer(PlaneModel model, std::shared_ptr<const PointCloud> cloud,
                         DisplaySample sample, PlanesLayerOptions options)
    : model_(std::move(model)),
      cloud_(std::move(cloud)),
      sample_(sample),
      options_(std::move(options)) {
  if (cloud_->size() != model_.membership.pointCount)
    throw Error("PlanesLayer: the cloud has " + std::to_string(cloud_->size()) +
                " points, the planes result " + std::to_string(model_.membership.pointCount));
}

const std::vector<std::string>& PlanesLayer::componentFields() {
  static const std::vector<std::string> fields = {"id",
                                                  "birth_level",
                                                  "death_level",
                                                  "birth_scale",
                                                  "death_scale",
                                                  "persistence",
                                                  "representative_level",
                                                  "point_count",
                                                  "nx",
                                                  "ny",
                                                  "nz",
                                                  "offset",
                                                  "rms",
                                                  "area",
                                                  "planar",
                                                  "noise_limited"};
  return fields;
}

nlohmann::json PlanesLayer::manifest() const {
  int maxPersistence = 0;
  for (const PlaneComponent& c : model_.components)
    maxPersistence = std::max(maxPersistence, c.persistence);
  return {{"scales", model_.scales},
          {"component_count", model_.components.size()},
          {"max_persistence", maxPersistence},
          {"component_fields", componentFields()},
          {"export_directory", options_.exportDirectory}};
}

std::vector<int> PlanesLayer::labels(const ViewerRequest& request, std::string* description) const {
  const int components = int(model_.components.size());
  const auto persistence = intParam(request, "min_persistence", 0, 1 << 30);
  const auto level = intParam(request, "level", 0, std::max(0, model_.scaleCount() - 1));
  // components=body: the ids are the body (uint32), for a selection too long for a URL.
  const auto listed = request.params.find("components");
  const auto ids = listed != request.params.end() && listed->second == "body"
                       ? std::optional<std::vector<int>>(
                             componentIdsFromBody(request.body, model_.components.size()))
                       : intListParam(request, "components", 0, std::max(0, components - 1),
                                      kMaxListedComponents);
  if (int(bool(persistence)) + int(bool(level)) + int(bool(ids)) != 1)
    throw RequestError(400, "give one of the parameters min_persistence, level, components");
  if (persistence) {
    if (description) *description = "persistence" + std::to_string(*persistence);
    return labelsByPersistence(model_, int(*persistence));
  }
  if (level) {
    if (model_.scales.empty()) throw RequestError(400, "parameter level: the result has no scales");
    if (description) *description = "level" + std::to_string(*level);
    // The level's own scale: nearestLevel finds that level again, as for `segment --scale t_j`.
    return labelsAtScale(model_, model_.scales[std::size_t(*level)]);
  }
  if (components == 0 && !ids->empty())
    throw RequestError(400, "parameter components: the result has no components");
  if (description) *description = "components" + std::to_string(ids->size());
  return labelsOfComponents(model_, *ids);
}

ViewerResponse PlanesLayer::brush(const ViewerRequest& request) const {
  requireMethod(request, "POST");
  const std::vector<BrushMatch> matches =
      rankByBrush(model_, indicesFromBody(request.body, cloud_->size()));
  nlohmann::json out = nlohmann::json::array();
  for (const BrushMatch& m : matches)
    out.push_back({{"component", m.component},
                   {"score", m.score},
                   {"overlap", m.overlap},
                   {"persistence", model_.components[std::size_t(m.component)].persistence}});
  return jsonResponse(nlohmann::json{{"matches", out}}.dump());
}

ViewerResponse PlanesLayer::similar(const ViewerRequest& request) const {
  requireMethod(request, "POST");
  const int components = int(model_.components.size());
  if (components == 0) throw RequestError(400, "parameter component: the result has no components");
  const auto query = intParam(request, "component", 0, components - 1);
  if (!query) throw RequestError(400, "parameter component: missing");
  SimilarityOptions options;
  options.birthTolerance =
      int(intParam(request, "birth_tolerance", 0, 1 << 30).value_or(options.birthTolerance));
  options.deathTolerance =
      int(intParam(request, "death_tolerance", 0, 1 << 30).value_or(options.deathTolerance));
  options.maxAreaDifference = doubleParam(request, "area_tolerance", options.maxAreaDifference);
  options.maxAngleDegrees = doubleParam(request, "angle", options.maxAngleDegrees);
  validate(options);
  std::vector<Index> domain;
  const auto all = request.params.find("domain");
  if (all != request.params.end()) {
    if (all->second != "all") throw RequestError(400, "parameter domain: only 'all' is known");
    if (!request.body.empty()) throw RequestError(400, "domain=all takes no body");
    domain.resize(cloud_->size());
    std::iota(domain.begin(), domain.end(), Index(0));
  } else {
    domain = indicesFromBody(request.body, cloud_->size());
  }
  const std::vector<int> found = findSimilar(model_, int(*query), domain, options);
  return jsonResponse(nlohmann::json{{"components", found}}.dump());
}

ViewerResponse PlanesLayer::exportLabels(const ViewerRequest& request) const {
  requireMethod(request, "POST");
  const auto format = request.params.find("format");
  if (format == request.params.end() || (format->second != "ply" && format->second != "csv"))
    throw RequestError(400, "parameter format: ply or csv");
  std::string description;
  const std::vector<int> labels = this->labels(request, &description);
  PointCloud out = *cloud_;
  addPlaneLabelColumns(out, labels);
  std::lock_guard<std::mutex> lock(exportMutex_);
  // A new file every time: the page never names a path, and nothing existing is replaced.
  fs::path path;
  for (int n = 1;; ++n) {
    path = fs::path(options_.exportDirectory) /
           ("scalespace-view-" + description + "-" + std::to_string(n) + "." + format->second);
    std::error_code ec;
    if (!fs::exists(path, ec) && !ec) break;
    if (n == 10000) throw RequestError(409, "too many exports in " + options_.exportDirectory);
  }
  for (const std::string& p : options_.protectedPaths) {
    std::error_code ec;
    if (fs::weakly_canonical(p, ec) == fs::weakly_canonical(path, ec))
      throw RequestError(409, "export: " + path.string() + " is an input");
  }
  writeCloud(out, path.string());
  const auto labelled = std::count_if(labels.begin(), labels.end(), [](int l) { return l >= 0; });
  return jsonResponse(nlohmann::json{
      {"path", path.string()}, {"labelled", labelled}, {"point_count", labels.size()}}
                          .dump());
}

ViewerResponse PlanesLayer::handle(const std::string& endpoint,
                                   const ViewerRequest& request) const {
  if (endpoint == "components") {
    requireMethod(request, "GET");
    std::string out;
    for (const PlaneComponent& c : model_.components) {
      const Vec3& n = c.plane.normal;
      // Offsets are served absolute, as components.json has them: n . p = offset for file
      // coordinates p.
      const double offset = c.plane.offset + n.dot(cloud_->origin());
      for (double v : {double(c.id), double(c.birthLevel), double(c.deathLevel), c.birthScale,
                       c.deathScale, double(c.persistence), double(c.representativeLevel),
                       double(c.pointCount), n.x(), n.y(), n.z(), offset, c.plane.rms, c.area,
                       c.planar ? 1.0 : 0.0, c.noiseLimited ? 1.0 : 0.0})
        appendFloat64(out, v);
    }
    return binaryResponse(std::move(out));
  }
  if (endpoint == "labels") {
    // POST only for components=body; GET answers stay cacheable-looking plain queries.
    const auto listed = request.params.find("components");
    requireMethod(request,
                  listed != request.params.end() && listed->second == "body" ? "POST" : "GET");
    return binaryResponse(sampledArray(sample_, labels(request, nullptr),
                                       [](std::string& out, int v) { appendInt32(out, v); }));
  }
  if (endpoint == "brush") return brush(request);
  if (endpoint == "similar") return similar(request);
  if (endpoint == "export") return exportLabels(request);
  throw RequestError(404, "no endpoint " + request.path);
}

}  // namespace scalespace::viewer
