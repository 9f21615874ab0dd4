#include "scalespace/cli/ParamCommands.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/param/MeshlessDistortion.hpp"
#include "scalespace/param/Parametrization.hpp"

namespace scalespace::cli {
namespace {

using Clock = std::chrono::steady_clock;

/// The domain's coordinates as columns (what `distortion` and users read back).
void addDomainColumns(const DomainMap& domain, PointCloud& cloud) {
  const std::size_t n = cloud.size();
  if (domain.kind == DomainKind::Plane) {
    AttributeColumn& u = cloud.addAttribute("u", ScalarType::Float64);
    AttributeColumn& v = cloud.addAttribute("v", ScalarType::Float64);
    for (std::size_t i = 0; i < n; ++i) {
      u.values[i] = domain.uv[i].x();
      v.values[i] = domain.uv[i].y();
    }
    return;
  }
  const char* names[3] = {"s_x", "s_y", "s_z"};
  for (int c = 0; c < 3; ++c) {
    AttributeColumn& s = cloud.addAttribute(names[c], ScalarType::Float64);
    for (std::size_t i = 0; i < n; ++i) s.values[i] = domain.direction[i][c];
  }
  cloud.addAttribute("longitude", ScalarType::Float64).values = domain.longitude;
  cloud.addAttribute("latitude", ScalarType::Float64).values = domain.latitude;
}

/// The domain stored in a cloud's columns: u, v or s_x, s_y, s_z. FileError naming the file
/// otherwise.
DomainMap readDomainColumns(const PointCloud& cloud, const std::string& path) {
  const AttributeColumn* u = cloud.findAttribute("u");
  const AttributeColumn* v = cloud.findAttribute("v");
  const AttributeColumn* sx = cloud.findAttribute("s_x");
  const AttributeColumn* sy = cloud.findAttribute("s_y");
  const AttributeColumn* sz = cloud.findAttribute("s_z");
  std::vector<Vec2> uv;
  std::vector<Vec3> direction;
  if (u && v) {
    uv.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) uv[i] = Vec2(u->values[i], v->values[i]);
  } else if (sx && sy && sz) {
    direction.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
      direction[i] = Vec3(sx->values[i], sy->values[i], sz->values[i]);
  } else {
    throw FileError(path, "", "no parametrization columns (u v, or s_x s_y s_z)",
                    "pass the output of `scalespace parametrize`, or a cloud with such columns");
  }
  try {
    return domainFromCoordinates(uv, direction);
  } catch (const OptionError& e) {
    throw FileError(path, "", e.what());
  }
}

nlohmann::json vec(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

void addParametrizeCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, flattened, domain = "auto";
    ParametrizationOptions options;
    bool ascii = false, quiet = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "parametrize",
      "meshless parametrization (Sec. 4.3): the points flow onto their APSS while the scale "
      "grows, then onto one sphere or plane; writes u v (plane) or s_x s_y s_z longitude "
      "latitude (sphere) per point, with fold and overlap flags");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output,
                  "output cloud: the input's columns and the parametrization; a JSON summary "
                  "beside it")
      ->required();
  cmd->add_option("--scales", args->options.flattening.scaleCount,
                  "number of linear per-point scales (Eq. 1.39)")
      ->capture_default_str();
  cmd->add_option("--domain", args->domain,
                  "auto (plane when the points fit in a cap of 80 degrees) | plane | sphere")
      ->capture_default_str();
  cmd->add_option("--k", args->options.flattening.K,
                  "a point's first scale is its distance to its k-th neighbour")
      ->capture_default_str();
  cmd->add_option("--tmax", args->options.flattening.tMax,
                  "the last scale (0: the bounding-box diagonal)")
      ->capture_default_str();
  cmd->add_option("--alpha", args->options.flattening.alpha,
                  "pyramid decimation: samples at least 2 alpha t apart (Sec. 1.5.2)")
      ->capture_default_str();
  cmd->add_option("--relax", args->options.relaxation.iterations,
                  "beyond the thesis: local-global iterations per round that lower the "
                  "distortion of the domain (a sphere up to 100k points unless "
                  "--relax-large-spheres; 0: none, the thesis' map); not applied if it would add "
                  "folds or overlaps")
      ->capture_default_str();
  cmd->add_flag("--relax-large-spheres", args->options.relaxation.largeSpheres,
                "relax a sphere domain of more than 100k points too, on a subsample (slower: "
                "about +15 s at 1M points)");
  cmd->add_option("--relax-rounds", args->options.relaxation.rounds,
                  "robust re-weighting rounds of the relaxation (1: plain least squares, which "
                  "spreads a bump's misfit as shear over the whole map)")
      ->capture_default_str();
  cmd->add_option("--rigidity", args->options.relaxation.rigidity,
                  "how rigid the relaxation's local maps are on a plane domain: 1, rotations (as "
                  "rigid as possible: keeps lengths, so areas too, where the surface allows, and "
                  "gives the domain the surface's units); 0, similarities (angles only, areas "
                  "drift); between, a blend")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--sphere-rigidity", args->options.relaxation.sphereRigidity,
                  "the same on a sphere domain (a closed surface cannot keep its lengths there: "
                  "mostly conformal by default)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag_callback(
      "--rigid",
      [args] { args->options.relaxation.rigidity = args->options.relaxation.sphereRigidity = 1; },
      "rotations on both domains: --rigidity 1 --sphere-rigidity 1");
  cmd->add_flag_callback(
      "--conformal",
      [args] { args->options.relaxation.rigidity = args->options.relaxation.sphereRigidity = 0; },
      "similarities on both domains: --rigidity 0 --sphere-rigidity 0");
  cmd->add_option("--flattened", args->flattened,
                  "also write the flowed points, on their sphere or plane, to this cloud");
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    args->options.domain.kind = parseDomainKind(args->domain);
    validateFlatteningOptions(args->options.flattening);
    validateRelaxationOptions(args->options.relaxation);
    std::vector<std::string> inputs{args->input.path};
    checkOutput(args->output, OutputKind::Cloud, inputs);
    if (!args->flattened.empty()) {
      checkOutput(args->flattened, OutputKind::Cloud, inputs);
      checkSecondOutput(args->flattened, "--flattened", args->output);
    }
    PointCloud cloud = loadCloud(args->input, args->quiet);
    ensureNormals(cloud, args->quiet);
    const Parametrization result = parametrize(cloud.positions(), cloud.normals(), args->options,
                                               makeProgressBar(args->quiet));
    const std::size_t n = cloud.size();
    PointCloud out = cloud;
    addDomainColumns(result.domain, out);
    AttributeColumn& valid = out.addAttribute("param_valid", ScalarType::UInt8);
    AttributeColumn& fold = out.addAttribute("fold", ScalarType::UInt8);
    AttributeColumn& overlap = out.addAttribute("overlap", ScalarType::UInt8);
    AttributeColumn& scale = out.addAttribute("local_scale", ScalarType::Float32);
    for (std::size_t i = 0; i < n; ++i) {
      valid.values[i] = result.valid[i];
      fold.values[i] = result.defects.fold[i];
      overlap.values[i] = result.defects.overlap[i];
      scale.values[i] = result.defects.localScale[i];
    }
    writeCloud(out, args->output, WriteOptions{args->ascii});
    if (!args->flattened.empty()) {
      PointCloud flat;
      std::vector<Vec3> positions = result.flattening.positions;
      for (Vec3& p : positions) p += cloud.origin();
      flat.setAbsolutePositions(positions);
      flat.setNormals(result.flattening.normals);
      writeCloud(flat, args->flattened, WriteOptions{args->ascii});
    }

    const DomainMap& d = result.domain;
    const FlatteningResult& f = result.flattening;
    nlohmann::json steps = nlohmann::json::array();
    for (const FlatteningStep& s : f.steps)
      steps.push_back({{"t_median", s.tMedian},
                       {"samples", s.samples},
                       {"invalid", s.invalid},
                       {"mean_move", s.meanMove},
                       {"seconds", s.seconds}});
    nlohmann::json domain = {{"kind", domainKindName(d.kind)},
                             {"global_fit_is_plane", d.globalFitIsPlane},
                             {"cap_degrees", d.capDegrees},
                             {"empty_cap_degrees", d.emptyCapDegrees}};
    if (!d.globalFitIsPlane) {
      domain["centre"] = vec(d.centre + cloud.origin());
      domain["radius"] = d.radius;
    }
    if (d.kind == DomainKind::Plane) {
      domain["plane_u"] = vec(d.planeU);
      domain["plane_v"] = vec(d.planeV);
      if (!d.globalFitIsPlane) {
        domain["stereographic_pole"] = vec(d.pole);
        domain["stereographic_scale"] = d.stereographicScale;
      } else {
        domain["plane_origin"] = vec(d.planeOrigin + cloud.origin());
      }
    }
    const nlohmann::json json = {{"command", "parametrize"},
                                 {"version", SCALESPACE_VERSION},
                                 {"input", args->input.path},
                                 {"point_count", n},
                                 {"domain", domain},
                                 {"one_to_one", result.oneToOne},
                                 {"folds", result.defects.folds},
                                 {"overlaps", result.defects.overlaps},
                                 {"undetermined_local_maps", result.defects.undetermined},
                                 {"invalid_points", result.invalid},
                                 {"relaxation",
                                  {{"iterations", args->options.relaxation.iterations},
                                   {"rounds", args->options.relaxation.rounds},
                                   {"rigidity", args->options.relaxation.rigidity},
                                   {"sphere_rigidity", args->options.relaxation.sphereRigidity},
                                   {"solved_points", result.relaxation.solvedPoints},
                                   {"rounds_applied", result.relaxation.roundsApplied},
                                   {"applied", result.relaxation.applied},
                                   {"reason", result.relaxation.reason},
                                   {"seconds", result.relaxation.seconds}}},
                                 {"flattening",
                                  {{"scales", args->options.flattening.scaleCount},
                                   {"k", args->options.flattening.K},
                                   {"alpha", args->options.flattening.alpha},
                                   {"t_min_median", f.medianTMin},
                                   {"t_max", f.tMax},
                                   {"residual_before_global_fit", f.residual},
                                   {"steps", steps}}},
                                 {"warnings", result.warnings},
                                 {"seconds", f.seconds}};
    writeJson(summaryPathFor(args->output), json);
    printWarnings(result.warnings);
    if (!args->quiet)
      std::fprintf(stderr,
                   "parametrize: %zu points onto a %s (%s), %zu folds, %zu overlaps -> %s\n", n,
                   domainKindName(d.kind),
                   d.globalFitIsPlane ? "the global fit is a plane"
                                      : ("sphere of radius " + std::to_string(d.radius)).c_str(),
                   result.defects.folds, result.defects.overlaps, args->output.c_str());
    reportDone("parametrize", start, args->quiet);
  });
}

