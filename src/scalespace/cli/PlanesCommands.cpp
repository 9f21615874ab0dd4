#include "scalespace/cli/PlanesCommands.hpp"

#include <chrono>
#include <cstdio>
#include <memory>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/render/PngWriter.hpp"
#include "scalespace/render/PointRenderer.hpp"

namespace scalespace::cli {

bool generateScene(const std::string& name, const GenerateOptions& options, PointCloud& cloud) {
  if (name != "tri" && name != "stairs" && name != "cubes" && name != "box") return false;
  if (options.pointCount == 0) throw OptionError("-n must be >= 1");
  SceneOptions scene;
  scene.pointCount = options.pointCount;
  scene.noise = options.noise;
  scene.seed = options.seed;
  cloud = generateScene(sceneKindFromName(name), scene);
  return true;
}

namespace {

// "1024x768" -> width, height.
void parseSize(const std::string& text, int& width, int& height) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
      w <= 0 || h <= 0)
    throw OptionError("--size '" + text + "' is not WIDTHxHEIGHT (e.g. 1024x768)");
  width = w;
  height = h;
}

void addRenderCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, color, labels, view = "iso", size = "1024x768";
    int radius = -1;
    bool noShading = false, quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("render", "render a point cloud to a PNG image (no GPU needed)");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output, "output image (.png)")->required();
  auto* color =
      cmd->add_option("--color", args->color,
                      "colour by a scalar attribute (viridis over its 2nd-98th percentile)");
  cmd->add_option("--labels", args->labels, "colour by an integer label attribute (-1 grey)")
      ->excludes(color);
  cmd->add_option("--view", args->view, "front | top | iso | X,Y,Z (viewing direction)")
      ->capture_default_str();
  cmd->add_option("--size", args->size, "image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--point-radius", args->radius, "splat radius in pixels (-1 = automatic)")
      ->capture_default_str();
  cmd->add_flag("--no-shading", args->noShading, "flat colours (no shading from normals)");
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    checkOutputPath(args->input.path, args->output);
    RenderOptions options;
    parseSize(args->size, options.width, options.height);
    options.view = args->view;
    viewDirection(options.view);  // validate before the (possibly long) read
    options.colorAttribute = args->color;
    options.labelAttribute = args->labels;
    options.pointRadius = args->radius;
    options.shading = !args->noShading;
    const PointCloud cloud = loadCloud(args->input, args->quiet);
    writePng(renderPoints(cloud, options), args->output);
    reportDone("render", start, args->quiet);
  });
}

void addGenerateCommand(CLI::App& app) {
  struct Args {
    std::string scene, output;
    GenerateOptions options;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "generate", "sample a synthetic piecewise-planar scene (Table 2.1) with face labels gt_face");
  cmd->add_option("scene", args->scene, "tri | stairs | cubes | box")->required();
  cmd->add_option("-n,--points", args->options.pointCount, "number of points")
      ->capture_default_str();
  cmd->add_option("--noise", args->options.noise,
                  "Gaussian noise sigma as a fraction of the bounding-box diagonal (e.g. 1e-4)")
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "random seed")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "output cloud (.ply .xyz .las .pcd)")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    PointCloud cloud;
    if (!generateScene(args->scene, args->options, cloud))
      throw OptionError("unknown scene '" + args->scene + "' (use tri, stairs, cubes or box)");
    writeCloud(cloud, args->output);
    reportDone("generate", start, args->quiet);
  });
}

bool hasSubcommand(CLI::App& app, const std::string& name) {
  return !app.get_subcommands([&](CLI::App* sub) { return sub->get_name() == name; }).empty();
}

}  // namespace

void addPlanesCommands(CLI::App& app) {
  addRenderCommand(app);
  if (!hasSubcommand(app, "generate")) addGenerateCommand(app);
}

}  // namespace scalespace::cli
