// The lines layer: a polyline file written and read back with io/Polylines, served as segments
// (one per edge of the file), positions relative to the cloud's origin, per-vertex attributes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "ViewerTestModel.hpp"
#include "scalespace/viewer/LinesLayer.hpp"

namespace fs = std::filesystem;

namespace scalespace::test {
namespace {

// Two lines: an open one of 3 vertices (2 edges), a closed one of 4 (4 edges), with a `scale`
// column; positions far from 0 (as a georeferenced file).
PolylineSet twoLines() {
  PolylineSet lines;
  std::vector<Vec3> p;
  for (int k = 0; k < 7; ++k) p.emplace_back(1000.0 + k, 2000.0 + 0.5 * k, 10.0 - k);
  lines.vertices.setAbsolutePositions(p);
  auto& scale = lines.vertices.addAttribute("scale", ScalarType::Float32);
  for (int k = 0; k < 7; ++k) scale.values[std::size_t(k)] = 0.25 * k;
  lines.offsets = {0, 3, 7};
  lines.closed = {0, 1};
  return lines;
}

std::unique_ptr<viewer::ViewerRouter> linesRouter(PolylineSet lines, const Vec3& origin) {
  std::vector<std::unique_ptr<viewer::ViewerLayer>> layers;
  layers.push_back(std::make_unique<viewer::LinesLayer>(std::move(lines), origin));
  auto r = std::make_unique<viewer::ViewerRouter>(kToken, viewer::PageAssets{"p", "js", ""},
                                                  std::move(layers), nlohmann::json{});
  r->setPort(kPort);
  return r;
}

TEST(LinesLayer, ServesOneSegmentPerEdgeOfTheFile) {
  const fs::path file =
      fs::temp_directory_path() / ("viewer_lines_" + std::to_string(::getpid()) + ".ply");
  writePolylines(twoLines(), file.string());
  PolylineSet read = readPolylines(file.string());
  fs::remove(file);
  const Vec3 origin(1000, 2000, 0);
  const auto r = linesRouter(read, origin);
  const auto manifest = nlohmann::json::parse(r->route(request("/api/manifest")).body).at("lines");
  EXPECT_EQ(manifest.at("vertex_count"), 7);
  EXPECT_EQ(manifest.at("segment_count"), 6);  // 2 + 4 edges, as the file has
  EXPECT_EQ(manifest.at("line_count"), 2);
  EXPECT_EQ(manifest.at("closed_count"), 1);
  EXPECT_EQ(manifest.at("attributes").at(0).at("name"), "line_index");
  EXPECT_EQ(manifest.at("attributes").at(1).at("name"), "scale");
  EXPECT_EQ(manifest.at("attributes").at(1).at("max"), 1.5);

  const auto segments = decode<std::uint32_t>(r->route(request("/api/lines/segments")).body);
  EXPECT_EQ(segments, (std::vector<std::uint32_t>{0, 1, 1, 2, 3, 4, 4, 5, 5, 6, 6, 3}));
  const auto positions = decode<float>(r->route(request("/api/lines/positions")).body);
  ASSERT_EQ(positions.size(), 21u);
  for (std::size_t k = 0; k < 7; ++k) {
    const Vec3 expected = read.vertices.absolutePosition(k) - origin;
    for (int d = 0; d < 3; ++d)
      EXPECT_FLOAT_EQ(positions[3 * k + std::size_t(d)], float(expected[d]));
  }
  EXPECT_EQ(decode<float>(r->route(request("/api/lines/attribute", {{"name", "scale"}})).body),
            (std::vector<float>{0, 0.25f, 0.5f, 0.75f, 1, 1.25f, 1.5f}));
  EXPECT_EQ(decode<float>(r->route(request("/api/lines/attribute", {{"name", "line_index"}})).body),
            (std::vector<float>{0, 0, 0, 1, 1, 1, 1}));
}

TEST(LinesLayer, RefusesBadRequests) {
  const auto r = linesRouter(twoLines(), Vec3::Zero());
  EXPECT_EQ(r->route(request("/api/lines/attribute")).status, 400);
  EXPECT_EQ(r->route(request("/api/lines/attribute", {{"name", "nothing"}})).status, 404);
  EXPECT_EQ(r->route(request("/api/lines/attribute", {{"name", "../x"}})).status, 404);
  EXPECT_EQ(r->route(request("/api/lines/segments", {}, "POST")).status, 405);
  EXPECT_EQ(r->route(request("/api/lines/other")).status, 404);
}

TEST(LinesLayer, AMalformedSetIsAnOptionErrorNamingTheField) {
  PolylineSet bad = twoLines();
  bad.offsets = {0, 1, 7};  // a line of one vertex
  try {
    viewer::LinesLayer layer(bad, Vec3::Zero());
    FAIL() << "accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("PolylineSet::offsets"), std::string::npos) << e.what();
  }
}

TEST(LinesLayer, NoLinesIsEmpty) {
  PolylineSet none;
  const auto r = linesRouter(none, Vec3::Zero());
  const auto manifest = nlohmann::json::parse(r->route(request("/api/manifest")).body).at("lines");
  EXPECT_EQ(manifest.at("segment_count"), 0);
  EXPECT_TRUE(r->route(request("/api/lines/segments")).body.empty());
}

}  // namespace
}  // namespace scalespace::test
