#include "scalespace/cli/CloudCommands.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/CylinderCommands.hpp"
#include "scalespace/cli/FeatureCommands.hpp"
#include "scalespace/cli/ParamCommands.hpp"
#include "scalespace/cli/PlanesCommands.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/cli/ScalesCommands.hpp"
#include "scalespace/cli/ViewCommands.hpp"
#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PipeScene.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/param/ParamShapes.hpp"

namespace scalespace::cli {
namespace {

using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------- info
void addInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "describe a point cloud file or a scale stack");
  cmd->add_option("file", *path, "point cloud or scale stack (NAME.stack)")->required();
  cmd->callback([path] {
    if (printStackInfo(*path, std::cout)) return;
    // `info` describes what is there: points with NaN/Inf coordinates are counted, not fatal.
    ReadOptions read;
    read.dropNonFinite = true;
    ReadReport report;
    const PointCloud cloud = readCloud(*path, read, &report);
    std::printf("file        %s\nformat      %s\npoints      %zu\n", path->c_str(),
                report.format.c_str(), cloud.size());
    if (report.droppedNonFinite > 0)
      std::printf(
          "invalid     %zu more points with NaN/Inf coordinates (not counted above; "
          "other commands stop on them unless given --drop-invalid)\n",
          report.droppedNonFinite);
    if (!cloud.empty()) {
      Vec3 lo, hi;
      cloud.bounds(lo, hi);
      lo += cloud.origin();
      hi += cloud.origin();
      std::printf("bounds      [%.17g, %.17g] x [%.17g, %.17g] x [%.17g, %.17g]\n", lo.x(), hi.x(),
                  lo.y(), hi.y(), lo.z(), hi.z());
      std::printf("diagonal    %.6g\n", (hi - lo).norm());
    }
    if (cloud.hasNormals()) {
      const std::size_t bad = unusableNormalCount(cloud);
      std::printf("normals     yes (nx ny nz)");
      if (bad > 0)
        std::printf(
            ", %zu of %zu NaN/Inf or zero (fits around them are invalid; `scalespace "
            "normals` re-estimates them)",
            bad, cloud.size());
      std::printf("\n");
    } else if (report.unusableNormalsDropped) {
      std::printf("normals     no (the file's are all NaN/Inf or zero: read as none)\n");
    } else {
      std::printf("normals     no\n");
    }
    if (cloud.viewpoint())
      std::printf("viewpoint   %.10g %.10g %.10g (estimated normals face it)\n",
                  cloud.viewpoint()->x(), cloud.viewpoint()->y(), cloud.viewpoint()->z());
    std::printf("attributes  %zu\n", cloud.attributes().size());
    for (const AttributeColumn& a : cloud.attributes()) {
      double mn = 0, mx = 0;
      if (!a.values.empty()) {
        const auto [lo, hi] = std::minmax_element(a.values.begin(), a.values.end());
        mn = *lo;
        mx = *hi;
      }
      std::printf("  %-20s %-8s min %.6g max %.6g\n", a.name.c_str(), scalarTypeName(a.type), mn,
                  mx);
    }
  });
}

