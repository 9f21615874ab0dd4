// The viewer's rules without a socket: the guard (token, Host), the fixed set of paths, methods,
// strict parameters, and answers equal to the library's queries (what `segment` computes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <set>

#include "ViewerTestModel.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/viewer/RequestGuard.hpp"
#include "scalespace/viewer/ViewerToken.hpp"

namespace scalespace::test {
namespace {

using viewer::ViewerRequest;

TEST(ViewerToken, Is32HexDigitsAndDiffersEachTime) {
  const std::string a = viewer::makeViewerToken(), b = viewer::makeViewerToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_NE(a, b);
  EXPECT_TRUE(viewer::tokensEqual(a, a));
  EXPECT_FALSE(viewer::tokensEqual(a, b));
  EXPECT_FALSE(viewer::tokensEqual(a, a.substr(0, 31)));
  EXPECT_FALSE(viewer::tokensEqual(a, ""));
}

TEST(ViewerGuard, RefusesAMissingOrWrongToken) {
  const auto router = smallRouter();
  ViewerRequest r = request("/api/manifest");
  EXPECT_EQ(router->route(r).status, 200);
  r.params.erase("token");
  EXPECT_EQ(router->route(r).status, 403);
  for (const std::string& bad :
       std::vector<std::string>{"", "0123456789abcdef0123456789abcdeX",
                                "0123456789abcdef0123456789abcde", kToken + "0", "../" + kToken}) {
    r.params["token"] = bad;
    EXPECT_EQ(router->route(r).status, 403) << bad;
  }
  // The page and unknown paths are behind the token too (nothing tells an outsider what exists).
  for (const std::string& path :
       std::vector<std::string>{"/", "/app.js", "/nothing", "/api/planes/labels"}) {
    ViewerRequest p = request(path);
    p.params.erase("token");
    EXPECT_EQ(router->route(p).status, 403) << path;
  }
}

TEST(ViewerGuard, AcceptsTheTokenAsAHeader) {
  const auto router = smallRouter();
  ViewerRequest r = request("/api/manifest");
  r.params.erase("token");
  r.tokenHeader = kToken;
  EXPECT_EQ(router->route(r).status, 200);
  r.tokenHeader = "nope";
  EXPECT_EQ(router->route(r).status, 403);
}

TEST(ViewerGuard, RefusesAHostThatIsNotThisServer) {
  const auto router = smallRouter();
  const std::string port = std::to_string(kPort);
  for (const std::string& host : std::vector<std::string>{
           "", "evil.example:" + port, "127.0.0.1", "localhost", "127.0.0.1:1",
           "127.0.0.1.evil.example:" + port, "evil.example", "[::1]:" + port, "0.0.0.0:" + port,
           "127.0.0.1:" + port + "0", " 127.0.0.1:" + port, "localhost.:" + port}) {
    ViewerRequest r = request("/api/manifest");
    r.host = host;
    EXPECT_EQ(router->route(r).status, 403) << "Host: " << host;
  }
  for (const std::string& host :
       std::vector<std::string>{"127.0.0.1:" + port, "localhost:" + port, "LocalHost:" + port}) {
    ViewerRequest r = request("/api/manifest");
    r.host = host;
    EXPECT_EQ(router->route(r).status, 200) << "Host: " << host;
  }
}

TEST(ViewerRouter, ServesOnlyItsPaths) {
  const auto router = smallRouter();
  for (const std::string path :
       {"/../etc/passwd", "/api/../index.html", "/index.html/..", "/%2e%2e/etc/passwd", "/api",
        "/api/", "/api/cloud", "/api/cloud/", "/api/cloud/positions/x", "/api/none/positions",
        "/app.js/", "/index.htm", "//", "/api/manifest/", "/viewer-page/app.js", "/etc/passwd",
        "/api/planes/../cloud/positions", ""})
    EXPECT_EQ(router->route(request(path)).status, 404) << path;
  EXPECT_EQ(router->route(request("/")).status, 200);
  EXPECT_EQ(router->route(request("/index.html")).status, 200);
  EXPECT_EQ(router->route(request("/app.js")).body, "js");
}

TEST(ViewerRouter, RefusesOtherMethods) {
  const auto router = smallRouter();
  EXPECT_EQ(router->route(request("/", {}, "POST")).status, 405);
  EXPECT_EQ(router->route(request("/api/manifest", {}, "DELETE")).status, 405);
  EXPECT_EQ(router->route(request("/api/cloud/positions", {}, "PUT")).status, 405);
  EXPECT_EQ(router->route(request("/api/planes/brush")).status, 405);
  EXPECT_EQ(
      router->route(request("/api/planes/export", {{"min_persistence", "0"}, {"format", "ply"}}))
          .status,
      405);
}

TEST(ViewerRouter, RefusesWhatTheHttpLayerFoundMalformedAfterTheGuard) {
  const auto router = smallRouter();
  ViewerRequest r = request("/api/manifest");
  r.malformed = "parameter token given twice";
  EXPECT_EQ(router->route(r).status, 400);
  r.params.erase("token");
  EXPECT_EQ(router->route(r).status, 403);  // no token: refused before anything is said
}

TEST(ViewerRouter, PutsTheTokenIntoThePage) {
  const auto router = smallRouter();
  EXPECT_EQ(router->route(request("/")).body, "<p>" + kToken + "</p>");
}

TEST(ViewerRouter, SaysWhenThePageWasNotBuilt) {
  const auto router = smallRouter(".", 100, viewer::readPageAssets("/nonexistent-folder"));
  const auto page = router->route(request("/"));
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("scripts/setup_web.sh"), std::string::npos);
  EXPECT_EQ(router->route(request("/app.js")).status, 404);
  EXPECT_EQ(router->route(request("/api/manifest")).status, 200);  // the data still works
}

TEST(ViewerRouter, RefusesMalformedParameters) {
  const auto router = smallRouter();
  const std::map<std::string, std::string> bad[] = {
      {},
      {{"level", "abc"}},
      {{"level", "-1"}},
      {{"level", "3"}},
      {{"level", "1 "}},
      {{"level", "+1"}},
      {{"level", ""}},
      {{"level", "99999999999999999999999"}},
      {{"min_persistence", "1e3"}},
      {{"min_persistence", "-1"}},
      {{"components", "1,,2"}},
      {{"components", "3"}},
      {{"components", "0,x"}},
      {{"components", ","}},
      {{"level", "1"}, {"min_persistence", "1"}},
  };
  for (const auto& params : bad) {
    const auto r = router->route(request("/api/planes/labels", params));
    EXPECT_EQ(r.status, 400) << (params.empty() ? "(none)" : params.begin()->second) << ": "
                             << r.body;
  }
  EXPECT_EQ(router->route(request("/api/cloud/attribute")).status, 400);
  EXPECT_EQ(router->route(request("/api/cloud/attribute", {{"name", "nope"}})).status, 404);
  EXPECT_EQ(router->route(request("/api/cloud/normals")).status, 404);  // the cloud has none
}

TEST(ViewerRouter, RefusesMalformedBodies) {
  const auto router = smallRouter();
  ViewerRequest r = request("/api/planes/brush", {}, "POST");
  r.body = "12345";  // not whole uint32s
  EXPECT_EQ(router->route(r).status, 400);
  r.body = indexBody({0, 8});  // 8 is out of range
  EXPECT_EQ(router->route(r).status, 400);
  r.body = indexBody({0xffffffffu});
  EXPECT_EQ(router->route(r).status, 400);
  r.body.clear();
  EXPECT_EQ(router->route(r).status, 200);  // an empty brush ranks nothing
  ViewerRequest s = request("/api/planes/similar", {{"component", "0"}}, "POST");
  s.body = "abc";
  EXPECT_EQ(router->route(s).status, 400);
  for (const auto& params : std::vector<std::map<std::string, std::string>>{
           {},
           {{"component", "3"}},
           {{"component", "0"}, {"angle", "nan"}},
           {{"component", "0"}, {"angle", "100"}},
           {{"component", "0"}, {"area_tolerance", "-1"}},
           {{"component", "0"}, {"birth_tolerance", "-1"}},
           {{"component", "0"}, {"domain", "everything"}}}) {
    ViewerRequest q = request("/api/planes/similar", params, "POST");
    EXPECT_EQ(router->route(q).status, 400);
  }
  ViewerRequest e =
      request("/api/planes/export", {{"min_persistence", "0"}, {"format", "exe"}}, "POST");
  EXPECT_EQ(router->route(e).status, 400);
}

TEST(ViewerLayers, LabelsAreTheLibrarysQueries) {
  const auto router = smallRouter();
  const auto shown = displayed(*router);
  const PlaneModel model = smallPlaneModel();
  for (int p = 0; p <= 3; ++p)
    EXPECT_EQ(
        decode<int>(
            router->route(request("/api/planes/labels", {{"min_persistence", std::to_string(p)}}))
                .body),
        inDisplayOrder(labelsByPersistence(model, p), shown))
        << p;
  for (int level = 0; level < 3; ++level)
    EXPECT_EQ(
        decode<int>(
            router->route(request("/api/planes/labels", {{"level", std::to_string(level)}})).body),
        inDisplayOrder(labelsAtScale(model, model.scales[std::size_t(level)]), shown))
        << level;
  EXPECT_EQ(decode<int>(router->route(request("/api/planes/labels", {{"components", "2,1"}})).body),
            inDisplayOrder(labelsOfComponents(model, {2, 1}), shown));
  EXPECT_EQ(decode<int>(router->route(request("/api/planes/labels", {{"components", ""}})).body),
            std::vector<int>(8, -1));
}

TEST(ViewerLayers, ALongSelectionTravelsInTheBody) {
  const auto router = smallRouter();
  ViewerRequest r = request("/api/planes/labels", {{"components", "body"}}, "POST");
  r.body = indexBody({2, 1});
  EXPECT_EQ(decode<int>(router->route(r).body),
            inDisplayOrder(labelsOfComponents(smallPlaneModel(), {2, 1}), displayed(*router)));
  r.body = indexBody({3});  // no component 3
  EXPECT_EQ(router->route(r).status, 400);
  r.body = "abc";
  EXPECT_EQ(router->route(r).status, 400);
  EXPECT_EQ(router->route(request("/api/planes/labels", {{"components", "body"}})).status, 405);
  EXPECT_EQ(router->route(request("/api/planes/labels", {{"components", "1"}}, "POST")).status,
            405);
}

TEST(ViewerLayers, BrushAndSimilarAreTheLibrarysQueries) {
  const auto router = smallRouter();
  const PlaneModel model = smallPlaneModel();
  ViewerRequest b = request("/api/planes/brush", {}, "POST");
  b.body = indexBody({4, 5, 6});
  const auto brushed = nlohmann::json::parse(router->route(b).body).at("matches");
  const auto expected = rankByBrush(model, {4, 5, 6});
  ASSERT_EQ(brushed.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(brushed[k].at("component").get<int>(), expected[k].component);
    EXPECT_DOUBLE_EQ(brushed[k].at("score").get<double>(), expected[k].score);
  }
  ViewerRequest s = request("/api/planes/similar", {{"component", "0"}, {"domain", "all"}}, "POST");
  EXPECT_EQ(nlohmann::json::parse(router->route(s).body).at("components").get<std::vector<int>>(),
            findSimilar(model, 0, {0, 1, 2, 3, 4, 5, 6, 7}));
  ViewerRequest w = request("/api/planes/similar", {{"component", "1"}, {"angle", "10"}}, "POST");
  w.body = indexBody({4, 6});
  SimilarityOptions o;
  o.maxAngleDegrees = 10;
  EXPECT_EQ(nlohmann::json::parse(router->route(w).body).at("components").get<std::vector<int>>(),
            findSimilar(model, 1, {4, 6}, o));
}

TEST(ViewerLayers, ComponentsTableHoldsEveryField) {
  const auto router = smallRouter();
  const auto fields = viewer::PlanesLayer::componentFields();
  const auto values = decode<double>(router->route(request("/api/planes/components")).body);
  ASSERT_EQ(values.size(), 3 * fields.size());
  const auto at = [&](int c, const std::string& f) {
    return values[std::size_t(c) * fields.size() +
                  std::size_t(std::find(fields.begin(), fields.end(), f) - fields.begin())];
  };
  EXPECT_EQ(at(0, "persistence"), 2);
  EXPECT_EQ(at(1, "death_level"), 1);
  EXPECT_EQ(at(2, "area"), 3.0);
  // Offsets absolute: the cloud's origin is added back (n . p = offset in file coordinates).
  EXPECT_DOUBLE_EQ(at(1, "offset"), 1.0 + smallCloud()->origin().z());
}

TEST(ViewerLayers, CloudArraysAreFloat32AtTheDisplaySample) {
  const auto all = smallRouter();
  const auto cloud = smallCloud();
  const auto shown = displayed(*all);
  std::vector<std::uint32_t> sorted = shown;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));  // within the budget
  const auto positions = decode<float>(all->route(request("/api/cloud/positions")).body);
  ASSERT_EQ(positions.size(), 24u);
  for (std::size_t k = 0; k < 8; ++k)
    for (int d = 0; d < 3; ++d)
      EXPECT_EQ(positions[3 * k + std::size_t(d)], float(cloud->positions()[shown[k]][d]));
  const auto decimated = smallRouter(".", 3);  // 8 points, budget 3: the first 3 coarse to fine
  const auto manifest = nlohmann::json::parse(decimated->route(request("/api/manifest")).body);
  EXPECT_EQ(manifest.at("cloud").at("display_order"), "coarse_to_fine");
  EXPECT_EQ(manifest.at("cloud").at("display_count"), 3);
  const auto few = displayed(*decimated);
  EXPECT_EQ(few, std::vector<std::uint32_t>(shown.begin(), shown.begin() + 3));
  std::vector<float> intensity;
  for (std::uint32_t i : few) intensity.push_back(float(10 * i));
  EXPECT_EQ(decode<float>(
                decimated->route(request("/api/cloud/attribute", {{"name", "intensity"}})).body),
            intensity);
  EXPECT_EQ(
      decode<int>(decimated->route(request("/api/planes/labels", {{"min_persistence", "0"}})).body),
      inDisplayOrder(labelsByPersistence(smallPlaneModel(), 0), few));
}

TEST(ViewerLayers, ExportWritesNewFilesWithSegmentsColumns) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("scalespace_viewer_export_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto router = smallRouter(dir.string());
  std::set<std::string> paths;
  for (const std::string& format : std::vector<std::string>{"ply", "ply", "csv"}) {
    const auto r =
        router->route(request("/api/planes/export", {{"level", "1"}, {"format", format}}, "POST"));
    ASSERT_EQ(r.status, 200) << r.body;
    const std::string path = nlohmann::json::parse(r.body).at("path");
    EXPECT_TRUE(paths.insert(path).second) << "an export replaced " << path;
    const PointCloud written = readCloud(path);
    const AttributeColumn* id = written.findAttribute("plane_id");
    ASSERT_NE(id, nullptr);
    const auto expected = labelsAtScale(smallPlaneModel(), 0.2);
    for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(id->values[i], expected[i]);
    EXPECT_NE(written.findAttribute("red"), nullptr);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace scalespace::test
