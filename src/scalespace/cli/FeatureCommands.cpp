#include "scalespace/cli/FeatureCommands.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/features/CurvatureLines.hpp"
#include "scalespace/features/FeatureCurves.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace::cli {
namespace {

using Clock = std::chrono::steady_clock;

/// Every line of `sets` as one polyline set with the per-vertex attributes of Sec. 3.3:
/// line id, scale, kappa1, kappa2, |kappa1| - |kappa2|, nu, tangent (and the normal).
PolylineSet toPolylines(const std::vector<CurvatureLineSet>& sets, const Vec3& origin) {
  std::vector<Vec3> positions, normals;
  std::vector<double> columns[9];
  PolylineSet out;
  std::size_t id = 0;
  for (const CurvatureLineSet& set : sets)
    for (const CurvatureLine& line : set.lines) {
      for (const CurvatureLineVertex& v : line.vertices) {
        positions.push_back(v.position);
        normals.push_back(v.normal);
        const double values[9] = {double(id),
                                  set.scale,
                                  v.kappa1,
                                  v.kappa2,
                                  std::abs(v.kappa1) - std::abs(v.kappa2),
                                  v.geometricVariation,
                                  v.tangent.x(),
                                  v.tangent.y(),
                                  v.tangent.z()};
        for (int c = 0; c < 9; ++c) columns[c].push_back(values[c]);
      }
      out.offsets.push_back(positions.size());
      out.closed.push_back(line.closed ? 1 : 0);
      ++id;
    }
  out.vertices.setRelativePositions(std::move(positions), origin);
  out.vertices.setNormals(std::move(normals));
  const char* names[9] = {"line_id", "scale", "k1", "k2", "k_gap", "nu", "tx", "ty", "tz"};
  for (int c = 0; c < 9; ++c) {
    AttributeColumn& column =
        out.vertices.addAttribute(names[c], c == 0 ? ScalarType::Int32 : ScalarType::Float32);
    column.values = std::move(columns[c]);
  }
  return out;
}

nlohmann::json stopCounts(const CurvatureLineSet& set) {
  nlohmann::json stops = nlohmann::json::object();
  for (std::size_t s = 0; s < set.stops.size(); ++s)
    stops[lineStopName(LineStop(s))] = set.stops[s];
  return stops;
}

// The seeds' order (CurvatureLineOptions::curvedSeedsFirst), one flag for lines and features.
void addSeedOrderFlag(CLI::App& cmd, CurvatureLineOptions& lines) {
  cmd.add_flag("--random-seed-order{false}", lines.curvedSeedsFirst,
               "trace the seeds in the sampler's random order (Sec. 3.3) instead of the most "
               "curved first");
}

// ------------------------------------------------------------------------------------- lines
void addLinesCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output;
    double scale = 0, tMin = 0, tMax = 0;
    int scales = 0;
    CurvatureLineOptions lines;
    bool robust = false, ascii = false, quiet = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "lines", "minimal-curvature lines on the APSS at one or several scales (Sec. 3.3)");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output, "output polylines (.ply with edges, or .obj)")
      ->required();
  auto* scale = cmd->add_option("--scale", args->scale, "scale t in the cloud's units");
  auto* scales = cmd->add_option(
      "--scales", args->scales,
      "M scales, log-spaced from --tmin (default: the mean distance to the 16th neighbour) to "
      "--tmax (default: 10% of the bounding-box diagonal)");
  scale->excludes(scales);
  cmd->add_option("--tmin", args->tMin, "smallest scale with --scales");
  cmd->add_option("--tmax", args->tMax, "largest scale with --scales");
  cmd->add_option("--beta", args->lines.beta, "seeds: Poisson-disk radius beta t")
      ->capture_default_str();
  cmd->add_option("--gamma", args->lines.gamma, "step delta = gamma t (Eq. 3.2)")
      ->capture_default_str();
  cmd->add_option("--alpha", args->lines.alpha,
                  "fits read the Poisson-disk level of radius alpha t (Sec. 1.5.2; 0 = all points)")
      ->capture_default_str();
  cmd->add_option("--max-steps", args->lines.maxSteps, "most steps each way")
      ->capture_default_str();
  cmd->add_flag("--robust", args->robust, "robust re-weighting (RIMLS) in the fits");
  addSeedOrderFlag(*cmd, args->lines);
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    if (args->scale <= 0 && args->scales <= 0)
      throw OptionError("give the scale: --scale T, or --scales M for M scales");
    if (args->scales > 0) validateScaleCount(args->scales);
    CurvatureLineOptions options = args->lines;
    options.fit.robust = args->robust;
    options.scale = args->scale > 0 ? args->scale : 1;
    validateCurvatureLineOptions(options);  // before the read
    checkOutput(args->output, OutputKind::Lines, {args->input.path});
    PointCloud cloud = loadCloud(args->input, args->quiet);
    ensureNormals(cloud, args->quiet);

    std::vector<double> ts{args->scale};
    if (args->scales > 0) {
      const double lo =
          args->tMin > 0 ? args->tMin : meanKthNeighborDistance(cloud.positions(), 16);
      const double hi = args->tMax > 0 ? args->tMax : 0.1 * cloud.boundingBoxDiagonal();
      if (args->scales > 1 && !(lo < hi)) {
        // Name the bounds as they were set: computed ones with their rule (a sparse or tiny
        // cloud has its 16th neighbour beyond a tenth of its diagonal), given ones as given.
        const auto bound = [](const char* flag, double value, bool given, const char* rule) {
          return std::string(given ? flag
                                   : std::string("the default ") + flag + " (" + rule + ")") +
                 " = " + std::to_string(value);
        };
        throw OptionError(
            "--scales " + std::to_string(args->scales) + " needs the smallest scale below the " +
            "largest, but " +
            bound("--tmin", lo, args->tMin > 0, "the mean distance to the 16th neighbour") +
            " is not below " +
            bound("--tmax", hi, args->tMax > 0, "10% of the bounding-box diagonal") +
            ": give --tmin and --tmax with tmin < tmax, or one scale with --scale T");
      }
      ts = scaleSeries(lo, std::max(hi, lo), args->scales, ScaleSpacing::Log);
    }
    const auto progress = makeProgressBar(args->quiet);
    std::vector<CurvatureLineSet> sets;
    nlohmann::json perScale = nlohmann::json::array();
    for (std::size_t s = 0; s < ts.size(); ++s) {
      options.scale = ts[s];
      const auto scaleProgress = [&](double f, std::string_view stage) {
        return !progress || progress((double(s) + f) / double(ts.size()), stage);
      };
      sets.push_back(traceCurvatureLines(cloud, options, scaleProgress));
      const CurvatureLineSet& set = sets.back();
      std::size_t vertices = 0, closed = 0;
      double length = 0;
      for (const CurvatureLine& line : set.lines) {
        vertices += line.vertices.size();
        closed += line.closed;
        length += line.length();
      }
      perScale.push_back({{"scale", set.scale},
                          {"lines", set.lines.size()},
                          {"closed_lines", closed},
                          {"vertices", vertices},
                          {"total_length", length},
                          {"seeds", set.seeds},
                          {"samples", set.samples},
                          {"fits", set.fits},
                          {"way_stops", stopCounts(set)},
                          {"seconds", set.seconds}});
      if (!args->quiet)
        std::fprintf(stderr, "lines: t = %.6g: %zu lines, %zu vertices, %zu seeds, %.2f s\n",
                     set.scale, set.lines.size(), vertices, set.seeds, set.seconds);
    }
    const PolylineSet polylines = toPolylines(sets, cloud.origin());
    writePolylines(polylines, args->output, WriteOptions{args->ascii});
    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    const nlohmann::json json = {{"command", "lines"},
                                 {"version", SCALESPACE_VERSION},
                                 {"input", args->input.path},
                                 {"output", args->output},
                                 {"points", cloud.size()},
                                 {"parameters",
                                  {{"beta", options.beta},
                                   {"gamma", options.gamma},
                                   {"alpha", options.alpha},
                                   {"robust", options.fit.robust},
                                   {"max_steps", options.maxSteps},
                                   {"curved_seeds_first", options.curvedSeedsFirst},
                                   {"threads", args->threads}}},
                                 {"scales", perScale},
                                 {"seconds", total}};
    writeJson(summaryPathFor(args->output), json);
    if (!args->quiet)
      std::fprintf(stderr, "lines: %zu lines -> %s\n", polylines.lineCount(), args->output.c_str());
    reportDone("lines", start, args->quiet);
  });
}