// ------------------------------------------------------------------------------------ generate
void addGenerateCommand(CLI::App& app) {
  struct Args {
    std::string shape, output;
    GenerateOptions options;
    double normalNoise = 0;
    bool absoluteNoise = false;
    bool oneSided = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "generate",
      "sample an analytic surface (exact normals and curvatures as columns) or a "
      "piecewise-planar scene (Table 2.1's, or house / yard in metres; face labels as gt_face, "
      "house / yard also group labels as gt_group), or the pipe rack or the poles of the cylinders "
      "(pipe labels as gt_pipe, elbow parts and cable strands as gt_part)");
  static const char* const kShapes =
      "sphere | cylinder | saddle | torus | ellipsoid | tri | stairs | cubes | box | house | yard "
      "| pipes | poles | bumpy-disk | hemisphere | relief | holed-sheet | partial-sphere "
      "| triaxial | blob | rounded-cube | tube | ring";
  cmd->add_option("shape", args->shape, std::string(kShapes) + " (the shapes of `parametrize`)")
      ->required();
  cmd->add_option("-n,--points", args->options.pointCount, "number of points")
      ->capture_default_str();
  cmd->add_option("--noise", args->options.noise,
                  "Gaussian position noise, as a fraction of the bounding-box diagonal")
      ->capture_default_str();
  cmd->add_option("--normal-noise", args->normalNoise,
                  "analytic shapes: normal rotation noise sigma in degrees (Sec. 1.4.3)");
  cmd->add_option("--seed", args->options.seed, "random seed")->capture_default_str();
  cmd->add_flag("--one-sided", args->oneSided,
                "pipes, poles: keep what one scanner sees, above the rack or on a tripod south of "
                "the poles (each pipe a half-pipe)");
  cmd->add_option("-o,--output", args->output,
                  "output cloud (.ply .xyz .pcd .las; .pwn: positions and normals only)")
      ->required();
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    // Beyond 100M points (~10 GB through a fit) an extra zero is likelier than intent; 4e9 ended
    // in "std::bad_alloc".
    constexpr std::size_t kMaxPoints = 100'000'000;
    if (args->options.pointCount == 0 || args->options.pointCount > kMaxPoints)
      throw OptionError("--points must be in [1, " + std::to_string(kMaxPoints) + "], got " +
                        std::to_string(args->options.pointCount));
    if (!(args->options.noise >= 0)) throw OptionError("--noise must be >= 0");
    checkOutput(args->output, OutputKind::PointsWithNormals, {});
    const bool pipeScene = args->shape == "pipes" || args->shape == "poles";
    if (args->oneSided && !pipeScene)
      throw OptionError("--one-sided applies to the pipes and poles scenes only");
    PointCloud cloud;
    if (pipeScene) {
      PipeSceneOptions o;
      o.layout = args->shape == "poles" ? PipeLayout::Poles : PipeLayout::Rack;
      o.pointCount = args->options.pointCount;
      o.noise = args->options.noise;
      o.seed = args->options.seed;
      o.oneSided = args->oneSided;
      cloud = generatePipeScene(o);
    } else if (isParamShapeName(args->shape)) {
      ParamShapeOptions o;
      o.pointCount = args->options.pointCount;
      o.noise = args->options.noise;
      o.seed = args->options.seed;
      cloud = generateParamShape(parseParamShape(args->shape), o);
    } else if (!generateScene(args->shape, args->options, cloud)) {
      SurfaceSampleOptions o;
      try {
        o.shape = parseSurfaceShape(args->shape);
      } catch (const OptionError&) {  // it names the analytic surfaces only
        throw OptionError("unknown shape '" + args->shape + "' (use one of " + kShapes + ")");
      }
      o.count = args->options.pointCount;
      o.seed = args->options.seed;
      o.normalNoiseDegrees = args->normalNoise;
      const PointCloud clean = sampleSurface(o);
      o.positionNoise = args->options.noise * clean.boundingBoxDiagonal();
      cloud = o.positionNoise > 0 ? sampleSurface(o) : clean;
    }
    writeCloud(cloud, args->output);
    if (!args->quiet)
      std::fprintf(stderr, "generate: %zu points written to %s\n", cloud.size(),
                   args->output.c_str());
    reportDone("generate", start, args->quiet);
  });
}

// ------------------------------------------------------------------------------------- normals
struct NormalArgs {
  std::size_t k = 10;
  std::size_t maxK = NormalEstimationOptions{}.maxK;
  std::vector<std::string> orient{"mst"};
  double acrossWeight = NormalOrientationOptions{}.acrossWeight;
  bool reflect = NormalOrientationOptions{}.reflectAcrossBisector;
  bool visibility = NormalOrientationOptions{}.visibility;
  double sheet = NormalEstimationOptions{}.sheetTolerance;
  bool signFromPlanes = false;
  bool signByRays = false;
};

