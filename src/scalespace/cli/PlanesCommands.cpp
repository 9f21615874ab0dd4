#include "scalespace/cli/PlanesCommands.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/CylinderCommands.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/planes/StackPlanes.hpp"
#include "scalespace/render/ColorMap.hpp"
#include "scalespace/render/LineRenderer.hpp"
#include "scalespace/render/PngWriter.hpp"
#include "scalespace/render/PointRenderer.hpp"

namespace scalespace::cli {

bool generateScene(const std::string& name, const GenerateOptions& options, PointCloud& cloud) {
  if (name != "tri" && name != "stairs" && name != "cubes" && name != "box" && name != "house" &&
      name != "yard")
    return false;
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
    std::string output, color, labels, view = "iso", up = "z", size = "1024x768";
    std::string lines, lineColor, checker;
    int radius = -1, checkerCells = 12;
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
  cmd->add_option("--up", args->up, "the cloud's up axis: x | y | z | -x | -y | -z")
      ->capture_default_str();
  cmd->add_option("--size", args->size, "image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--point-radius", args->radius, "splat radius in pixels (-1 = automatic)")
      ->capture_default_str();
  cmd->add_flag("--no-shading", args->noShading, "flat colours (no shading from normals)");
  auto* checker =
      cmd->add_option("--checker", args->checker,
                      "A,B: darken alternate cells of a grid over attributes A and B (e.g. u,v or "
                      "longitude,latitude of `parametrize`)");
  cmd->add_option("--checker-cells", args->checkerCells,
                  "checker cells across the larger of the two attributes' ranges")
      ->capture_default_str()
      ->needs(checker);
  auto* lines = cmd->add_option("--lines", args->lines,
                                "draw these polylines (.ply with vertex and edge elements) over "
                                "the points, hidden where the surface is in front of them");
  cmd->add_option("--line-color-by", args->lineColor,
                  "colour the lines by a vertex attribute of theirs (default: solid red)")
      ->needs(lines);
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    checkOutput(args->output, OutputKind::Png, {args->input.path, args->lines});
    RenderOptions options;
    parseSize(args->size, options.width, options.height);
    options.view = args->view;
    options.up = args->up;
    viewDirection(options.view, options.up);  // validate before the (possibly long) read
    options.colorAttribute = args->color;
    options.labelAttribute = args->labels;
    options.pointRadius = args->radius;
    if (!args->checker.empty()) {
      const std::size_t comma = args->checker.find(',');
      if (comma == std::string::npos || comma == 0 || comma + 1 == args->checker.size() ||
          args->checker.find(',', comma + 1) != std::string::npos)
        throw OptionError("--checker '" + args->checker + "' is not two attribute names A,B");
      options.checkerAttributes = {args->checker.substr(0, comma), args->checker.substr(comma + 1)};
      options.checkerCells = args->checkerCells;
    }
    if (args->radius > kMaxPointRadius && !args->quiet)
      std::fprintf(stderr, "warning: --point-radius %d is drawn as %d pixels (the largest)\n",
                   args->radius, kMaxPointRadius);
    options.shading = !args->noShading;
    // The lines first: they are small, and a bad lines file or colour attribute is then reported
    // before the (possibly long) read of the cloud.
    PolylineSet polylines;
    LineRenderOptions lineOptions;
    lineOptions.colorAttribute = args->lineColor;
    if (!args->lines.empty()) {
      polylines = readPolylines(args->lines);
      polylineColors(polylines, lineOptions);
    }
    const PointCloud cloud = loadCloud(args->input, args->quiet);
    Rendering rendering = renderPointsWithDepth(cloud, options);
    if (!args->lines.empty()) {
      drawPolylines(rendering, polylines, lineOptions);
      if (!args->quiet)
        std::fprintf(stderr, "%zu lines, %zu vertices drawn\n", polylines.lineCount(),
                     polylines.vertices.size());
    }
    writePng(rendering.image, args->output);
    reportDone("render", start, args->quiet);
  });
}

// Point indices from a text file: integers separated by spaces/newlines, '#' starts a comment.
std::vector<Index> readIndexFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError(path, "", "cannot open", "check the path");
  std::vector<Index> out;
  std::string line;
  for (std::size_t lineNo = 1; std::getline(in, line); ++lineNo) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string word;
    while (words >> word) {
      char* end = nullptr;
      const long long v = std::strtoll(word.c_str(), &end, 10);
      if (*end != '\0' || v < 0 || v > 0xffffffffLL)
        throw FileError(path, "line " + std::to_string(lineNo),
                        "'" + word + "' is not a point index", "one non-negative integer per word");
      out.push_back(Index(v));
    }
  }
  if (out.empty()) throw FileError(path, "", "no point index found");
  return out;
}

