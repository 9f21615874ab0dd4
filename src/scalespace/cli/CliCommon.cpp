#include "scalespace/cli/CliCommon.hpp"

#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>

#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace scalespace::cli {

void addInputOptions(CLI::App& command, InputOptions& input) {
  command
      .add_option("input", input.path,
                  "input point cloud (.ply .xyz .txt .csv .off .obj .las .pcd)")
      ->required()
      ->check(CLI::ExistingFile);
  command.add_flag("--drop-invalid", input.dropInvalid,
                   "skip points with NaN/Inf coordinates instead of stopping with an error");
}

PointCloud loadCloud(const InputOptions& input, bool quiet) {
  ReadOptions options;
  options.dropNonFinite = input.dropInvalid;
  ReadReport report;
  PointCloud cloud = readCloud(input.path, options, &report);
  if (cloud.empty())
    throw FileError(input.path, "", "the file holds no points", "nothing to analyse");
  if (!quiet && report.droppedNonFinite > 0)
    std::fprintf(stderr, "%s: skipped %zu points with NaN/Inf coordinates\n", input.path.c_str(),
                 report.droppedNonFinite);
  return cloud;
}

void ensureNormals(PointCloud& cloud, bool quiet) {
  if (cloud.hasNormals()) return;
  if (!quiet)
    std::fprintf(stderr,
                 "input has no normals: estimating (PCA, 10 neighbours) and orienting (MST)\n");
  auto index = makeSpatialIndex(cloud.positions());
  NormalEstimationResult est =
      estimateNormals(cloud.positions(), *index, {}, makeProgressBar(quiet));
  orientNormals(cloud.positions(), est.normals, *index, {}, est.valid, makeProgressBar(quiet));
  cloud.setNormals(std::move(est.normals));
}

void checkOutputPath(const std::string& input, const std::string& output) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(output, ec) && fs::equivalent(input, output, ec))
    throw OptionError("output " + output + " is the input file: choose another output name " +
                      "(inputs are never overwritten)");
}

std::string summaryPathFor(const std::string& output) {
  return std::filesystem::path(output).replace_extension(".json").string();
}

void writeJson(const std::string& path, const nlohmann::json& summary) {
  writeFileAtomically(path, [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
}

struct ThreadScope::Impl {
  std::unique_ptr<tbb::global_control> control;
};

ThreadScope::ThreadScope(int threads) : impl_(std::make_unique<Impl>()) {
  if (threads < 0) throw OptionError("--threads must be >= 0 (0 = all cores)");
  if (threads > 0)
    impl_->control = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, std::size_t(threads));
}

ThreadScope::~ThreadScope() = default;

}  // namespace scalespace::cli