std::vector<int> parseSizes(const std::string& text) {
  std::vector<int> sizes;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    int k = 0;
    try {
      k = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      throw OptionError("DistortionOptions::neighbors: '" + item + "' is not an integer");
    sizes.push_back(k);
  }
  return sizes;
}

void addDistortionCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string parametrization, output, sizes = "16,64,256";
    bool ascii = false, quiet = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "distortion",
      "meshless distortion of a parametrization (Sec. 4.4): per point and neighbourhood size, "
      "the conformal and authalic distortions of Eq. 4.3-4.4, and the map's folds and overlaps");
  addInputOptions(*cmd, args->input);
  cmd->add_option("parametrization", args->parametrization,
                  "cloud with u v or s_x s_y s_z columns, same points in the same order (default: "
                  "the input itself, e.g. a `parametrize` output)");
  cmd->add_option("-o,--output", args->output,
                  "output cloud with eps_conf_kN and eps_auth_kN columns; a JSON summary beside it")
      ->required();
  cmd->add_option("--scales-k", args->sizes,
                  "neighbourhood sizes as neighbour counts, comma-separated")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_flag("--ascii", args->ascii, "write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on stderr");
  cmd->callback([args] {
    const auto start = Clock::now();
    ThreadScope threads(args->threads);
    DistortionOptions options;
    options.neighbors = parseSizes(args->sizes);
    validateDistortionOptions(options);
    std::vector<std::string> inputs{args->input.path};
    if (!args->parametrization.empty()) inputs.push_back(args->parametrization);
    checkOutput(args->output, OutputKind::Cloud, inputs);
    PointCloud cloud = loadCloud(args->input, args->quiet);
    DomainMap domain;
    if (args->parametrization.empty()) {
      domain = readDomainColumns(cloud, args->input.path);
    } else {
      InputOptions paramInput = args->input;
      paramInput.path = args->parametrization;
      const PointCloud param = loadCloud(paramInput, true);
      if (param.size() != cloud.size())
        throw FileError(args->parametrization, "",
                        "has " + std::to_string(param.size()) + " points, the input " +
                            std::to_string(cloud.size()),
                        "the parametrization must list the input's points in the same order");
      domain = readDomainColumns(param, args->parametrization);
    }
    ensureNormals(cloud, args->quiet);
    const ProgressCallback bar = makeProgressBar(args->quiet);
    const DistortionResult distortion =
        measureDistortion(cloud.positions(), cloud.normals(), domain, options, bar);
    const MapDefects defects = findMapDefects(cloud.positions(), cloud.normals(), domain);

    nlohmann::json sizes = nlohmann::json::array();
    for (const DistortionAtSize& s : distortion.sizes) {
      const std::string k = std::to_string(s.neighbors);
      AttributeColumn& conf = cloud.addAttribute("eps_conf_k" + k, ScalarType::Float32);
      AttributeColumn& auth = cloud.addAttribute("eps_auth_k" + k, ScalarType::Float32);
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        conf.values[i] = s.conformal[i];
        auth.values[i] = s.authalic[i];
      }
      sizes.push_back({{"neighbors", s.neighbors},
                       {"median_conformal", s.medianConformal},
                       {"p90_conformal", s.p90Conformal},
                       {"median_authalic", s.medianAuthalic},
                       {"p90_authalic", s.p90Authalic},
                       {"area_factor", s.areaFactor},
                       {"undetermined", s.undetermined}});
    }
    AttributeColumn& fold = cloud.addAttribute("fold", ScalarType::UInt8);
    AttributeColumn& overlap = cloud.addAttribute("overlap", ScalarType::UInt8);
    AttributeColumn& stretch = cloud.addAttribute("stretch", ScalarType::Float32);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      fold.values[i] = defects.fold[i];
      overlap.values[i] = defects.overlap[i];
      stretch.values[i] = defects.stretch[i];
    }
    writeCloud(cloud, args->output, WriteOptions{args->ascii});
    const nlohmann::json json = {
        {"command", "distortion"},
        {"version", SCALESPACE_VERSION},
        {"input", args->input.path},
        {"parametrization",
         args->parametrization.empty() ? args->input.path : args->parametrization},
        {"domain", domainKindName(domain.kind)},
        {"point_count", cloud.size()},
        {"area_normalisation",
         "one factor per size: the median of a3D / a2D (eps_auth = 1 at the median point)"},
        {"sizes", sizes},
        {"folds", defects.folds},
        {"overlaps", defects.overlaps},
        {"median_stretch", defects.medianStretch},
        {"p90_stretch", defects.p90Stretch},
        {"seconds", std::chrono::duration<double>(Clock::now() - start).count()}};
    writeJson(summaryPathFor(args->output), json);
    if (!args->quiet) {
      for (const DistortionAtSize& s : distortion.sizes)
        std::fprintf(stderr,
                     "distortion: k = %d: eps_conf median %.3f (90%% %.3f), eps_auth median %.3f "
                     "(90%% %.3f)\n",
                     s.neighbors, s.medianConformal, s.p90Conformal, s.medianAuthalic,
                     s.p90Authalic);
      std::fprintf(stderr,
                   "distortion: local maps' stretch median %.3f (90%% %.3f); %zu folds, %zu "
                   "overlaps -> %s\n",
                   defects.medianStretch, defects.p90Stretch, defects.folds, defects.overlaps,
                   args->output.c_str());
    }
    reportDone("distortion", start, args->quiet);
  });
}

}  // namespace

void addParamCommands(CLI::App& app) {
  addParametrizeCommand(app);
  addDistortionCommand(app);
}

}  // namespace scalespace::cli