void addSegmentCommand(CLI::App& app) {
  struct Args {
    std::string directory, output, input, brush, within;
    int minPersistence = -1, similar = -1;
    double scale = 0;
    SimilarityOptions similarity;
    bool coverage = false;
    CoverageOptions coverageOptions;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "segment", "label points with plane components (Sec. 2.4): plane_id (-1 none) and colours");
  cmd->add_option("directory", args->directory, "output directory of `scalespace planes`")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--output", args->output, "output cloud (.ply ...)")->required();
  auto* pers = cmd->add_option(
      "--min-persistence", args->minPersistence,
      "components with persistence >= P (per point the most persistent, a planar one "
      "before a flagged one)");
  auto* scale =
      cmd->add_option("--scale", args->scale, "segmentation at the computed scale nearest to T");
  auto* brush = cmd->add_option(
      "--brush", args->brush, "file of point indices: rank components by Eq. 2.2, label the best");
  auto* similar =
      cmd->add_option("--similar", args->similar, "component id to search for (with --within)");
  auto* within = cmd->add_option("--within", args->within, "file of point indices: search domain");
  similar->needs(within);
  within->needs(similar);
  pers->excludes(scale, brush, similar);
  scale->excludes(brush, similar);
  brush->excludes(similar);
  cmd->add_option("--birth-tolerance", args->similarity.birthTolerance,
                  "similarity: max birth level difference")
      ->capture_default_str();
  cmd->add_option("--death-tolerance", args->similarity.deathTolerance,
                  "similarity: max death level difference")
      ->capture_default_str();
  cmd->add_option("--area-tolerance", args->similarity.maxAreaDifference,
                  "similarity: max |area difference| / query area")
      ->capture_default_str();
  cmd->add_option("--angle", args->similarity.maxAngleDegrees,
                  "similarity: max angle between planes (degrees)")
      ->capture_default_str();
  cmd->add_flag(
      "--extend-coverage", args->coverage,
      "extend the labels to nearby points close to the plane (Sec. 2.5.1; needs normals)");
  cmd->add_option("--coverage-distance", args->coverageOptions.maxDistanceFraction,
                  "coverage: max distance to the plane, fraction of the diagonal")
      ->capture_default_str();
  cmd->add_option("--coverage-angle", args->coverageOptions.maxAngleDegrees,
                  "coverage: max normal deviation (degrees)")
      ->capture_default_str();
  cmd->add_option("--input", args->input,
                  "the cloud the planes were computed on (default: the one recorded in DIR)");
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args, pers, scale, brush, similar] {
    const auto start = std::chrono::steady_clock::now();
    if (!*pers && !*scale && !*brush && !*similar)
      throw OptionError("segment needs one of --min-persistence, --scale, --brush, --similar");
    validate(args->coverageOptions);  // before any reading
    validate(args->similarity);
    if (isCylinderResult(args->directory))
      throw FileError(args->directory, "", "is a `scalespace cylinders` result, not a `planes` one",
                      "label its points with `scalespace cylinders-segment`");
    std::string recorded;
    PlaneModel model = readPlaneModel(args->directory, &recorded);
    PointCloud cloud = loadResultInput(recorded, args->input, args->directory, "planes",
                                       model.membership.pointCount, args->output, args->quiet);
    // The saved offsets are absolute; the algorithms work on positions relative to the origin.
    for (auto& c : model.components) c.plane.offset -= c.plane.normal.dot(cloud.origin());

    std::vector<int> labels;
    if (*pers) {
      labels = labelsByPersistence(model, args->minPersistence);
    } else if (*scale) {
      if (model.scales.empty()) throw OptionError(args->directory + " holds no scales");
      const int level = nearestLevel(model, args->scale);
      labels = labelsAtScale(model, args->scale);
      std::set<int> planes(labels.begin(), labels.end());
      planes.erase(-1);
      if (!args->quiet) {
        const double lo = model.scales.front(), hi = model.scales.back();
        if (args->scale < lo || args->scale > hi)
          std::fprintf(stderr,
                       "warning: --scale %g is outside the computed scales [%g, %g]; using the "
                       "nearest\n",
                       args->scale, lo, hi);
        std::fprintf(stderr, "scale t = %g (level %d of %d, nearest to %g): %zu planes\n",
                     model.scales[std::size_t(level)], level, model.scaleCount(), args->scale,
                     planes.size());
      }
    } else if (*brush) {
      const auto matches = rankByBrush(model, readIndexFile(args->brush));
      labels.assign(cloud.size(), -1);
      if (!args->quiet) std::printf("component,score,overlap,persistence\n");
      for (const BrushMatch& m : matches)
        if (!args->quiet)
          std::printf("%d,%.6g,%.6g,%d\n", m.component, m.score, m.overlap,
                      model.components[std::size_t(m.component)].persistence);
      if (!matches.empty()) labels = labelsOfComponents(model, {matches.front().component});
    } else {
      const auto found =
          findSimilar(model, args->similar, readIndexFile(args->within), args->similarity);
      labels = labelsOfComponents(model, found);
      if (!args->quiet) std::fprintf(stderr, "%zu similar components\n", found.size());
    }
    if (args->coverage) {
      ensureNormals(cloud, args->quiet);
      labels = extendCoverage(model, labels, cloud.positions(), cloud.normals(),
                              buildKnnGraph(cloud.positions()), args->coverageOptions);
    }
    addPlaneLabelColumns(cloud, labels);
    const std::size_t labelled =
        std::size_t(std::count_if(labels.begin(), labels.end(), [](int l) { return l >= 0; }));
    writeCloud(cloud, args->output);
    if (!args->quiet) std::fprintf(stderr, "%zu of %zu points labelled\n", labelled, labels.size());
    reportDone("segment", start, args->quiet);
  });
}

void addPlanesCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, stack;
    int scales = 50;
    double alpha = 0.1, angle = 5.0;
    PlaneDetectionOptions detection;
    int threads = 0;
    bool quiet = false, robust = true;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "planes", "multi-scale planes by persistence (Chapter 2): components, outlines, diagram");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output,
                  "output directory (components.json/.csv, outlines.obj, persistence.svg, "
                  "membership.bin)")
      ->required();
  cmd->add_option("--scales", args->scales, "number of log-spaced scales M")->capture_default_str();
  cmd->add_option("--stack", args->stack,
                  "use this stack (`scalespace scales IN -o STACK`) instead of computing one")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--alpha", args->alpha, "Poisson-disk sub-sampling factor of the stack")
      ->capture_default_str();
  cmd->add_option("--angle", args->angle, "region growing angle theta (degrees)")
      ->capture_default_str();
  cmd->add_option("--max-step", args->detection.growing.maxStep,
                  "largest step a region crosses between neighbours along its seed's normal, as a "
                  "fraction of t (0 = the angle alone, Sec. 2.3.1)")
      ->capture_default_str();
  cmd->add_option("--max-rms", args->detection.planarity.maxRelativeRms,
                  "a region whose points lie farther from their plane (RMS) than this fraction "
                  "of t and twice the noise is not planar: never linked to a planar one, its "
                  "component flagged (0 = link any regions, Sec. 2.3.2)")
      ->capture_default_str();
  cmd->add_option("--merge-rms", args->detection.merging.maxRelativeRms,
                  "before the filter, adjacent regions each smaller than the scale are merged "
                  "where their union's plane RMS is at most this fraction of t (a staircase "
                  "becomes its mean ramp; 0 = as grown, Sec. 2.3.1)")
      ->capture_default_str();
  cmd->add_option("--merge-deviation", args->detection.merging.maxRelativeDeviation,
                  "with --merge-rms: the farthest any point of a merged union may lie from its "
                  "plane, as a fraction of t")
      ->capture_default_str();
  cmd->add_option("--merge-parallel", args->detection.merging.parallelDegrees,
                  "with --merge-rms: a union within this angle (degrees) of a large region next "
                  "to it and within --merge-deviation of its plane, which that region does not "
                  "take, is undone: it is that surface cut off by --max-step, not a second plane "
                  "(0 = kept)")
      ->capture_default_str();
  cmd->add_option("--refine-distance", args->detection.refinement.maxRelativeDistance,
                  "with --merge-rms: a merged union takes the neighbouring points that lie nearer "
                  "its plane than their own region's, within this fraction of t of it (its "
                  "edges, which the robust fit gives to the surfaces it meets; 0 = as grown)")
      ->capture_default_str();
  cmd->add_flag("--refine-unlabelled,!--no-refine-unlabelled",
                args->detection.refinement.takeUnlabelled,
                "with --refine-distance: a merged union also takes the points of no region next "
                "to it that its plane describes as well as its own (the ends of a short "
                "staircase, dropped with the small regions there)")
      ->capture_default_str();
  cmd->add_option("--fill-max-angle", args->detection.refinement.fillMaxAngleDegrees,
                  "with --refine-unlabelled: ... but not a point whose own surface (the plane of "
                  "its neighbours) turns more than this many degrees from the union's plane (a "
                  "staircase's sides); 90 = by distance alone")
      ->capture_default_str();
  cmd->add_flag("--no-robust{false}", args->robust,
                "plain APSS for the stack instead of the robust one of Sec. 2.3 (faster)");
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    ThreadScope threads(args->threads);
    if (args->scales < 2) throw OptionError("--scales must be >= 2 (persistence needs levels)");
    ScaleSpaceOptions stack;
    stack.fit.robust = args->robust;  // Sec. 2.3, Fig. 2.5: planes use the robust APSS
    stack.series.count = args->scales;
    stack.alpha = args->alpha;
    stack.threads = args->threads;
    PlaneDetectionOptions options = args->detection;
    options.growing.maxAngleDegrees = args->angle;
    validateScaleSpaceOptions(stack);  // before the (possibly long) read
    validatePlaneDetectionOptions(options);
    checkOutput(args->output, OutputKind::PlanesResult, {args->input.path, args->stack});
    PointCloud cloud = loadCloud(args->input, args->quiet);
    if (args->stack.empty()) ensureNormals(cloud, args->quiet);
    StackPlaneDetection result;
    if (args->stack.empty()) {
      result = detectPlanesInCloud(cloud, stack, options, makeProgressBar(args->quiet));
      printWarnings(invalidFitWarnings(cloud, stackFitCounts(result.stack, cloud.size(), stack)));
    } else {
      const ScaleStackReader reader(args->stack);
      result.detection =
          detectPlanesFromStack(cloud, reader, options, makeProgressBar(args->quiet));
    }
    const PlaneModel model = makePlaneModel(result.detection);
    // The absolute path, so that `segment` finds the cloud from any working folder.
    std::error_code ec;
    const std::string inputPath = std::filesystem::absolute(args->input.path, ec).string();
    writePlaneModel(model, cloud.origin(), ec ? args->input.path : inputPath, args->output);
    if (!args->quiet) {
      const auto& t = result.detection.timings;
      // With a stack computed here, segmentation and filtering ran during it (StackPlanes.hpp).
      std::fprintf(stderr,
                   "%zu components; time (s): stack %.2f, segmentation %.2f, filtering %.2f%s, "
                   "graph %.2f, components %.2f\n",
                   model.components.size(), result.stackSeconds, t.segmentation, t.filtering,
                   args->stack.empty() ? " (during the stack)" : "", t.graph, t.components);
    }
    std::size_t curved = 0, noiseLimited = 0;
    for (const PlaneComponent& c : model.components) {
      curved += !c.planar;
      noiseLimited += c.noiseLimited;
    }
    const double maxRms = args->detection.planarity.maxRelativeRms > 0
                              ? args->detection.planarity.maxRelativeRms
                              : ComponentOptions{}.maxRelativeRms;
    if (curved && !args->quiet)
      std::fprintf(stderr,
                   "%zu of the components are not described by a plane (RMS > %g of their scale "
                   "and > %g x the noise, %.3g): components.json marks them \"planar\": false; "
                   "segment --min-persistence prefers the planar ones\n",
                   curved, maxRms, args->detection.planarity.noiseFactor,
                   result.detection.noiseRms);
    if (noiseLimited && !args->quiet)
      std::fprintf(stderr,
                   "%zu planar components have an RMS above %g of their scale, within the noise "
                   "only (fine scales): components.json marks them \"noise_limited\": true\n",
                   noiseLimited, maxRms);
    reportDone("planes", start, args->quiet);
  });
}

}  // namespace

void addPlanesCommands(CLI::App& app) {
  addRenderCommand(app);
  addPlanesCommand(app);
  addSegmentCommand(app);
}

}  // namespace scalespace::cli
