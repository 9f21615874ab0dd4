#include "scalespace/cli/CliCommon.hpp"

#include <tbb/global_control.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "scalespace/cli/CylinderCommands.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/scales/ScaleStackWriter.hpp"

namespace scalespace::cli {

namespace {
// 100M points take ~10 GB through a fit; beyond, a typo (an extra zero) more likely than intent.
constexpr std::size_t kMaxMeshSamples = 100'000'000;
}  // namespace

void addInputOptions(CLI::App& command, InputOptions& input) {
  command
      .add_option("input", input.path,
                  "input point cloud (.ply .xyz .txt .csv .pts .pwn .off .obj .stl .las .pcd)")
      ->required()
      ->check(CLI::ExistingFile);
  command.add_flag("--drop-invalid", input.dropInvalid,
                   "skip points with NaN/Inf coordinates instead of stopping with an error");
  command
      .add_option("--sample", input.meshSamples,
                  "meshes (OFF, OBJ, STL, PLY with faces): N points sampled uniformly by area, "
                  "with interpolated normals (face normals at creases of 30 degrees or more when "
                  "the file has none) (default: the mesh vertices)")
      ->check(CLI::Range(std::size_t(1), kMaxMeshSamples));
}

PointCloud loadCloud(const InputOptions& input, bool quiet) {
  ReadOptions options;
  options.dropNonFinite = input.dropInvalid;
  options.meshSamples = input.meshSamples;
  if (input.meshSamples > 0) {
    const CloudFormat format = formatFromPath(input.path);
    if (!canHoldFaces(format))
      throw OptionError("--sample applies to meshes (.off .obj .stl, .ply with faces); " +
                        input.path + " is a " + formatName(format) + " point cloud");
  }
  ReadReport report;
  PointCloud cloud = readCloud(input.path, options, &report);
  if (cloud.empty())
    throw FileError(input.path, "", "the file holds no points", "nothing to analyse");
  if (!quiet && input.meshSamples == 0 && isMeshPath(input.path))
    std::fprintf(stderr,
                 "%s: a mesh, read as its %zu vertices (--sample N draws N points on its faces "
                 "instead)\n",
                 input.path.c_str(), cloud.size());
  if (!quiet && report.droppedNonFinite > 0)
    std::fprintf(stderr, "%s: skipped %zu points with NaN/Inf coordinates\n", input.path.c_str(),
                 report.droppedNonFinite);
  if (!quiet && report.unusableNormalsDropped)
    std::fprintf(stderr, "%s: every normal in the file is zero or NaN/Inf: read without normals\n",
                 input.path.c_str());
  return cloud;
}

void faceFileViewpoint(const PointCloud& cloud, NormalOrientationOptions& orientation) {
  if (!cloud.viewpoint() || orientation.method != OrientationMethod::MinimumSpanningTree) return;
  orientation.faceViewpoint = true;
  orientation.viewpoint = *cloud.viewpoint() - cloud.origin();  // recentred, as the points
}

NormalOrientationResult ensureNormals(PointCloud& cloud, bool quiet,
                                      const OrientedNormalsOptions& options) {
  if (cloud.hasNormals()) return {};
  const NormalEstimationOptions& estimation = options.estimation;
  if (!quiet)
    std::fprintf(stderr,
                 "input has no normals: estimating (%s, %zu neighbours, up to %zu under noise) and "
                 "orienting (MST%s%s)\n",
                 estimation.sheetTolerance > 0 ? "sheet planes" : "PCA", estimation.k,
                 std::max(estimation.k, estimation.maxK),
                 estimation.sheetTolerance <= 0               ? ""
                 : options.sheetSign == SheetSign::FromPlanes ? " of the PCA normals"
                 : options.sheetSign == SheetSign::ByRays
                     ? " of the sheet or the PCA normals, whichever the rays contradict less"
                     : "",
                 cloud.viewpoint() ? ", facing the file's viewpoint" : "");
  auto index = makeSpatialIndex(cloud.positions());
  OrientedNormalsOptions run = options;
  faceFileViewpoint(cloud, run.orientation);
  OrientedNormals normals =
      estimateOrientedNormals(cloud.positions(), *index, run, makeProgressBar(quiet));
  if (!quiet && normals.estimation.k != estimation.k)
    std::fprintf(stderr, "normals: noisy input, estimated over %zu neighbours\n",
                 normals.estimation.k);
  cloud.setNormals(std::move(normals.normals));
  NormalOrientationResult found = std::move(normals.orientation);
  found.reliable.clear();
  found.reliable.shrink_to_fit();
  return found;
}

namespace {

std::string lowerExtension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

bool isWithin(const std::filesystem::path& inner, const std::filesystem::path& outer) {
  const auto o = outer.begin(), oe = outer.end();
  auto i = inner.begin();
  for (auto it = o; it != oe; ++it, ++i)
    if (i == inner.end() || *i != *it) return false;
  return true;
}

// The files `planes`, `cylinders` and `scales` write into their folders.
bool isResultFile(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  for (const char* own : {"components.json", "components.csv", "outlines.obj", "persistence.svg",
                          "membership.bin", "cloud.ply", "axes.ply", "manifest.json"})
    if (name == own) return true;
  return path.extension() == ".npy";
}

}  // namespace

void checkOutput(const std::string& output, OutputKind kind,
                 const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (output.empty()) throw OptionError("the output path is empty");
  const fs::path out = fs::weakly_canonical(fs::absolute(output, ec), ec);
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    const fs::path in = fs::weakly_canonical(fs::absolute(input, ec), ec);
    if (in == out || (fs::exists(output, ec) && fs::equivalent(input, output, ec)))
      throw OptionError("output " + output + " is the input " + input +
                        ": choose another output name (inputs are never overwritten)");
    if (isWithin(in, out))
      throw OptionError("output " + output + " holds the input " + input +
                        ": choose another output (inputs are never overwritten)");
    // An input folder (a `planes` or `cylinders` result, a stack) may take the user's files, but
    // none of its own may be replaced: `segment P -o P/components.csv` overwrote the table.
    if (in != out && isWithin(out, in) && isResultFile(out))
      throw OptionError("output " + output + " is a file of the input " + input +
                        ": choose another output (inputs are never overwritten)");
  }
  const std::string ext = lowerExtension(output);
  const bool isFolder = kind == OutputKind::Stack || kind == OutputKind::PlanesResult ||
                        kind == OutputKind::CylindersResult;
  switch (kind) {
    case OutputKind::Cloud:
    case OutputKind::PointsWithNormals: {
      const std::string writable = std::string("write .ply, .xyz, .txt, .csv, .pts, ") +
                                   (kind == OutputKind::Cloud ? "" : ".pwn, ") + ".las or .pcd";
      CloudFormat format;
      try {
        format = formatFromPath(output);
      } catch (const Error&) {
        throw OptionError("output " + output + ": not a point cloud extension; " + writable);
      }
      if (isMeshFormat(format))
        throw OptionError("output " + output +
                          ": OFF, OBJ and STL are meshes and cannot hold a point cloud; " +
                          writable);
      if (kind == OutputKind::Cloud && ext == ".pwn")
        throw OptionError("output " + output +
                          ": a .pwn holds positions and normals only, and this command's result "
                          "is per-point columns; " +
                          writable);
      break;
    }
    case OutputKind::Png:
      if (ext != ".png")
        throw OptionError("output " + output + ": images are written as PNG; name it *.png");
      break;
    case OutputKind::Csv:
      if (ext != ".csv")
        throw OptionError("output " + output + ": this output is CSV text; name it *.csv");
      break;
    case OutputKind::Lines:
      if (ext != ".ply" && ext != ".obj")
        throw OptionError("output " + output + ": lines are written as .ply or .obj");
      break;
    case OutputKind::Stack:
      checkStackDestination(output);
      break;
    case OutputKind::PlanesResult:
      checkPlaneResultDestination(output);
      break;
    case OutputKind::CylindersResult:
      checkCylinderResultDestination(output);
      break;
  }
  if (!isFolder && fs::is_directory(output, ec))
    throw FileError(output, "", "is a folder", "give the path of a file to write");
  // The nearest existing folder above the output must take new files.
  fs::path parent = out.parent_path();
  while (!parent.empty() && !fs::exists(parent, ec) && parent != parent.root_path())
    parent = parent.parent_path();
  if (parent.empty()) parent = ".";
  if (!fs::is_directory(parent, ec))
    throw FileError(output, "", parent.string() + " is not a folder",
                    "choose an output inside a folder");
  if (::access(parent.c_str(), W_OK) != 0)
    throw FileError(output, "", "the folder " + parent.string() + " is not writable",
                    "choose another output folder or check its permissions");
}