void addNormalOptions(CLI::App& cmd, NormalArgs& a) {
  cmd.add_option("--k", a.k, "neighbours for PCA normals and the orientation graph")
      ->capture_default_str();
  cmd.add_option("--max-k", a.maxK,
                 "under noise comparable to the sampling, the PCA's k doubles up to this while the "
                 "normals of k and 2k neighbours differ by more than 12 degrees (median); <= --k: "
                 "k as given")
      ->capture_default_str();
  cmd.add_option("--orient", a.orient,
                 "orientation: 'mst' (Hoppe 1992 propagation, seeds towards +z, or each part "
                 "facing a PCD's VIEWPOINT) or 'viewpoint X Y Z' (towards a scanner position, in "
                 "file coordinates)")
      ->expected(1, 4);
  cmd.add_option("--sheet", a.sheet,
                 "the plane of the neighbours within this x the k-th neighbour's distance (or 8 "
                 "noise RMS) of one through the point and two neighbours instead of the PCA "
                 "plane: one side's at a crease or across a thin part (0 = PCA; features: 0.05)")
      ->capture_default_str();
  cmd.add_flag("--sign-from-pca", a.signFromPlanes,
               "with --sheet: orient the PCA normals and give each sheet normal its point's sign "
               "(where surfaces touch, the sheet normals' own tree can turn one inside out; "
               "cylinders does this)");
  cmd.add_flag("--sign-by-rays", a.signByRays,
               "with --sheet: orient the sheet normals both ways (their own tree, the PCA "
               "normals' signs) and keep the one the visibility rays find facing inward less "
               "often (features does this)");
  cmd.add_option("--across-weight", a.acrossWeight,
                 "mst: extra cost of a graph edge across a thin part (offset along both normals), "
                 "so that its two sides are oriented apart (clean, dense scans of thin parts; it "
                 "hurts noisy or sparse ones); 0 = Hoppe's cost alone")
      ->capture_default_str();
  cmd.add_flag("--reflect", a.reflect,
               "mst: compare each normal with its neighbour's reflected across the plane that "
               "bisects their offset, not with the neighbour's itself: the two sides of a crease "
               "sharper than 90 degrees (a narrow V-groove) and of a thin part stay apart "
               "(features does this)");
  cmd.add_flag("--visibility,!--no-visibility", a.visibility,
               "mst: turn over the pieces of the propagation tree that rays cast from the points "
               "show facing the inside of a closed surface (both sides of thin parts, creases); "
               "on by default")
      ->capture_default_str();
}

NormalOrientationOptions orientationFrom(const NormalArgs& args, const PointCloud& cloud) {
  NormalArgs a = args;
  if (a.orient.size() == 1) {  // quoted as the help shows it: --orient 'viewpoint X Y Z'
    std::istringstream words(a.orient[0]);
    a.orient.assign(std::istream_iterator<std::string>(words), {});
  }
  NormalOrientationOptions o;
  o.k = a.k;
  o.acrossWeight = a.acrossWeight;
  o.reflectAcrossBisector = a.reflect;
  o.visibility = a.visibility;
  if (a.orient.size() == 1 && a.orient[0] == "mst") {
    o.method = OrientationMethod::MinimumSpanningTree;
    faceFileViewpoint(cloud, o);
  } else if (a.orient.size() == 4 && a.orient[0] == "viewpoint") {
    o.method = OrientationMethod::Viewpoint;
    Vec3 v;
    for (int c = 0; c < 3; ++c) {
      try {
        v[c] = std::stod(a.orient[1 + c]);
      } catch (const std::exception&) {
        throw OptionError("--orient viewpoint expects three numbers, got '" + a.orient[1 + c] +
                          "'");
      }
    }
    o.viewpoint = v - cloud.origin();  // the cloud works in recentred coordinates
  } else {
    throw OptionError("--orient takes 'mst' or 'viewpoint X Y Z'");
  }
  return o;
}

