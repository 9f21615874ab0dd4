// The stack layer against the reader: a small stack written with the library's writer (both
// encodings), every served byte equal to ScaleStackReader's values; bad parameters give 400 and a
// stack damaged after opening an error answer, never a crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "ViewerTestModel.hpp"
#include "scales/ScalesTestClouds.hpp"
#include "scalespace/scales/ScaleStackIO.hpp"
#include "scalespace/viewer/StackLayer.hpp"

namespace fs = std::filesystem;

namespace scalespace::test {
namespace {

using viewer::ViewerRequest;

// 600 points on a sphere, 3 scales, written once per encoding.
struct StackViewer : ::testing::TestWithParam<StackEncoding> {
  fs::path dir;
  std::string path;
  std::shared_ptr<const ScaleStackReader> reader;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("viewer_stack_test_" + std::to_string(::getpid()) + "_" + stackEncodingName(GetParam()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const PointCloud cloud = sphereCloud(600, 2.0);
    ScaleSpaceOptions options;
    options.series.count = 3;
    options.threads = 1;
    path = (dir / "sphere.stack").string();
    StackWriteOptions write;
    write.encoding = GetParam();
    writeScaleStack(path, cloud, options, computeScaleStackInMemory(cloud, options), write);
    reader = std::make_shared<const ScaleStackReader>(path);
  }
  void TearDown() override {
    reader.reset();
    fs::remove_all(dir);
  }
  // A router over the stack's positions and the stack, drawing at most `budget` points.
  std::unique_ptr<viewer::ViewerRouter> router(std::size_t budget = 1000) const {
    auto cloud = std::make_shared<PointCloud>();
    cloud->setAbsolutePositions(reader->inputPositions());
    const auto sample = viewer::displaySampleFor(cloud->positions(), budget);
    std::vector<std::unique_ptr<viewer::ViewerLayer>> layers;
    layers.push_back(std::make_unique<viewer::CloudLayer>(cloud, sample));
    layers.push_back(std::make_unique<viewer::StackLayer>(reader, sample));
    auto r =
        std::make_unique<viewer::ViewerRouter>(kToken, viewer::PageAssets{"p", "js", ""},
                                               std::move(layers), nlohmann::json{{"path", path}});
    r->setPort(kPort);
    return r;
  }
};

float quantity(const ScaleLayer& L, const std::string& name, std::size_t i) {
  if (name == "curv_mean") return L.meanCurvature[i];
  if (name == "curv_max") return L.kMax[i];
  if (name == "curv_min") return L.kMin[i];
  if (name == "gls_tau") return L.tau[i];
  if (name == "gls_kappa") return L.kappa[i];
  if (name == "gls_fitness") return L.fitness[i];
  if (name == "anisotropy") return L.anisotropy[i];
  if (name == "geometric_variation") return L.geometricVariation[i];
  if (name == "neighbors") return float(L.neighbors[i]);
  if (name == "fit_valid") return float(L.valid[i]);
  ADD_FAILURE() << "unknown quantity " << name;
  return 0;
}

TEST_P(StackViewer, ManifestListsScalesQuantitiesAndPoints) {
  const auto r = router();
  const auto manifest = nlohmann::json::parse(r->route(request("/api/manifest")).body);
  const auto& stack = manifest.at("stack");
  EXPECT_EQ(stack.at("point_count"), 600);
  EXPECT_EQ(stack.at("scale_count"), 3);
  EXPECT_EQ(stack.at("scales").get<std::vector<double>>(), reader->info().scales);
  EXPECT_EQ(stack.at("encoding"), stackEncodingName(GetParam()));
  std::vector<std::string> names;
  for (const auto& q : stack.at("quantities")) names.push_back(q.at("name"));
  EXPECT_EQ(names, viewer::StackLayer::quantityNames(GetParam()));
  // The compact encoding does not store the fitness: it is not offered.
  const bool fitness = std::find(names.begin(), names.end(), "gls_fitness") != names.end();
  EXPECT_EQ(fitness, GetParam() == StackEncoding::Float32);
  EXPECT_EQ(names.front(), "curv_mean");
  // Positions: the stack's input positions, relative to the cloud's origin.
  EXPECT_EQ(manifest.at("cloud").at("point_count"), 600);
}

TEST_P(StackViewer, ValuesAreTheReadersAtEveryScaleForEveryQuantity) {
  for (std::size_t budget : {std::size_t(1000), std::size_t(250)}) {  // all 600, then 250
    const auto r = router(budget);
    const auto shown = displayed(*r);
    ASSERT_EQ(shown.size(), std::min<std::size_t>(budget, 600));
    for (std::size_t j = 0; j < 3; ++j) {
      const ScaleLayer L = reader->readScale(j);
      for (const std::string& name : viewer::StackLayer::quantityNames(GetParam())) {
        const auto answer = r->route(
            request("/api/stack/values", {{"quantity", name}, {"scale", std::to_string(j)}}));
        ASSERT_EQ(answer.status, 200) << answer.body;
        EXPECT_EQ(answer.contentType, "application/octet-stream");
        const auto values = decode<float>(answer.body);
        ASSERT_EQ(values.size(), shown.size()) << name;
        std::size_t differ = 0;
        for (std::size_t k = 0; k < values.size(); ++k) {
          const float expected = quantity(L, name, shown[k]);
          differ += std::memcmp(&values[k], &expected, 4) != 0;
        }
        EXPECT_EQ(differ, 0u) << name << " at scale " << j;
        if (name == "curv_max" || name == "fit_valid") {  // not trivial: the fits are valid
          EXPECT_GT(*std::max_element(values.begin(), values.end()), 0.1f) << name;
        }
      }
    }
  }
}

TEST_P(StackViewer, SeriesIsTheReadersPointSeries) {
  const auto r = router();
  for (std::size_t i : {std::size_t(0), std::size_t(17), std::size_t(599)}) {
    const ScaleLayer S = reader->readPointSeries(i);
    // Default: every quantity, in the manifest's order.
    const auto names = viewer::StackLayer::quantityNames(GetParam());
    const auto all =
        decode<float>(r->route(request("/api/stack/series", {{"point", std::to_string(i)}})).body);
    ASSERT_EQ(all.size(), names.size() * 3);
    for (std::size_t q = 0; q < names.size(); ++q)
      for (std::size_t j = 0; j < 3; ++j) EXPECT_EQ(all[3 * q + j], quantity(S, names[q], j));
    // Chosen quantities, in the order asked.
    const auto two =
        decode<float>(r->route(request("/api/stack/series", {{"point", std::to_string(i)},
                                                             {"quantities", "curv_max,neighbors"}}))
                          .body);
    ASSERT_EQ(two.size(), 6u);
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(two[j], S.kMax[j]);
      EXPECT_EQ(two[3 + j], float(S.neighbors[j]));
    }
  }
}

TEST_P(StackViewer, BadParametersAre400) {
  const auto r = router();
  const std::vector<std::map<std::string, std::string>> badValues = {
      {},
      {{"quantity", "curv_max"}},
      {{"scale", "0"}},
      {{"quantity", "curv_max"}, {"scale", "3"}},
      {{"quantity", "curv_max"}, {"scale", "-1"}},
      {{"quantity", "curv_max"}, {"scale", "1.5"}},
      {{"quantity", "curv_max"}, {"scale", "99999999999999999999999"}},
      {{"quantity", "curv_max"}, {"scale", ""}},
      {{"quantity", "curv_max"}, {"scale", " 1"}},
      {{"quantity", "nothing"}, {"scale", "0"}},
      {{"quantity", ""}, {"scale", "0"}},
      {{"quantity", "projection"}, {"scale", "0"}},
      {{"quantity", "../manifest.json"}, {"scale", "0"}},
  };
  for (const auto& params : badValues) {
    const auto answer = r->route(request("/api/stack/values", params));
    EXPECT_EQ(answer.status, 400) << answer.body;
  }
  const std::vector<std::map<std::string, std::string>> badSeries = {
      {},
      {{"point", "600"}},
      {{"point", "-1"}},
      {{"point", "x"}},
      {{"point", "1"}, {"quantities", ""}},
      {{"point", "1"}, {"quantities", "curv_max,"}},
      {{"point", "1"}, {"quantities", "curv_max,,neighbors"}},
      {{"point", "1"}, {"quantities", "curv_max,nope"}},
      {{"point", "1"}, {"quantities", std::string(2000, ',')}},
  };
  for (const auto& params : badSeries) {
    const auto answer = r->route(request("/api/stack/series", params));
    EXPECT_EQ(answer.status, 400) << answer.body;
  }
  // The message names the parameter.
  EXPECT_NE(r->route(request("/api/stack/values", {{"quantity", "x"}, {"scale", "0"}}))
                .body.find("parameter quantity"),
            std::string::npos);
  EXPECT_NE(r->route(request("/api/stack/series", {{"point", "600"}})).body.find("parameter point"),
            std::string::npos);
  // Unknown endpoint, wrong method.
  EXPECT_EQ(r->route(request("/api/stack/nothing")).status, 404);
  EXPECT_EQ(
      r->route(request("/api/stack/values", {{"quantity", "curv_max"}, {"scale", "0"}}, "POST"))
          .status,
      405);
}

TEST_P(StackViewer, AStackDamagedAfterOpeningGivesAnErrorAnswerNotACrash) {
  const auto r = router();
  // Truncate every data file: the reader's reads come up short.
  for (const auto& entry : fs::directory_iterator(path))
    if (entry.path().extension() == ".npy" && entry.path().filename() != "input_positions.npy")
      fs::resize_file(entry.path(), 100);
  const auto values =
      r->route(request("/api/stack/values", {{"quantity", "curv_max"}, {"scale", "2"}}));
  EXPECT_GE(values.status, 500) << values.body;
  EXPECT_NE(values.body.find(".npy"), std::string::npos) << values.body;  // names the file
  const auto series = r->route(request("/api/stack/series", {{"point", "599"}}));
  EXPECT_GE(series.status, 500) << series.body;
  // A damaged stack is refused when opened (the viewer then does not start).
  EXPECT_THROW(ScaleStackReader{path}, FileError);
}

INSTANTIATE_TEST_SUITE_P(Encodings, StackViewer,
                         ::testing::Values(StackEncoding::Compact, StackEncoding::Float32),
                         [](const auto& info) {
                           return std::string(stackEncodingName(info.param));
                         });

}  // namespace
}  // namespace scalespace::test
