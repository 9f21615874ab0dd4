#pragma once
// A small hand-made plane result for the viewer's tests: 8 points, 3 levels, 3 components with
// persistences 2, 1 and 0, and a router over it (token kToken, port kPort).
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "scalespace/viewer/CloudLayer.hpp"
#include "scalespace/viewer/PlanesLayer.hpp"
#include "scalespace/viewer/ViewerRouter.hpp"

namespace scalespace::test {

inline const std::string kToken = "0123456789abcdef0123456789abcdef";
constexpr int kPort = 43210;

inline PlaneModel smallPlaneModel() {
  PlaneModel model;
  model.scales = {0.1, 0.2, 0.4};
  // Per level, per point: the component holding it (-1 none).
  model.membership.pointCount = 8;
  model.membership.levelCount = 3;
  model.membership.ids = {0, 0, 0, 1, 1, -1, 2,  -1,   // level 0
                          0, 0, 0, 0, 1, 1,  -1, -1,   // level 1
                          0, 0, 0, 0, 0, -1, -1, -1};  // level 2
  const int birth[] = {0, 0, 0}, death[] = {2, 1, 0}, representative[] = {2, 1, 0};
  for (int c = 0; c < 3; ++c) {
    PlaneComponent p;
    p.id = c;
    p.birthLevel = birth[c];
    p.deathLevel = death[c];
    p.birthScale = model.scales[std::size_t(birth[c])];
    p.deathScale = model.scales[std::size_t(death[c])];
    p.persistence = death[c] - birth[c];
    p.representativeLevel = representative[c];
    p.plane.normal = Vec3(0, 0, 1);
    p.plane.offset = double(c);
    p.area = 1.0 + c;
    model.components.push_back(p);
  }
  return model;
}

inline std::shared_ptr<PointCloud> smallCloud() {
  auto cloud = std::make_shared<PointCloud>();
  std::vector<Vec3> positions;
  for (int i = 0; i < 8; ++i) positions.emplace_back(i, 0.5 * i, 0.25 * i);
  cloud->setAbsolutePositions(positions);
  auto& a = cloud->addAttribute("intensity", ScalarType::Float32);
  for (int i = 0; i < 8; ++i) a.values[std::size_t(i)] = 10.0 * i;
  return cloud;
}

inline std::unique_ptr<viewer::ViewerRouter> smallRouter(
    const std::string& exportDir = ".", std::size_t budget = 100,
    viewer::PageAssets page = {"<p>%SCALESPACE_TOKEN%</p>", "js", ""}) {
  auto cloud = smallCloud();
  const auto sample = viewer::displaySampleFor(cloud->positions(), budget);
  std::vector<std::unique_ptr<viewer::ViewerLayer>> layers;
  layers.push_back(std::make_unique<viewer::CloudLayer>(cloud, sample));
  viewer::PlanesLayerOptions options;
  options.exportDirectory = exportDir;
  layers.push_back(
      std::make_unique<viewer::PlanesLayer>(smallPlaneModel(), cloud, sample, options));
  auto router = std::make_unique<viewer::ViewerRouter>(kToken, std::move(page), std::move(layers),
                                                       nlohmann::json{{"path", "test"}});
  router->setPort(kPort);
  return router;
}

inline viewer::ViewerRequest request(const std::string& path,
                                     std::map<std::string, std::string> params = {},
                                     const std::string& method = "GET") {
  viewer::ViewerRequest r;
  r.method = method;
  r.path = path;
  r.host = "127.0.0.1:" + std::to_string(kPort);
  params.emplace("token", kToken);
  r.params = std::move(params);
  return r;
}

template <typename T>
std::vector<T> decode(const std::string& bytes) {
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));  // the tests run little-endian
  return out;
}

/// The cloud's indices of the points the router draws, in the order of every per-point array.
inline std::vector<std::uint32_t> displayed(const viewer::ViewerRouter& router) {
  return decode<std::uint32_t>(router.route(request("/api/cloud/indices")).body);
}

/// values[indices[k]] for every k: a whole-cloud array in the display order.
template <typename T>
std::vector<T> inDisplayOrder(const std::vector<T>& values,
                              const std::vector<std::uint32_t>& indices) {
  std::vector<T> out;
  for (std::uint32_t i : indices) out.push_back(values.at(i));
  return out;
}

inline std::string indexBody(const std::vector<std::uint32_t>& indices) {
  return std::string(reinterpret_cast<const char*>(indices.data()), indices.size() * 4);
}

}  // namespace scalespace::test