/// Estimates (PCA) and orients normals in place; adds a `normal_reliable` column (0/1).
void estimateAndOrient(PointCloud& cloud, const NormalArgs& a, const ProgressCallback& progress,
                       bool quiet) {
  if (a.k < 3) throw OptionError("--k must be >= 3");
  if (a.k >= cloud.size())
    throw OptionError("--k " + std::to_string(a.k) +
                      " must be smaller than the number of points (" +
                      std::to_string(cloud.size()) + ")");
  if (a.signFromPlanes && !(a.sheet > 0))
    throw OptionError("--sign-from-pca needs sheet normals (--sheet > 0)");
  if (a.signByRays && !(a.sheet > 0))
    throw OptionError("--sign-by-rays needs sheet normals (--sheet > 0)");
  if (a.signByRays && a.signFromPlanes)
    throw OptionError("give one of --sign-from-pca and --sign-by-rays");
  OrientedNormalsOptions options;
  options.orientation = orientationFrom(a, cloud);
  options.estimation.k = a.k;
  options.estimation.maxK = a.maxK;
  options.estimation.sheetTolerance = a.sheet;
  options.sheetSign = a.signByRays       ? SheetSign::ByRays
                      : a.signFromPlanes ? SheetSign::FromPlanes
                                         : SheetSign::OwnTree;
  const NormalOrientationOptions& orientation = options.orientation;
  const auto index = makeSpatialIndex(cloud.positions());
  OrientedNormals normals = estimateOrientedNormals(cloud.positions(), *index, options, progress);
  const NormalEstimationResult& est = normals.estimation;
  const NormalOrientationResult& ori = normals.orientation;
  cloud.setNormals(std::move(normals.normals));
  AttributeColumn& flag = cloud.addAttribute("normal_reliable", ScalarType::UInt8);
  for (std::size_t i = 0; i < cloud.size(); ++i) flag.values[i] = ori.reliable[i];
  if (!quiet)
    std::fprintf(stderr,
                 "normals: %zu estimated (k = %zu), %zu degenerate, %zu flipped, %zu without a "
                 "reliable orientation (normal_reliable = 0)%s\n",
                 cloud.size(), est.k, est.invalidCount, ori.flippedCount, ori.unreliableCount,
                 orientation.faceViewpoint ? "; the tree's parts face the file's VIEWPOINT" : "");
  if (!quiet && options.sheetSign == SheetSign::ByRays)
    std::fprintf(stderr,
                 "normals: signs of %s (the two differ at %zu points; of %zu sampled, the rays "
                 "find %zu facing inward with the sheet normals' own tree, %zu with the PCA "
                 "signs)\n",
                 normals.signSource == SheetSign::OwnTree ? "the sheet normals' own tree"
                                                          : "the PCA normals",
                 normals.rays.differing, normals.rays.sampled, normals.rays.firstInward,
                 normals.rays.secondInward);
}

void addNormalsCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output;
    NormalArgs normals;
    int threads = 0;
    bool ascii = false, quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "normals", "estimate (PCA over k neighbours) and orient normals; replaces existing ones");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output,
                  "output cloud with the normals and normal_reliable (a .pwn, CGAL's points with "
                  "normals, holds the positions and normals only)")
      ->required();
  addNormalOptions(*cmd, args->normals);
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    checkOutput(args->output, OutputKind::PointsWithNormals, {args->input.path});
    PointCloud cloud = loadCloud(args->input, args->quiet);
    estimateAndOrient(cloud, args->normals, makeProgressBar(args->quiet), args->quiet);
    writeCloud(cloud, args->output, WriteOptions{args->ascii});
    if (!args->quiet) std::fprintf(stderr, "normals: written to %s\n", args->output.c_str());
    reportDone("normals", start, args->quiet);
  });
}

