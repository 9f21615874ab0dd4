#include "scalespace/cli/ScalesCommands.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scalespace/cli/CliCommon.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/scales/ScaleStackCompute.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"

namespace scalespace::cli {
namespace {

// The PLY properties of `export --scale`, after x y z (the input positions) and nx ny nz.
struct ExportColumn {
  const char* name;
  float (*value)(const ScaleLayer&, std::size_t i, const Vec3& origin);
};

#define SS_VEC(field, k) \
  [](const ScaleLayer& L, std::size_t i, const Vec3&) { return L.field[3 * i + k]; }
#define SS_SCALAR(field) [](const ScaleLayer& L, std::size_t i, const Vec3&) { return L.field[i]; }
const ExportColumn kColumns[] = {
    {"curv_mean", SS_SCALAR(meanCurvature)},
    {"curv_max", SS_SCALAR(kMax)},
    {"curv_min", SS_SCALAR(kMin)},
    {"dir_max_x", SS_VEC(dirMax, 0)},
    {"dir_max_y", SS_VEC(dirMax, 1)},
    {"dir_max_z", SS_VEC(dirMax, 2)},
    {"dir_min_x", SS_VEC(dirMin, 0)},
    {"dir_min_y", SS_VEC(dirMin, 1)},
    {"dir_min_z", SS_VEC(dirMin, 2)},
    {"gls_tau", SS_SCALAR(tau)},
    {"gls_kappa", SS_SCALAR(kappa)},
    {"gls_fitness", SS_SCALAR(fitness)},
    {"anisotropy", SS_SCALAR(anisotropy)},
    {"geometric_variation", SS_SCALAR(geometricVariation)},
    {"neighbors",
     [](const ScaleLayer& L, std::size_t i, const Vec3&) { return float(L.neighbors[i]); }},
    {"fit_valid",
     [](const ScaleLayer& L, std::size_t i, const Vec3&) { return float(L.valid[i]); }},
    // Absolute projected position (float32 relative to the origin + origin; the PLY holds doubles).
    {"proj_x", nullptr},
    {"proj_y", nullptr},
    {"proj_z", nullptr},
};
#undef SS_VEC
#undef SS_SCALAR

/// One line per scale: t, samples, mean neighbours per projection, MLS steps, valid fits, and the
/// sampling and projection seconds (what `scales` prints at the end and `stack-info` shows).
std::string scaleTable(const std::vector<ScaleStats>& stats, std::size_t points) {
  std::string table =
      "  scale        t  samples  mean_nbrs  mls_steps  valid%  sample_s  project_s\n";
  for (std::size_t j = 0; j < stats.size(); ++j) {
    const ScaleStats& s = stats[j];
    char line[160];
    std::snprintf(line, sizeof line, "  %5zu %8.4g %8zu %10.1f %10.2f %7.2f %9.3f %10.3f\n", j, s.t,
                  s.samples, s.meanNeighbors, s.meanMlsSteps,
                  points ? 100.0 * double(s.validPoints) / double(points) : 0.0, s.samplingSeconds,
                  s.projectionSeconds);
    table += line;
  }
  return table;
}

void addScalesCommand(CLI::App& app) {
  struct Args {
    InputOptions input;
    std::string output, spacing = "log", estimator = "w3", encoding = "compact";
    ScaleSpaceOptions options;
    bool noRobust = false, quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "scales",
      "multi-scale, multi-resolution stack (Sec. 1.5): robust APSS projection of every "
      "point at M scales, written as NAME.stack/ (.npy files + manifest.json)");
  addInputOptions(*cmd, args->input);
  cmd->add_option("-o,--output", args->output, "output stack directory (NAME.stack)")->required();
  cmd->add_option("--scales", args->options.series.count, "number of scales M")
      ->capture_default_str();
  cmd->add_option("--spacing", args->spacing, "log (Eq. 1.40) | linear (Eq. 1.39)")
      ->capture_default_str();
  cmd->add_option("--tmin", args->options.series.tMin, "smallest scale (0 = median 10-NN distance)")
      ->capture_default_str();
  cmd->add_option("--tmax", args->options.series.tMax, "largest scale (0 = bounding-box diagonal)")
      ->capture_default_str();
  cmd->add_option("--alpha", args->options.alpha,
                  "Poisson-disk radius / scale (0 = keep all points)")
      ->capture_default_str();
  cmd->add_flag("--robust,!--no-robust", args->options.fit.robust,
                "robust APSS re-weighting (RIMLS, as the planes use; default off)");
  cmd->add_option("--mls-steps", args->options.fit.mlsMaxSteps, "MLS projection steps per scale")
      ->capture_default_str();
  cmd->add_option("--estimator", args->estimator, "w3 | w2 | w1 | plane | mean | quadric | jet")
      ->capture_default_str();
  cmd->add_option("--encoding", args->encoding,
                  "compact (quantised, ~19 bytes per point per scale) | float32 (83 bytes)")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.threads, "worker threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Poisson-disk sampling seed")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args] {
    const auto start = std::chrono::steady_clock::now();
    checkOutput(args->output, OutputKind::Stack, {args->input.path});
    ScaleSpaceOptions options = args->options;
    options.series.spacing = parseScaleSpacing(args->spacing);
    options.fit.estimator = parseEstimator(args->estimator);
    // Validate the options before the (possibly long) read.
    validateScaleSpaceOptions(options);
    StackWriteOptions write;
    write.encoding = parseStackEncoding(args->encoding);
    ThreadScope threads(options.threads);
    PointCloud cloud = loadCloud(args->input, args->quiet);
    ensureNormals(cloud, args->quiet);
    const ScaleSpaceSummary s =
        computeScaleStackToDisk(cloud, options, args->output, makeProgressBar(args->quiet), write);
    printWarnings(invalidFitWarnings(cloud, stackFitCounts(s, cloud.size(), options)));
    if (!args->quiet)
      std::fprintf(stderr, "%s%zu points x %zu scales (t = %.6g .. %.6g) -> %s\n",
                   scaleTable(s.stats, cloud.size()).c_str(), cloud.size(), s.series.scales.size(),
                   s.series.tMin, s.series.tMax, args->output.c_str());
    reportDone("scales", start, args->quiet);
  });
}

