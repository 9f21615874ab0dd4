#include "scalespace/cli/ViewCommands.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/CylinderCommands.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"
#include "scalespace/viewer/CloudLayer.hpp"
#include "scalespace/viewer/LinesLayer.hpp"
#include "scalespace/viewer/PageAssets.hpp"
#include "scalespace/viewer/PlanesLayer.hpp"
#include "scalespace/viewer/StackLayer.hpp"
#include "scalespace/viewer/ViewerServer.hpp"
#include "scalespace/viewer/ViewerToken.hpp"

extern char** environ;

namespace scalespace::cli {

namespace fs = std::filesystem;

namespace {

struct ViewArgs {
  std::string path, input, lines, exportDir = ".";
  int port = 0;
  std::size_t pointBudget = 4000000;
  bool noBrowser = false, quiet = false;
};

// The running program's path (/proc/self/exe), where the page is looked for beside it.
std::string programPath() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

// xdg-open when there is one; a viewer without a browser still serves (the URL is printed).
void openBrowser(const std::string& url, bool quiet) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  std::string program = "xdg-open";
  char* argv[] = {program.data(), const_cast<char*>(url.c_str()), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "xdg-open", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    if (!quiet)
      std::fprintf(stderr, "no browser opened (xdg-open not found): open the URL above\n");
    return;
  }
  std::thread([pid] { waitpid(pid, nullptr, 0); }).detach();  // no zombie left behind
}

// True when `path` is a PLY file whose header declares an edge element (a polyline file, as
// `scalespace lines` writes): only the header's text is looked at, readPolylines parses the file.
bool isPolylinePly(const std::string& path) {
  const std::string extension = fs::path(path).extension().string();
  if (extension != ".ply" && extension != ".PLY") return false;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int k = 0; k < 1000 && std::getline(in, line); ++k) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") return false;
    if (line.rfind("element edge ", 0) == 0) return true;
  }
  return false;
}

// A scale stack: its input positions (or the --input cloud, checked to be the stack's input, with
// its own attributes) as the cloud, the stack's quantities over them.
void loadStack(const ViewArgs& args, nlohmann::json& source,
               std::vector<std::unique_ptr<viewer::ViewerLayer>>& layers) {
  auto reader = std::make_shared<const ScaleStackReader>(args.path);
  std::shared_ptr<PointCloud> cloud;
  if (!args.input.empty()) {
    InputOptions input;
    input.path = args.input;
    cloud = std::make_shared<PointCloud>(loadCloud(input, args.quiet));
    reader->checkInput(*cloud, args.input);
  } else {
    cloud = std::make_shared<PointCloud>();
    cloud->setAbsolutePositions(reader->inputPositions());
  }
  const viewer::DisplaySample sample =
      viewer::displaySampleFor(cloud->positions(), args.pointBudget);
  source = {{"path", args.path}, {"kind", "stack"}};
  if (!args.input.empty()) source["input"] = args.input;
  layers.push_back(std::make_unique<viewer::CloudLayer>(cloud, sample));
  layers.push_back(std::make_unique<viewer::StackLayer>(reader, sample));
}

std::vector<std::unique_ptr<viewer::ViewerLayer>> loadLayersWithoutLines(const ViewArgs& args,
                                                                         nlohmann::json& source) {
  std::vector<std::unique_ptr<viewer::ViewerLayer>> layers;
  std::error_code ec;
  if (fs::is_directory(args.path, ec)) {
    if (isScaleStack(args.path)) {
      loadStack(args, source, layers);
      return layers;
    }
    if (isCylinderResult(args.path)) {
      if (!args.input.empty())
        throw OptionError(
            "--input goes with a `planes` result or a scale stack, not with a "
            "`cylinders` result (its cloud.ply is the input with its labels)");
      InputOptions input;
      input.path = (fs::path(args.path) / "cloud.ply").string();
      auto cloud = std::make_shared<PointCloud>(loadCloud(input, args.quiet));
      source = {{"path", args.path}, {"kind", "cylinders"}};
      layers.push_back(std::make_unique<viewer::CloudLayer>(
          cloud, viewer::displaySampleFor(cloud->positions(), args.pointBudget)));
      return layers;
    }
    if (!isPlaneResult(args.path))
      throw FileError(args.path, "",
                      "is a folder but not a `scalespace planes` or `cylinders` result",
                      "pass a cloud file or the output folder of `scalespace planes` or "
                      "`scalespace cylinders`");
    std::string recorded;
    PlaneModel model = readPlaneModel(args.path, &recorded);
    auto cloud = std::make_shared<PointCloud>(loadResultInput(
        recorded, args.input, args.path, "planes", model.membership.pointCount, "", args.quiet));
    // As `segment`: the saved offsets are absolute, the queries work relative to the origin.
    for (auto& c : model.components) c.plane.offset -= c.plane.normal.dot(cloud->origin());
    const viewer::DisplaySample sample =
        viewer::displaySampleFor(cloud->positions(), args.pointBudget);
    viewer::PlanesLayerOptions options;
    options.exportDirectory = fs::absolute(args.exportDir, ec).lexically_normal().string();
    options.protectedPaths = {args.input.empty() ? recorded : args.input};
    for (const auto& entry : fs::directory_iterator(args.path, ec))
      options.protectedPaths.push_back(entry.path().string());
    source = {{"path", args.path}, {"kind", "planes"}, {"input", options.protectedPaths.front()}};
    layers.push_back(std::make_unique<viewer::CloudLayer>(cloud, sample));
    layers.push_back(
        std::make_unique<viewer::PlanesLayer>(std::move(model), cloud, sample, options));
    return layers;
  }
  if (!args.input.empty())
    throw OptionError("--input goes with a `planes` result or a scale stack, not with a file");
  if (isPolylinePly(args.path)) {
    // Lines alone: their vertices are the cloud (coloured by the same attributes).
    PolylineSet lines = readPolylines(args.path);
    auto cloud = std::make_shared<PointCloud>(lines.vertices);
    source = {{"path", args.path}, {"kind", "lines"}};
    layers.push_back(std::make_unique<viewer::CloudLayer>(
        cloud, viewer::displaySampleFor(cloud->positions(), args.pointBudget)));
    layers.push_back(std::make_unique<viewer::LinesLayer>(std::move(lines), cloud->origin()));
    return layers;
  }
  InputOptions input;
  input.path = args.path;
  auto cloud = std::make_shared<PointCloud>(loadCloud(input, args.quiet));
  source = {{"path", args.path}, {"kind", "cloud"}};
  layers.push_back(std::make_unique<viewer::CloudLayer>(
      cloud, viewer::displaySampleFor(cloud->positions(), args.pointBudget)));
  return layers;
}