// ---------------------------------------------------------------------------------- features
void addFeaturesCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, linesOutput;
    FeatureCurveOptions features;
    std::size_t samplesPerVertex = 100;
    double sheetNormals = kFeatureSheetNormals;
    std::string foldBorders = "auto";
    bool ascii = false, quiet = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "features",
      "feature curves by multi-scale voting of salient curvature lines (Sec. 3.4.1); a mesh "
      "input (.off .obj .stl, .ply with faces) labels its vertices");
  cmd->add_option("input", args->input.path, "input point cloud or mesh")->required();
  cmd->add_flag("--drop-invalid", args->input.dropInvalid,
                "skip points with NaN/Inf coordinates instead of failing");
  cmd->add_option("-o,--output", args->output,
                  "output cloud (input points or mesh vertices + feature_votes, curve_id, "
                  "convexity); a JSON summary is written beside it")
      ->required();
  cmd->add_option("--lines", args->linesOutput,
                  "also write the curvature lines of every scale (.ply or .obj; their k1 and "
                  "scale tell the salient ones)");
  cmd->add_option("--spacing", args->features.spacing,
                  "unit e of the scales and votes (0: mesh median edge length, or mean distance "
                  "to the 16th neighbour)")
      ->capture_default_str();
  cmd->add_option("--scales", args->features.scaleCount, "number of scales in [e, 3e]")
      ->capture_default_str();
  cmd->add_option("--salient", args->features.salientThreshold,
                  "salient vertices: |k1| > (1 - this) K, K the 90th percentile of |k1|")
      ->capture_default_str();
  cmd->add_option("--vote-threshold", args->features.voteThreshold,
                  "curves hold points with |votes| > this x the largest")
      ->capture_default_str();
  cmd->add_option("--salient-cap", args->features.salientBoundCap,
                  "salient vertices with |k1| t >= this pass whatever K is (0 = the thesis' "
                  "relative bound alone)")
      ->capture_default_str();
  cmd->add_option("--min-curvature", args->features.minSalientCurvature,
                  "salient vertices also have |k1| t >= this (0 = the thesis' rule alone)")
      ->capture_default_str();
  cmd->add_option("--noise-curvature", args->features.noiseSalientFactor,
                  "and |k1| t >= this x sigma / e, sigma the noise read from the points (0 = off)")
      ->capture_default_str();
  cmd->add_option("--min-scales", args->features.minVotingScales,
                  "points join curves only when this many scales voted for them (1 = the thesis)")
      ->capture_default_str();
  cmd->add_flag("--all-salient{false}", args->features.ridgeOnly,
                "vote with every salient vertex, not only the most curved across nearby lines "
                "(the thesis)");
  cmd->add_flag("--salient-per-scale{false}", args->features.salientBoundFromFinest,
                "take K at each scale (the thesis), not the finest scale's K t over t");
  cmd->add_option("--join-gap", args->features.joinGap,
                  "curves of one sign within this x e of each other are one curve (0 keeps the "
                  "pieces)")
      ->capture_default_str();
  cmd->add_option("--centreline-reach", args->features.centrelineReach,
                  "keep a curve's points near the centreline fitted to the salient vertices within "
                  "this x e (0 = the thesis' band: every point the votes reach)")
      ->capture_default_str();
  cmd->add_option("--edge-reach", args->features.edgeReach,
                  "edge_id splits each curve at its corners: points whose curve neighbours within "
                  "this x e do not lie along a line are corners (0: one edge per curve)")
      ->capture_default_str();
  cmd->add_option("--edge-rejoin-angle", args->features.edgeRejoinAngle,
                  "adjacent edges of a curve along one line (within this angle, degrees, in "
                  "[0, 90]) are joined again where no third edge meets them (0: never)")
      ->capture_default_str();
  cmd->add_option("--band-half-width", args->features.bandHalfWidth,
                  "the points kept lie within this x e of the centreline")
      ->capture_default_str();
  cmd->add_option("--crease-reach", args->features.creaseReach,
                  "where the points within this x e form two flat sides, the line where their "
                  "planes meet replaces the centreline (0: never)")
      ->capture_default_str();
  cmd->add_option("--crease-half-width", args->features.creaseHalfWidth,
                  "the points kept lie within this x e of that line")
      ->capture_default_str();
  cmd->add_option("--crease-flatness", args->features.creaseFlatness,
                  "a side is flat when its points lie within this x e (RMS; or twice the noise) "
                  "of its plane")
      ->capture_default_str();
  cmd->add_option("--crease-side-margin", args->features.creaseSideMargin,
                  "the sides are the points beyond this x e, less 3 noise RMS, of the plane "
                  "through the centreline that holds their mean normal")
      ->capture_default_str();
  cmd->add_flag("!--crease-sides-by-normals", args->features.creaseSidesByPosition,
                "tell the sides apart by their normals instead, which blend across the crease");
  cmd->add_flag("!--no-rim-lines", args->features.rimLines,
                "where no crease line is found, do not trim the band to the rim of a part "
                "thinner than the crease reach (its outermost points)");
  cmd->add_option("--min-extent", args->features.minCurveExtent,
                  "drop curves spanning less than this x e, after the joining (0 keeps all)")
      ->capture_default_str();
  cmd->add_option("--min-piece-extent", args->features.minPieceExtent,
                  "drop regions spanning less than this x e before the joining (0 keeps all)")
      ->capture_default_str();
  addSeedOrderFlag(*cmd, args->features.lines);
  cmd->add_option("--mesh-samples", args->samplesPerVertex,
                  "mesh inputs: sample this many points per vertex by area (Sec. 3.4.1: 100)")
      ->capture_default_str();
  cmd->add_option("--sheet-normals", args->sheetNormals,
                  "a cloud without normals: estimate each as the plane of the neighbours within "
                  "this x the 10th neighbour's distance (or 8 noise RMS) of one through the "
                  "point and two neighbours, one side's at a crease (0: PCA); oriented as "
                  "'normals --sign-by-rays --reflect' does")
      ->capture_default_str();
  cmd->add_option("--fold-borders", args->foldBorders,
                  "where the sampled surface is closed, its borders are folds thinner than the "
                  "noise (a thin part's rim) and join the convex curves: auto (a cloud whose "
                  "estimated normals' rays find it closed, or nearly closed with at least half "
                  "of the borders found seeing out on both sides), on, off (meshes: auto is off)")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  cmd->add_option("--fold-reach", args->features.foldReach,
                  "--fold-borders: the neighbourhood's radius, x e")
      ->capture_default_str();
  cmd->add_option("--fold-share", args->features.foldBorderShare,
                  "--fold-borders: a point is on a border when its neighbours' centroid lies "
                  "this x the radius off it in their plane (0.42 on a straight border)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    FeatureCurveOptions options = args->features;
    options.foldBorders = args->foldBorders == "on";
    validateFeatureCurveOptions(options);  // before the read
    if (args->samplesPerVertex < 1 || args->samplesPerVertex > 10000)
      throw OptionError("--mesh-samples must be in [1, 10000]");
    if (!(args->sheetNormals >= 0) || !std::isfinite(args->sheetNormals))
      throw OptionError("--sheet-normals must be finite and >= 0 (0: PCA normals)");
    std::vector<std::string> inputs{args->input.path};
    checkOutput(args->output, OutputKind::Cloud, inputs);
    if (!args->linesOutput.empty()) {
      checkOutput(args->linesOutput, OutputKind::Lines, inputs);
      checkSecondOutput(args->linesOutput, "--lines", args->output);
    }

    // A mesh is sampled by area (interpolated normals) and its vertices are labelled on its
    // edges; a cloud labels its own points on its k-NN graph. A mesh file without faces (an OFF
    // of vertices only, as CGAL's point sets) is a cloud.
    std::optional<TriangleMesh> faces = readFacesIfAny(args->input.path);
    const bool mesh = faces.has_value();
    PointCloud cloud, targets;
    FeatureCurveResult result;
    // The share of points whose rays see out on both sides, where `features` estimated the
    // normals (NormalOrientationResult::openShare); null in the summary otherwise.
    std::optional<double> openShare;
    const auto progress = makeProgressBar(args->quiet);
    if (mesh) {
      const TriangleMesh triangles = std::move(*faces);
      MeshFeatureCurves onMesh =
          detectMeshFeatureCurves(triangles, options, args->samplesPerVertex, progress);
      if (onMesh.coarse)
        printWarnings({"the mesh is coarse (median edge " + std::to_string(onMesh.curves.spacing) +
                       ", over 5% of its diagonal): the scales [e, 3e] are as large as its "
                       "faces; give a finer --spacing, or remesh it"});
      if (!args->quiet)
        std::fprintf(stderr, "%s: %zu vertices, %zu triangles, %zu samples, e = %.6g\n",
                     args->input.path.c_str(), triangles.vertices.size(),
                     triangles.triangles.size(), onMesh.samples.size(), onMesh.curves.spacing);
      targets.setAbsolutePositions(triangles.vertices);
      cloud = std::move(onMesh.samples);
      result = std::move(onMesh.curves);
    } else {
      cloud = loadCloud(args->input, args->quiet);
      const bool estimated = !cloud.hasNormals();
      const NormalOrientationResult orientation =
          ensureNormals(cloud, args->quiet, featureNormalOptions(args->sheetNormals));
      if (estimated) openShare = orientation.openShare;
      const bool automatic = args->foldBorders == "auto";
      if (automatic) chooseFoldBorders(options, orientation);
      result = detectFeatureCurves(cloud, options, progress);
      const std::string hint = foldBordersHint(orientation, result, "--fold-borders on");
      if (!args->quiet && automatic && !hint.empty())
        std::fprintf(stderr, "features: %s\n", hint.c_str());
      if (!args->quiet && result.foldsApplied)
        std::fprintf(stderr, "features: %s; %zu points on its borders (folds) joined the curves\n",
                     !automatic                  ? "--fold-borders on"
                     : orientation.closedSurface ? "the rays found the surface closed"
                                                 : "the rays found the surface nearly closed and "
                                                   "its borders thin",
                     result.foldPoints);
    }
    PointCloud& out = mesh ? targets : cloud;
    AttributeColumn& votes = out.addAttribute("feature_votes", ScalarType::Float32);
    votes.values = result.votes;
    AttributeColumn& ids = out.addAttribute("curve_id", ScalarType::Int32);
    AttributeColumn& convexity = out.addAttribute("convexity", ScalarType::Int8);
    AttributeColumn& edgeIds = out.addAttribute("edge_id", ScalarType::Int32);
    for (std::size_t i = 0; i < out.size(); ++i) {
      ids.values[i] = result.curveId[i];
      convexity.values[i] = result.convexity[i];
      edgeIds.values[i] = result.edgeId[i];
    }
    writeCloud(out, args->output, WriteOptions{args->ascii});
    if (!args->linesOutput.empty()) {
      // The salient part of the lines is what voted; the whole lines are written, with k1 and
      // the scale to tell them apart.
      writePolylines(toPolylines(result.lineSets, cloud.origin()), args->linesOutput,
                     WriteOptions{args->ascii});
    }

    nlohmann::json scales = nlohmann::json::array();
    for (const FeatureCurveScale& s : result.scales)
      scales.push_back({{"scale", s.scale},
                        {"salient_bound", s.salientBound},
                        {"vertex_bound", s.vertexBound},
                        {"lines", s.lines},
                        {"vertices", s.vertices},
                        {"salient_vertices", s.salientVertices}});
    nlohmann::json curves = nlohmann::json::array();
    std::size_t labelled = 0;
    for (std::size_t c = 0; c < result.curves.size(); ++c) {
      const FeatureCurve& curve = result.curves[c];
      labelled += curve.points.size();
      nlohmann::json voted = nlohmann::json::array();
      for (std::size_t s = 0; s < result.scales.size(); ++s)
        if (curve.scaleMask >> s & 1) voted.push_back(result.scales[s].scale);
      curves.push_back({{"id", c},
                        {"points", curve.points.size()},
                        {"length", curve.length},
                        {"convexity", curve.convexity > 0 ? "convex" : "concave"},
                        {"scales", voted}});
    }
    nlohmann::json edges = nlohmann::json::array();
    for (std::size_t k = 0; k < result.edges.size(); ++k)
      edges.push_back({{"id", k},
                       {"curve", result.edges[k].curve},
                       {"points", result.edges[k].points.size()},
                       {"length", result.edges[k].length}});
    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    const nlohmann::json openShareJson = openShare ? nlohmann::json(*openShare) : nullptr;
    const nlohmann::json seeThroughJson =
        result.foldSeeThrough >= 0 ? nlohmann::json(result.foldSeeThrough) : nullptr;
    const nlohmann::json json = {{"command", "features"},
                                 {"version", SCALESPACE_VERSION},
                                 {"input", args->input.path},
                                 {"output", args->output},
                                 {"labelled", mesh ? "mesh vertices" : "points"},
                                 {"points", out.size()},
                                 {"samples", cloud.size()},
                                 {"spacing", result.spacing},
                                 {"max_vote", result.maxVote},
                                 {"noise_rms", result.noiseRms},
                                 {"salient_curvature_floor", result.salientCurvatureFloor},
                                 {"feature_points", labelled},
                                 {"fold_points", result.foldPoints},
                                 {"rays_open_share", openShareJson},
                                 {"fold_see_through", seeThroughJson},
                                 {"parameters",
                                  {{"scale_count", options.scaleCount},
                                   {"salient_threshold", options.salientThreshold},
                                   {"salient_percentile", options.salientPercentile},
                                   {"salient_bound_from_finest", options.salientBoundFromFinest},
                                   {"salient_bound_cap", options.salientBoundCap},
                                   {"vote_threshold", options.voteThreshold},
                                   {"min_salient_curvature", options.minSalientCurvature},
                                   {"noise_salient_factor", options.noiseSalientFactor},
                                   {"min_voting_scales", options.minVotingScales},
                                   {"ridge_only", options.ridgeOnly},
                                   {"min_piece_extent", options.minPieceExtent},
                                   {"min_curve_extent", options.minCurveExtent},
                                   {"fold_borders", result.foldsApplied},
                                   {"fold_reach", options.foldReach},
                                   {"fold_border_share", options.foldBorderShare},
                                   {"join_gap", options.joinGap},
                                   {"centreline_reach", options.centrelineReach},
                                   {"band_half_width", options.bandHalfWidth},
                                   {"centreline_linearity", options.centrelineLinearity},
                                   {"crease_reach", options.creaseReach},
                                   {"crease_half_width", options.creaseHalfWidth},
                                   {"crease_flatness", options.creaseFlatness},
                                   {"crease_sides_by_position", options.creaseSidesByPosition},
                                   {"crease_side_margin", options.creaseSideMargin},
                                   {"rim_lines", options.rimLines},
                                   {"edge_reach", options.edgeReach},
                                   {"edge_rejoin_angle", options.edgeRejoinAngle},
                                   {"curved_seeds_first", options.lines.curvedSeedsFirst},
                                   {"threads", args->threads}}},
                                 {"scales", scales},
                                 {"curves", curves},
                                 {"edges", edges},
                                 {"seconds", total}};
    const std::string summaryPath = summaryPathFor(args->output);
    writeJson(summaryPath, json);
    if (!args->quiet)
      std::fprintf(stderr, "features: %zu curves, %zu of %zu %s labelled -> %s (summary %s)\n",
                   result.curves.size(), labelled, out.size(), mesh ? "vertices" : "points",
                   args->output.c_str(), summaryPath.c_str());
    reportDone("features", start, args->quiet);
  });
}

}  // namespace

void addFeatureCommands(CLI::App& app) {
  addLinesCommand(app);
  addFeaturesCommand(app);
}

}  // namespace scalespace::cli
