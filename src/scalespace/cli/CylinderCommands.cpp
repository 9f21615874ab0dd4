#include "scalespace/cli/CylinderCommands.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/features/CylinderDetection.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/planes/PlaneExport.hpp"

namespace scalespace::cli {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// The marker that tells our folder from a user's: components.json names the result.
constexpr const char* kResultTag = "\"result\":\"cylinders\"";

nlohmann::json point(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

// The axes of the components (their representative tubes) as polylines with the radius profile.
PolylineSet axesOf(const CylinderDetection& detection, const Vec3& origin) {
  PolylineSet out;
  std::vector<Vec3> positions;
  std::vector<double> ids, radii;
  for (const CylinderComponent& c : detection.components) {
    if (c.tube.axis.size() < 2) continue;
    for (std::size_t k = 0; k < c.tube.axis.size(); ++k) {
      positions.push_back(c.tube.axis[k]);
      ids.push_back(c.id);
      radii.push_back(c.tube.radii[k]);
    }
    out.offsets.push_back(positions.size());
  }
  out.vertices.setRelativePositions(std::move(positions), origin);
  out.vertices.addAttribute("component", ScalarType::Int32).values = std::move(ids);
  out.vertices.addAttribute("radius", ScalarType::Float32).values = std::move(radii);
  return out;
}

void writeComponentsCsv(const CylinderDetection& detection, const Vec3& origin,
                        const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "id,birth_level,birth_scale,death_level,death_scale,persistence,representative_scale,"
           "point_count,straight,radius,radius_start,radius_end,rms,length,arc_degrees,dx,dy,dz,"
           "cx,cy,cz,gap_levels\n";
    out.precision(9);
    for (const CylinderComponent& c : detection.components) {
      const TubeFit& t = c.tube;
      const Vec3 centre = t.centre + origin;
      out << c.id << ',' << c.birthLevel << ',' << c.birthScale << ',' << c.deathLevel << ','
          << c.deathScale << ',' << c.persistence << ','
          << detection.levels[std::size_t(c.representativeLevel)].scale << ',' << t.pointCount
          << ',' << (t.straight ? 1 : 0) << ',' << t.radius << ',' << t.radii.front() << ','
          << t.radii.back() << ',' << t.rms << ',' << t.length << ',' << t.arcDegrees;
      if (t.straight)
        out << ',' << t.direction.x() << ',' << t.direction.y() << ',' << t.direction.z() << ','
            << centre.x() << ',' << centre.y() << ',' << centre.z();
      else
        out << ",,,,,,";  // a bent tube has no straight axis
      out << ',' << c.gapLevels << '\n';
    }
  });
}

nlohmann::json componentsJson(const CylinderDetection& detection, const Vec3& origin) {
  nlohmann::json components = nlohmann::json::array();
  for (const CylinderComponent& c : detection.components) {
    const TubeFit& t = c.tube;
    nlohmann::json axis = nlohmann::json::array();
    for (const Vec3& p : t.axis) axis.push_back(point(p + origin));
    nlohmann::json item = {{"id", c.id},
                           {"birth_level", c.birthLevel},
                           {"birth_scale", c.birthScale},
                           {"death_level", c.deathLevel},
                           {"death_scale", c.deathScale},
                           {"gap_levels", c.gapLevels},
                           {"persistence", c.persistence},
                           {"representative_level", c.representativeLevel},
                           {"point_count", t.pointCount},
                           {"straight", t.straight},
                           {"radius", t.radius},
                           {"rms", t.rms},
                           {"length", t.length},
                           {"arc_degrees", t.arcDegrees},
                           {"sector_fill", t.sectorFill},
                           {"section_shape", t.sectionShapeShare},
                           {"face_sectors", t.faceSectors},
                           {"normal_lean", t.normalLean},
                           {"axis", axis},
                           {"radii", t.radii}};
    if (t.straight) {  // the straight axis means nothing for a bent tube
      item["direction"] = point(t.direction);
      item["centre"] = point(t.centre + origin);
    }
    components.push_back(std::move(item));
  }
  return components;
}

void addCylindersCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output;
    CylinderOptions cylinders;
    double scale = 0;
    int minPersistence = 0;
    bool ascii = false, quiet = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "cylinders",
      "cylinders across scales (Sec. 3.5): regular minimal-curvature lines, their anisotropy, "
      "region growing, a tube per region (curved axis, radius profile), linked across scales "
      "into persistent components");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output,
                  "output folder: cloud.ply (cylinder_id, anisotropy), components.json / .csv, "
                  "axes.ply, membership.bin (for cylinders-segment)")
      ->required();
  cmd->add_option("--scales", args->cylinders.scaleCount, "number of log-spaced scales")
      ->capture_default_str();
  cmd->add_option("--tmin", args->cylinders.tMin,
                  "smallest scale (0: twice the median distance to the 10th neighbour)")
      ->capture_default_str();
  cmd->add_option("--tmax", args->cylinders.tMax, "largest scale (0: a tenth of the diagonal)")
      ->capture_default_str();
  const CLI::Option* scaleOption = cmd->add_option(
      "--scale", args->scale,
      "label the points with the components at the scale nearest to this (default: the most "
      "persistent component holding each point)");
  cmd->add_option("--min-persistence", args->minPersistence,
                  "label only components living at least this many scale steps")
      ->capture_default_str();
  cmd->add_option("--epsilon", args->cylinders.epsilon,
                  "region growing tolerance of Eq. 3.10 on anisotropy, directions and normals")
      ->capture_default_str();
  cmd->add_option("--min-line-length", args->cylinders.filter.minLengthFactor,
                  "keep the minimal-curvature lines at least this many times the scale t long "
                  "(L of Eq. 3.5)")
      ->capture_default_str();
  cmd->add_option("--max-line-curvature", args->cylinders.filter.maxCurvatureFactor,
                  "keep the lines whose total curvature (K of Eq. 3.6, radians) is at most this "
                  "x their length / t")
      ->capture_default_str();
  cmd->add_option("--max-line-variation", args->cylinders.filter.maxMeanVariation,
                  "keep the lines whose total geometric variation (V of Eq. 3.7) is at most this "
                  "x their vertex count: the mean tanh(nu) over the line")
      ->capture_default_str();
  cmd->add_option("--min-anisotropy", args->cylinders.minAnisotropy,
                  "points join regions only with at least this line anisotropy")
      ->capture_default_str();
  cmd->add_option("--min-arc", args->cylinders.tube.minArcDegrees,
                  "a tube's points' normals must turn at least this much around its axis")
      ->capture_default_str();
  cmd->add_option("--min-sector-fill", args->cylinders.tube.minSectorFill,
                  "a tube's normals must fill at least this share of the 10-degree sectors of "
                  "the arc its points cover (0 to 1; a box edge rounded into a tube fills about "
                  "half)")
      ->capture_default_str();
  cmd->add_option("--max-section-shape", args->cylinders.tube.maxSectionShapeShare,
                  "turn down a straight tube when more than this share of its points' spread "
                  "about it is a section shape fixed along its axis and that shape's RMS is over "
                  "--max-section-shape-rms (a noisy box's faces: 0.23 and more; real table legs "
                  "read 0.25-0.68 too; 1: off)")
      ->capture_default_str();
  cmd->add_option("--max-section-shape-rms", args->cylinders.tube.maxSectionShapeRms,
                  "with --max-section-shape: the shape's RMS must also be over this x the "
                  "radius (a noisy box: 0.08 and more; a stereo scan's mug wall: 0.03)")
      ->capture_default_str();
  cmd->add_option("--max-face-sectors", args->cylinders.tube.maxFaceSectors,
                  "turn down a tube whose normals turn less than half as far as its points over "
                  "more than this many neighbouring 10-degree sectors round its axis (a prism's "
                  "face), with --min-face-lean (36: off)")
      ->capture_default_str();
  cmd->add_option("--min-face-lean", args->cylinders.tube.minFaceLeanDegrees,
                  "with --max-face-sectors: the RMS of the sectors' mean lean of the normals from "
                  "the radial must also be at least this (degrees; a noisy box: 14 and more, "
                  "pipes and a cable's strands: under 9)")
      ->capture_default_str();
  cmd->add_option("--max-rms", args->cylinders.tube.maxRelativeRms,
                  "a tube's RMS distance to its surface is at most this x its radius")
      ->capture_default_str();
  cmd->add_option("--max-gap", args->cylinders.maxGapLevels,
                  "a component bridges up to this many scales where its tube was not found (0: "
                  "consecutive scales only, as the thesis)")
      ->capture_default_str();
  cmd->add_option("--bridge-radius-tolerance", args->cylinders.bridgeRadiusTolerance,
                  "the tubes on both sides of such a gap agree in radius within this share of "
                  "the larger (a real tube's fitted radius grows with the scale)")
      ->capture_default_str();
  cmd->add_option("--nested-link-tolerance", args->cylinders.nestedLinkTolerance,
                  "tubes of two scales that fail the Jaccard rule but one of which holds over half "
                  "of the other's points, the smaller at least a quarter the size, are one "
                  "component when the smaller one's points lie on the larger one's tube within "
                  "this share of its radius (median; 0: off): a scale that finds a piece of a tube "
                  "the next finds whole; narrow tubes whose points lie on one tube are kept too")
      ->capture_default_str();
  cmd->add_flag("--one-curvature-sign", args->cylinders.oneCurvatureSign,
                "a region only grows over points curving the way its seed does, which stops it at "
                "the groove between a noisy cable's strands; needs consistently oriented normals");
  cmd->add_flag("!--no-axis-split", args->cylinders.split.enabled,
                "do not split a region whose points' curvature reads tubes thinner than its own "
                "by the axes they propose (the strands of a noisy cable grown into one region)");
  cmd->add_flag("!--no-junction-trim", args->cylinders.trim.enabled,
                "do not trim a region turned down as no tube, or a tube partly curving against "
                "itself, to its points curving one way and fit it again (a cylinder standing on a "
                "plane, grown out onto the plane over the junction)");
  cmd->add_flag("!--no-narrow-tubes", args->cylinders.narrow.enabled,
                "do not keep regions turned down for their arc alone (seen over 75 degrees or "
                "more) that are found with the same radius at 3 or more scales (a cylinder seen "
                "from one side)");
  cmd->add_option("--trim-keep-fraction", args->cylinders.trim.keepFraction,
                  "the trimming keeps the points curving the way most of a region's do by at "
                  "least this share of their median |kappa1| t")
      ->capture_default_str();
  cmd->add_option("--trim-min-radius", args->cylinders.trim.minRadiusScales,
                  "a trimmed region replaces its region only as a tube of radius at least this "
                  "many times the scale t (a box edge trimmed of its faces is a tube of the scale)")
      ->capture_default_str();
  cmd->add_option("--trim-against-share", args->cylinders.trim.tubeMinAgainstShare,
                  "a tube is trimmed too when at least this share of its points curve against it")
      ->capture_default_str();
  cmd->add_option("--narrow-min-arc", args->cylinders.narrow.minArcDegrees,
                  "degrees the normals of a region turned down for its arc alone must still turn "
                  "for it to be kept as a narrow tube")
      ->capture_default_str();
  cmd->add_option("--narrow-min-persistence", args->cylinders.narrow.minPersistence,
                  "a component of narrow tubes alone is kept when it is found at scales at least "
                  "this many steps apart (bridged gaps counted; radii as --narrow-radius-spread)")
      ->capture_default_str();
  cmd->add_option("--narrow-radius-spread", args->cylinders.narrow.maxRadiusSpread,
                  "the radii of a component of narrow tubes alone must lie within this share of "
                  "one another (the radius of a tube the scale makes grows with t), unless its "
                  "points lie on one tube (--nested-link-tolerance)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args, scaleOption] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    validateCylinderOptions(args->cylinders);
    // Given, it must be a scale: 0 is no "unset" (it used to fall back to the persistence labels).
    const bool atScale = scaleOption->count() > 0;
    if (atScale && !(args->scale > 0 && std::isfinite(args->scale)))
      throw OptionError("--scale must be finite and > 0");
    if (args->minPersistence < 0) throw OptionError("--min-persistence must be >= 0");
    checkOutput(args->output, OutputKind::CylindersResult, {args->input.path});
    PointCloud cloud = loadCloud(args->input, args->quiet);
    ensureNormals(cloud, args->quiet, cylinderNormalOptions());
    const CylinderDetection detection = withMeshSampleHint(args->input, cloud.size(), [&] {
      return detectCylinders(cloud, args->cylinders, makeProgressBar(args->quiet));
    });

    int level = -1;
    std::vector<int> labels;
    if (atScale) {
      level = nearestCylinderLevel(detection, args->scale);
      labels = cylinderLabelsAtLevel(detection, level, args->minPersistence);
    } else {
      labels = cylinderLabelsByPersistence(detection, args->minPersistence);
    }
    // Anisotropy at the chosen scale, or the largest over the scales; -1 where no line passed.
    std::vector<double> anisotropy(cloud.size(), -1.0);
    for (int j = 0; j < detection.scaleCount(); ++j) {
      if (level >= 0 && j != level) continue;
      const std::vector<float>& sigma = detection.levels[std::size_t(j)].anisotropy;
      for (std::size_t i = 0; i < cloud.size(); ++i)
        if (std::isfinite(sigma[i])) anisotropy[i] = std::max(anisotropy[i], double(sigma[i]));
    }
    std::size_t labelled = 0;
    AttributeColumn& ids = cloud.addAttribute("cylinder_id", ScalarType::Int32);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ids.values[i] = labels[i];
      labelled += labels[i] >= 0;
    }
    cloud.addAttribute("anisotropy", ScalarType::Float32).values = std::move(anisotropy);

    std::error_code ec;
    fs::create_directories(args->output, ec);
    if (ec) throw FileError(args->output, "", "cannot create the folder: " + ec.message());
    const fs::path dir(args->output);
    writeCloud(cloud, (dir / "cloud.ply").string(), WriteOptions{args->ascii});
    writePolylines(axesOf(detection, cloud.origin()), (dir / "axes.ply").string(),
                   WriteOptions{args->ascii});
    writeComponentsCsv(detection, cloud.origin(), (dir / "components.csv").string());
    // What `cylinders-segment` reloads to answer other queries without recomputing.
    writeMembership(pointMembership(detection.graph), (dir / "membership.bin").string());
    nlohmann::json levels = nlohmann::json::array();
    for (const CylinderLevel& l : detection.levels) {
      nlohmann::json rejected = nlohmann::json::object();
      for (std::size_t k = 1; k < l.rejections.size(); ++k)
        rejected[tubeRejectionName(TubeRejection(k))] = l.rejections[k];
      levels.push_back({{"scale", l.scale},
                        {"rejected", rejected},
                        {"lines", l.lines},
                        {"regular_lines", l.regularLines},
                        {"regions", l.regions},
                        {"tubes", l.tubes.size()},
                        {"seconds", l.seconds}});
    }
    const CylinderOptions& o = args->cylinders;
    // Absolute, as `planes` records it: cylinders-segment finds it from any folder.
    const std::string inputPath = fs::absolute(args->input.path, ec).string();
    const nlohmann::json json = {
        {"result", "cylinders"},
        {"version", SCALESPACE_VERSION},
        {"input", inputPath},
        {"point_count", cloud.size()},
        {"labels",
         {{"scale", level >= 0 ? nlohmann::json(detection.levels[std::size_t(level)].scale)
                               : nlohmann::json("most persistent")},
          {"min_persistence", args->minPersistence},
          {"labelled_points", labelled}}},
        {"parameters",
         {{"epsilon", o.epsilon},
          {"min_anisotropy", o.minAnisotropy},
          {"min_length_factor", o.filter.minLengthFactor},
          {"max_curvature_factor", o.filter.maxCurvatureFactor},
          {"max_mean_variation", o.filter.maxMeanVariation},
          {"min_arc_degrees", o.tube.minArcDegrees},
          {"min_sector_fill", o.tube.minSectorFill},
          {"max_section_shape_share", o.tube.maxSectionShapeShare},
          {"max_section_shape_rms", o.tube.maxSectionShapeRms},
          {"max_face_sectors", o.tube.maxFaceSectors},
          {"min_face_lean_degrees", o.tube.minFaceLeanDegrees},
          {"max_relative_rms", o.tube.maxRelativeRms},
          {"max_gap_levels", o.maxGapLevels},
          {"bridge_radius_tolerance", o.bridgeRadiusTolerance},
          {"nested_link_tolerance", o.nestedLinkTolerance},
          {"axis_split", o.split.enabled},
          {"junction_trim", o.trim.enabled},
          {"trim_keep_fraction", o.trim.keepFraction},
          {"trim_min_radius", o.trim.minRadiusScales},
          {"trim_against_share", o.trim.tubeMinAgainstShare},
          {"narrow_tubes", o.narrow.enabled},
          {"narrow_min_arc", o.narrow.minArcDegrees},
          {"narrow_min_persistence", o.narrow.minPersistence},
          {"narrow_radius_spread", o.narrow.maxRadiusSpread},
          {"curved_seeds_first", o.lines.curvedSeedsFirst},
          {"threads", args->threads}}},
        {"levels", levels},
        {"components", componentsJson(detection, cloud.origin())},
        {"seconds", detection.seconds}};
    // Compact: the tag is then found as written (isCylinderResult).
    const std::string text = json.dump();
    writeFileAtomically((dir / "components.json").string(),
                        [&](std::ostream& out) { out << text << '\n'; });
    if (!args->quiet)
      std::fprintf(stderr,
                   "cylinders: %zu components over %d scales, %zu of %zu points labelled -> %s\n",
                   detection.components.size(), detection.scaleCount(), labelled, cloud.size(),
                   args->output.c_str());
    reportDone("cylinders", start, args->quiet);
  });
}

