// libFuzzer target for the saved plane result (readPlaneModel: components.json + membership.bin,
// PlaneExport.hpp) and the queries `scalespace segment` runs on it (PlaneQueries.hpp). At start-up
// the planes of a small box (600 points, 6 scales) are detected and saved; each input replaces
// one of the two files (first byte: which one; the rest: its new content). The read must succeed
// or throw scalespace::Error; after a successful read every query must too, on any result: no
// crash, hang or huge allocation. `SCALESPACE_FUZZ_SEEDS=fuzz/corpus/planes fuzz_planes` writes
// the seeds and exits.
#include <algorithm>
#include <filesystem>
#include <vector>

#include "FuzzFiles.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/planes/StackPlanes.hpp"

namespace {

using namespace scalespace;

struct Result {
  PointCloud cloud;  // what the planes were detected on (for the coverage extension)
  KnnGraph knn;
  std::vector<fuzz::TemplateFile> files;  // components.json, membership.bin
};

Result makeResult() {
  Result r;
  SceneOptions scene;
  scene.pointCount = 600;
  scene.boxSize = Vec3(4, 2, 1);
  r.cloud = generateScene(SceneKind::Box, scene);
  r.knn = buildKnnGraph(r.cloud.positions());
  ScaleSpaceOptions stack;
  stack.series.count = 6;
  stack.threads = 1;
  PlaneDetectionOptions options;
  options.outlines = false;
  const PlaneModel model = makePlaneModel(detectPlanesInCloud(r.cloud, stack, options).detection);
  const std::filesystem::path dir = fuzz::processTempDir("fuzz_planes") / "box.planes";
  writePlaneModel(model, r.cloud.origin(), "box.ply", dir.string());
  for (const char* name : {"components.json", "membership.bin"})
    r.files.push_back({dir / name, fuzz::readBytes(dir / name)});
  return r;
}

const Result& result() {
  static const Result r = makeResult();
  return r;
}

// Runs a query; scalespace::Error (e.g. OptionError for a model without scales) is an answer.
template <class Query>
void ask(Query&& query) {
  try {
    query();
  } catch (const Error&) {
  }
}

// What `segment` does with a component it picked (labelComponent in cli/PlanesCommands.cpp):
// label the points that the component holds at its representative level.
void labelComponent(const PlaneModel& model, int c, std::vector<int>& labels) {
  const int level = model.components[std::size_t(c)].representativeLevel;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] < 0 && model.membership.at(level, i) == c) labels[i] = c;
}

// Every query of `segment` on the model: --min-persistence, --scale, --brush, --similar/--within
// and --extend-coverage.
void queryEverything(PlaneModel& model) {
  const Result& r = result();
  for (auto& c : model.components) c.plane.offset -= c.plane.normal.dot(r.cloud.origin());
  const std::size_t n = model.membership.pointCount;
  for (const int p : {-1, 0, 1, 3})
    ask([&] {
      if (labelsByPersistence(model, p).size() != n) std::abort();
    });
  std::vector<double> scales = {1e-300, 0.5, 1.0, 1e300};
  if (!model.scales.empty()) {
    scales.push_back(model.scales.front());
    scales.push_back(model.scales.back());
  }
  for (const double t : scales)
    ask([&] {
      const int level = nearestLevel(model, t);
      if (level < 0 || level >= model.scaleCount()) std::abort();
      if (labelsAtScale(model, t).size() != n || labelsAtScale(model, t, 2).size() != n)
        std::abort();
    });
  std::vector<Index> points;  // a brush / search domain: up to 64 points spread over the cloud
  for (std::size_t k = 0; k < std::min<std::size_t>(n, 64); ++k)
    points.push_back(Index(k * n / 64));
  if (n > 0) points.push_back(Index(n - 1));
  std::vector<int> labels(n, -1);
  ask([&] {
    const auto matches = rankByBrush(model, points);
    if (!matches.empty()) labelComponent(model, matches.front().component, labels);
  });
  ask([&] { rankByBrush(model, {Index(n)}); });  // out of range: OptionError
  if (!model.components.empty())
    ask([&] {
      for (const int c : findSimilar(model, 0, points)) labelComponent(model, c, labels);
    });
  ask([&] { findSimilar(model, int(model.components.size()), points); });  // no such component
  if (n == r.cloud.size())
    ask([&] {
      const std::vector<int> seeds = labelsByPersistence(model, 0);
      if (extendCoverage(model, seeds, r.cloud.positions(), r.cloud.normals(), r.knn).size() != n)
        std::abort();
    });
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(result().files);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const fuzz::ReplacedFile replaced(result().files, data, size);
  PlaneModel model;
  try {
    model = readPlaneModel(replaced.file().path.parent_path().string());
  } catch (const Error&) {
    return 0;
  }
  queryEverything(model);
  return 0;
}