// ----------------------------------------------------------------------------------- curvature
void addCurvatureCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, estimator = "w3";
    double scale = 0;
    int scaleK = 0;
    bool mls = false, robust = false, ascii = false, quiet = false;
    int threads = 0;
    NormalArgs normals;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "curvature", "normals, mean and principal curvatures and directions at one scale (Ch. 1)");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output, "output cloud, one row per input point")->required();
  auto* scale = cmd->add_option("--scale", args->scale, "support radius t in the cloud's units");
  auto* scaleK = cmd->add_option("--scale-k", args->scaleK,
                                 "per-point t = distance to the K-th nearest neighbour");
  scale->excludes(scaleK);
  cmd->add_option("--estimator", args->estimator, "w3 | w2 | w1 | plane | mean | quadric | jet")
      ->capture_default_str();
  cmd->add_flag("--mls", args->mls, "iterate the MLS projection (Eq. 1.12; <= 20 steps, 0.001 t)");
  cmd->add_flag("--robust", args->robust, "robust re-weighting (RIMLS, Oztireli 2009)");
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  addNormalOptions(*cmd, args->normals);
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    checkOutput(args->output, OutputKind::Cloud, {args->input.path});
    CurvatureOptions options;
    options.fit.estimator = parseEstimator(args->estimator);
    options.fit.mls = args->mls;
    options.fit.robust = args->robust;
    options.scale = args->scale;
    options.scaleK = args->scaleK;

    validateCurvatureOptions(options);  // before the read
    PointCloud cloud = loadCloud(args->input, args->quiet);
    if (std::size_t(options.scaleK) >= cloud.size())
      throw OptionError("--scale-k " + std::to_string(options.scaleK) +
                        " must be smaller than the number of points (" +
                        std::to_string(cloud.size()) + ")");
    const auto progress = makeProgressBar(args->quiet);
    const bool hadNormals = cloud.hasNormals();
    if (!hadNormals) {
      if (!args->quiet)
        std::fprintf(stderr, "%s has no normals: estimating and orienting them first\n",
                     args->input.path.c_str());
      estimateAndOrient(cloud, args->normals, progress, args->quiet);
    }
    // The fitted normal is written as nx ny nz after the input's attributes; the normals the fit
    // started from are kept as in_nx in_ny in_nz so nothing of the input is lost.
    const std::vector<Vec3> inputNormals = cloud.normals();
    const char* inNames[] = {"in_nx", "in_ny", "in_nz"};
    for (int c = 0; c < 3; ++c) {
      AttributeColumn& col = cloud.addAttribute(inNames[c], ScalarType::Float32);
      for (std::size_t i = 0; i < cloud.size(); ++i) col.values[i] = inputNormals[i][c];
    }
    // Shown before the work, which such a scale makes long; not again at the end.
    const std::vector<std::string> early = curvatureScaleWarnings(cloud, options);
    printWarnings(early);
    const CurvatureSummary summary = computeCurvatureColumns(cloud, options, progress);
    cloud.setNormals({});
    writeCloud(cloud, args->output, WriteOptions{args->ascii});

    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    nlohmann::json json = {{"command", "curvature"},
                           {"version", SCALESPACE_VERSION},
                           {"input", args->input.path},
                           {"output", args->output},
                           {"points", summary.points},
                           {"invalid_fits", summary.invalid},
                           {"mean_neighbors", summary.meanNeighbors},
                           {"parameters",
                            {{"estimator", estimatorName(options.fit.estimator)},
                             {"scale", options.scale},
                             {"scale_k", options.scaleK},
                             {"median_scale", summary.medianScale},
                             {"mls", options.fit.mls},
                             {"robust", options.fit.robust},
                             {"normals_estimated", !hadNormals},
                             {"threads", args->threads}}},
                           {"seconds", {{"fits", summary.seconds}, {"total", total}}},
                           {"warnings", summary.warnings}};
    std::vector<std::string> late;
    for (const std::string& w : summary.warnings)
      if (std::find(early.begin(), early.end(), w) == early.end()) late.push_back(w);
    printWarnings(late);
    const std::string summaryPath = summaryPathFor(args->output);
    writeJson(summaryPath, json);
    if (!args->quiet)
      std::fprintf(stderr,
                   "curvature: %zu points, t = %.6g%s, %.1f neighbours on average, %zu invalid "
                   "fits -> %s (summary %s)\n",
                   summary.points, summary.medianScale, options.scaleK ? " (median)" : "",
                   summary.meanNeighbors, summary.invalid, args->output.c_str(),
                   summaryPath.c_str());
    reportDone("curvature", start, args->quiet);
  });
}

}  // namespace

void addCloudCommands(CLI::App& app) {
  addInfoCommand(app);
  addGenerateCommand(app);
  addNormalsCommand(app);
  addCurvatureCommand(app);
  addScalesCommands(app);
  addPlanesCommands(app);
  addFeatureCommands(app);
  addCylinderCommands(app);
  addParamCommands(app);
  addViewCommand(app);
}

}  // namespace scalespace::cli