void checkSecondOutput(const std::string& second, const std::string& flag,
                       const std::string& output) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path a = fs::weakly_canonical(fs::absolute(second, ec), ec);
  const fs::path b = fs::weakly_canonical(fs::absolute(output, ec), ec);
  if (a == b || (fs::exists(second, ec) && fs::equivalent(second, output, ec)))
    throw OptionError(flag + " " + second + " is the output " + output +
                      ": give each output its own name (one would replace the other)");
}

PointCloud loadResultInput(const std::string& recorded, const std::string& override,
                           const std::string& directory, const std::string& what,
                           std::size_t pointCount, const std::string& output, bool quiet) {
  InputOptions input;
  input.path = override.empty() ? recorded : override;
  std::error_code ec;
  if (override.empty() && !std::filesystem::is_regular_file(recorded, ec))
    throw FileError(recorded, "",
                    "the cloud the " + what + " in " + directory + " were computed on is not there",
                    "pass it with --input IN");
  if (!output.empty()) checkOutput(output, OutputKind::Cloud, {input.path, directory});
  PointCloud cloud = loadCloud(input, quiet);
  if (cloud.size() != pointCount)
    throw FileError(input.path, "",
                    "has " + std::to_string(cloud.size()) + " points but the " + what + " in " +
                        directory + " were computed on " + std::to_string(pointCount),
                    "pass the original cloud with --input");
  return cloud;
}

void printWarnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
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