/// The attributes of `input` (the cloud the stack was computed on, checked point by point against
/// the stack's input positions) into `cloud`, in the input's order; a name that an exported
/// quantity takes is prefixed with "input_".
void addInputAttributes(const PointCloud& input, const std::string& inputPath,
                        const ScaleStackReader& reader, const std::string& stackPath,
                        PointCloud& cloud) {
  const std::vector<Vec3> positions = reader.inputPositions();
  const auto fix =
      "pass the cloud the stack was computed from (with --drop-invalid if `scales` "
      "had it)";
  if (input.size() != positions.size())
    throw FileError(inputPath, "",
                    "has " + std::to_string(input.size()) + " points but " + stackPath +
                        " was computed on " + std::to_string(positions.size()),
                    fix);
  // Equal up to the rounding of another file format's coordinates (a scan saved as LAS and PLY).
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!((input.absolutePosition(i) - positions[i]).norm() <=
          1e-9 * std::max(1.0, positions[i].norm())))
      throw FileError(
          inputPath, "",
          "point " + std::to_string(i) + " is not the stack's input point " + std::to_string(i),
          fix);
  for (const AttributeColumn& a : input.attributes()) {
    bool taken = false;
    for (const ExportColumn& c : kColumns) taken = taken || a.name == c.name;
    AttributeColumn& out = cloud.addAttribute(taken ? "input_" + a.name : a.name, a.type);
    out.values = a.values;
  }
}

void exportScale(const ScaleStackReader& reader, std::size_t j, const std::string& output,
                 const PointCloud* input, const std::string& inputPath,
                 const std::string& stackPath) {
  const ScaleLayer L = reader.readScale(j);
  const Vec3 origin = reader.info().origin;
  const std::size_t n = reader.pointCount();
  PointCloud cloud;
  cloud.setAbsolutePositions(reader.inputPositions());
  std::vector<Vec3> normals(n);
  for (std::size_t i = 0; i < n; ++i)
    normals[i] = Vec3(L.normal[3 * i], L.normal[3 * i + 1], L.normal[3 * i + 2]);
  cloud.setNormals(std::move(normals));
  // As in `curvature`: the input's own attributes first, then the scale's quantities.
  if (input) addInputAttributes(*input, inputPath, reader, stackPath, cloud);
  for (const ExportColumn& c : kColumns) {
    const bool isProj = c.value == nullptr;
    const bool isInt = std::string(c.name) == "neighbors" || std::string(c.name) == "fit_valid";
    AttributeColumn& col = cloud.addAttribute(c.name, isProj  ? ScalarType::Float64
                                                      : isInt ? ScalarType::Int32
                                                              : ScalarType::Float32);
    for (std::size_t i = 0; i < n; ++i) {
      if (isProj) {
        const int k = c.name[5] - 'x';
        col.values[i] = double(L.projection[3 * i + std::size_t(k)]) + origin[k];
      } else {
        col.values[i] = double(c.value(L, i, origin));
      }
    }
  }
  writeCloud(cloud, output);
}

void exportPoint(const ScaleStackReader& reader, std::size_t i, std::ostream& out) {
  const ScaleLayer S = reader.readPointSeries(i);
  const Vec3 origin = reader.info().origin;
  out << "scale,t,nx,ny,nz";
  for (const ExportColumn& c : kColumns) out << ',' << c.name;
  out << '\n' << std::setprecision(9);
  for (std::size_t j = 0; j < reader.scaleCount(); ++j) {
    out << j << ',' << reader.info().scales[j] << ',' << S.normal[3 * j] << ','
        << S.normal[3 * j + 1] << ',' << S.normal[3 * j + 2];
    for (const ExportColumn& c : kColumns) {
      if (c.value) {
        out << ',' << c.value(S, j, origin);
      } else {
        const int k = c.name[5] - 'x';
        out << ',' << std::setprecision(17)
            << double(S.projection[3 * j + std::size_t(k)]) + origin[k] << std::setprecision(9);
      }
    }
    out << '\n';
  }
}