// The layers of PATH, and the polylines of --lines over them (positions relative to the cloud's
// origin, so that lines and points line up).
std::vector<std::unique_ptr<viewer::ViewerLayer>> loadLayers(const ViewArgs& args,
                                                             nlohmann::json& source) {
  auto layers = loadLayersWithoutLines(args, source);
  // A cylinders result brings its axes; --lines draws other polylines instead.
  const std::string linesPath = !args.lines.empty() || source.value("kind", "") != "cylinders"
                                    ? args.lines
                                    : (fs::path(args.path) / "axes.ply").string();
  if (linesPath.empty()) return layers;
  for (const auto& layer : layers)
    if (layer->name() == "lines")
      throw OptionError("--lines: " + args.path + " is a polyline file already");
  if (!isPolylinePly(linesPath))
    throw FileError(linesPath, "", "is not a PLY file with an edge element",
                    "pass the .ply written by `scalespace lines` (its .obj has no attributes)");
  PolylineSet lines = readPolylines(linesPath);
  const auto origin = layers.front()->manifest().at("origin");
  source["lines"] = linesPath;
  layers.push_back(std::make_unique<viewer::LinesLayer>(
      std::move(lines),
      Vec3(origin[0].get<double>(), origin[1].get<double>(), origin[2].get<double>())));
  return layers;
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "explore a cloud, a `planes` or `cylinders` result, a scale stack or polylines in the "
      "browser (local "
      "server, Sec. 2.4)");
  cmd->add_option("path", args->path,
                  "a cloud (.ply .las ...), a `scalespace planes` or `cylinders` folder (the "
                  "latter with its axes as lines), a scale stack (`scalespace scales`) or a "
                  "polyline .ply (`scalespace lines`)")
      ->required();
  cmd->add_option("--port", args->port, "port on 127.0.0.1 (0 = any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--no-browser", args->noBrowser, "only print the URL (no xdg-open)");
  cmd->add_option("--point-budget", args->pointBudget,
                  "draw at most this many points (beyond it, a subset spread evenly over the "
                  "cloud; queries still use all points)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t(1), std::size_t(1) << 31));
  cmd->add_option("--export-dir", args->exportDir,
                  "folder the page's exports are written to (new files, never replacing one)")
      ->capture_default_str()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--input", args->input,
                  "the cloud the planes or the stack were computed on (default: the one recorded "
                  "in PATH; for a stack, its stored input positions; given, its attributes can "
                  "colour the points)");
  cmd->add_option("--lines", args->lines,
                  "polylines (.ply with an edge element, `scalespace lines`) drawn over PATH")
      ->check(CLI::ExistingFile);
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr (the URL still goes to stdout)");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    nlohmann::json source;
    auto layers = loadLayers(*args, source);
    const std::string pageDir = viewer::findPageDirectory(programPath());
    viewer::PageAssets page = viewer::readPageAssets(pageDir);
    if (!page.missingReason.empty()) printWarnings({page.missingReason});
    std::size_t pointCount = 0;
    for (const auto& layer : layers)
      if (layer->name() == "cloud") pointCount = layer->manifest().at("point_count");
    auto router = std::make_unique<viewer::ViewerRouter>(viewer::makeViewerToken(), std::move(page),
                                                         std::move(layers), source);
    viewer::ViewerServerOptions options;
    options.port = args->port;
    options.maxBodyBytes = 4 * pointCount + 4096;  // a brush or domain of every point at most
    viewer::ViewerServer server(std::move(router), options);
    const int port = server.start();
    const std::string url =
        "http://127.0.0.1:" + std::to_string(port) + "/?token=" + server.router().token();
    std::printf("scalespace view: %s\n", url.c_str());
    std::fflush(stdout);
    if (!args->quiet) {
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "serving %s (loaded in %.2f s); Ctrl-C stops\n", args->path.c_str(),
                   seconds);
    }
    if (!args->noBrowser) openBrowser(url, args->quiet);
    // Serve until Ctrl-C / SIGTERM: the interrupt flag is what the progress callbacks read.
    const ProgressCallback interrupted = makeProgressBar(true);
    while (interrupted(0.0, "view")) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    server.stop();
    if (!args->quiet) std::fprintf(stderr, "scalespace view: stopped\n");
  });
}

}  // namespace scalespace::cli