void addCylindersSegmentCommand(CLI::App& app) {
  struct Args {
    std::string directory, output, input;
    int minPersistence = 0;
    double scale = 0;
    bool ascii = false, quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "cylinders-segment",
      "label points with the cylinders of a `cylinders` folder, without recomputing them: the "
      "most persistent component per point, or the components at one scale");
  cmd->add_option("directory", args->directory, "output folder of `scalespace cylinders`")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--output", args->output, "output cloud (input points + cylinder_id)")
      ->required();
  cmd->add_option("--min-persistence", args->minPersistence,
                  "label only components living at least this many scale steps")
      ->capture_default_str();
  auto* scale =
      cmd->add_option("--scale", args->scale, "the components at the computed scale nearest to T");
  cmd->add_option("--input", args->input,
                  "the cloud the cylinders were computed on (default: the one recorded in DIR)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args, scale] {
    const auto start = Clock::now();
    if (args->minPersistence < 0) throw OptionError("--min-persistence must be >= 0");
    if (!isCylinderResult(args->directory))
      throw FileError(args->directory, "", "holds no cylinders result (components.json)",
                      "give the output folder of `scalespace cylinders`");
    const fs::path dir(args->directory);
    nlohmann::json result;
    {
      std::ifstream in(dir / "components.json");
      result = nlohmann::json::parse(in, nullptr, false);
    }
    if (result.is_discarded() || !result.contains("levels") || !result.contains("components"))
      throw FileError((dir / "components.json").string(), "", "is not a cylinders result",
                      "run `scalespace cylinders` again");
    std::vector<double> scales;
    std::vector<int> persistence;
    for (const auto& level : result["levels"]) scales.push_back(level["scale"].get<double>());
    for (const auto& c : result["components"]) persistence.push_back(c["persistence"].get<int>());
    const PointMembership membership = readMembership((dir / "membership.bin").string());
    if (membership.levelCount != int(scales.size()))
      throw FileError((dir / "membership.bin").string(), "",
                      "does not match components.json (" + std::to_string(membership.levelCount) +
                          " levels against " + std::to_string(scales.size()) + ")",
                      "run `scalespace cylinders` again");
    for (const int id : membership.ids)
      if (id >= int(persistence.size()))
        throw FileError(
            (dir / "membership.bin").string(), "",
            "names component " + std::to_string(id) + " of " + std::to_string(persistence.size()),
            "run `scalespace cylinders` again");
    PointCloud cloud =
        loadResultInput(result.value("input", std::string()), args->input, args->directory,
                        "cylinders", membership.pointCount, args->output, args->quiet);
    const std::vector<int> labels =
        *scale ? labelsAtLevel(membership, persistence, nearestScaleIndex(scales, args->scale),
                               args->minPersistence)
               : labelsByPersistence(membership, persistence, args->minPersistence);
    std::size_t labelled = 0;
    AttributeColumn& ids = cloud.addAttribute("cylinder_id", ScalarType::Int32);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ids.values[i] = labels[i];
      labelled += labels[i] >= 0;
    }
    writeCloud(cloud, args->output, WriteOptions{args->ascii});
    if (!args->quiet)
      std::fprintf(stderr, "cylinders-segment: %zu of %zu points labelled -> %s\n", labelled,
                   cloud.size(), args->output.c_str());
    reportDone("cylinders-segment", start, args->quiet);
  });
}

}  // namespace

bool isCylinderResult(const std::string& directory) {
  std::ifstream in(fs::path(directory) / "components.json");
  std::stringstream text;
  text << in.rdbuf();
  return in && text.str().find(kResultTag) != std::string::npos;
}

void checkCylinderResultDestination(const std::string& directory) {
  std::error_code ec;
  if (!fs::exists(directory, ec)) return;
  if (!fs::is_directory(directory, ec))
    throw FileError(directory, "", "exists and is not a folder",
                    "choose another output folder for the cylinders");
  if (!fs::is_empty(directory, ec) && !isCylinderResult(directory))
    throw FileError(directory, "",
                    "is a folder that holds other files and no cylinders result: refusing to "
                    "write into it",
                    "choose a new or empty output folder");
}

void addCylinderCommands(CLI::App& app) {
  addCylindersCommand(app);
  addCylindersSegmentCommand(app);
}

}  // namespace scalespace::cli