void addExportCommand(CLI::App& app) {
  struct Args {
    std::string stack, output;
    InputOptions input;
    long long scale = -1, point = -1;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "export one scale of a stack as a cloud (PLY, input positions and order) or one "
      "point across scales as CSV");
  cmd->add_option("STACK", args->stack, "stack directory written by `scalespace scales`")
      ->required();
  auto* scale = cmd->add_option("--scale", args->scale, "scale index j (0-based)");
  auto* point = cmd->add_option("--point", args->point, "point index i (0-based, input order)");
  scale->excludes(point);
  cmd->add_option("-o,--output", args->output,
                  "output file (.ply for --scale; .csv for --point, stdout if omitted)");
  auto* input = cmd->add_option("--input", args->input.path,
                                "with --scale: the cloud the stack was computed on, whose own "
                                "attributes (colours, intensity, ...) are carried over");
  cmd->add_flag("--drop-invalid", args->input.dropInvalid,
                "with --input: skip points with NaN/Inf coordinates (as `scales` did)");
  cmd->add_flag("-q,--quiet", args->quiet, "no messages on stderr");
  cmd->callback([args, scale, point, input] {
    if (!*scale && !*point) throw OptionError("export needs --scale J or --point I");
    if (*input && !*scale) throw OptionError("--input goes with --scale");
    if (args->input.dropInvalid && !*input) throw OptionError("--drop-invalid goes with --input");
    ScaleStackReader reader(args->stack);
    if (*scale) {
      if (args->output.empty()) throw OptionError("export --scale needs -o OUT.ply");
      if (args->scale < 0) throw OptionError("--scale must be >= 0");
      checkOutput(args->output, OutputKind::Cloud, {args->stack, args->input.path});
      std::optional<PointCloud> cloud;
      if (*input) cloud = loadCloud(args->input, args->quiet);
      exportScale(reader, std::size_t(args->scale), args->output, cloud ? &*cloud : nullptr,
                  args->input.path, args->stack);
      if (!args->quiet)
        std::fprintf(stderr, "scale %lld -> %s\n", args->scale, args->output.c_str());
    } else {
      if (args->point < 0) throw OptionError("--point must be >= 0");
      if (args->output.empty()) {
        exportPoint(reader, std::size_t(args->point), std::cout);
      } else {
        checkOutput(args->output, OutputKind::Csv, {args->stack});
        writeFileAtomically(args->output, [&](std::ostream& out) {
          exportPoint(reader, std::size_t(args->point), out);
        });
      }
    }
  });
}

void addStackInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd =
      app.add_subcommand("stack-info", "describe a scale stack (scales, statistics, files)");
  cmd->add_option("STACK", *path, "stack directory")->required();
  cmd->callback([path] {
    if (printStackInfo(*path, std::cout)) return;
    // A manifest that is there but not recognised (damaged, or not a stack's): the reader says
    // what is wrong with it, as `export` does.
    std::error_code ec;
    if (std::filesystem::is_regular_file(std::filesystem::path(*path) / "manifest.json", ec)) {
      (void)ScaleStackReader(*path);
      throw FileError(*path, "", "not a scale stack (its manifest.json has no stack format tag)",
                      "give a NAME.stack directory written by 'scalespace scales'");
    }
    throw FileError(*path, "", "not a scale stack (no manifest.json)",
                    "give a NAME.stack directory");
  });
}

}  // namespace

bool printStackInfo(const std::string& path, std::ostream& out) {
  if (!isScaleStack(path)) return false;
  ScaleStackReader reader(path);
  const StackInfo& info = reader.info();
  out << path << ": scale stack (format " << info.formatVersion << ", scalespace "
      << info.programVersion << ")\n";
  char encoding[160];
  std::snprintf(encoding, sizeof encoding, "  encoding: %s, %.3f bytes per point per scale",
                stackEncodingName(info.encoding), info.bytesPerPointPerScale);
  out << encoding;
  if (info.encoding == StackEncoding::Compact)
    out << ", " << info.clampedValues << " values clamped (out of range when written)";
  out << "\n";
  out << "  points: " << info.pointCount << "\n  scales: " << info.scales.size()
      << " (t = " << info.scales.front() << " .. " << info.scales.back() << ")\n";
  out << "  input checksum: " << std::hex << std::setw(16) << std::setfill('0')
      << info.inputChecksum << std::dec << std::setfill(' ')
      << "\n  parameters: " << info.parametersJson << "\n";
  out << scaleTable(info.stats, info.pointCount);
  return true;
}

void addScalesCommands(CLI::App& app) {
  addScalesCommand(app);
  addExportCommand(app);
  addStackInfoCommand(app);
}

}  // namespace scalespace::cli
