#pragma once
// Small pieces shared by the command files: loading with the common input options, output-path
// checks (inputs are never overwritten), the JSON summary written beside outputs, thread limits.
#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace scalespace::cli {

struct InputOptions {
  std::string path;
  bool dropInvalid = false;     // skip points with NaN/Inf coordinates instead of failing
  std::size_t meshSamples = 0;  // OFF/OBJ: sample this many points by area (0 = the vertices)
};

/// Adds the positional IN argument, --drop-invalid and --sample to `command`.
void addInputOptions(CLI::App& command, InputOptions& input);

/// Reads the cloud; throws if it has no points (nothing to analyse).
PointCloud loadCloud(const InputOptions& input, bool quiet);

/// Runs `analyse()`. When the input is a mesh read as its vertices and the analysis turns the
/// cloud down (OptionError: too few or too sparse points), the error ends with what to do about
/// it, since the start-up line that said so has usually scrolled away by then.
template <class Analyse>
auto withMeshSampleHint(const InputOptions& input, std::size_t pointCount, Analyse&& analyse) {
  try {
    return analyse();
  } catch (const OptionError& e) {
    if (input.meshSamples > 0 || !isMeshPath(input.path)) throw;
    throw OptionError(std::string(e.what()) + "; " + input.path + " is a mesh read as its " +
                      std::to_string(pointCount) +
                      " vertices: --sample N draws N points on its faces");
  }
}

/// The cloud a saved result (`planes`, `cylinders`) was computed on: `override` when given, else
/// `recorded` (the path the result names), checked to exist and to hold `pointCount` points, after
/// checkOutput(output) (the output is neither of them; "" for a command without an output, such
/// as `view`). `what` names the result in messages ("planes", "cylinders"). Throws FileError
/// naming the file and what to pass.
PointCloud loadResultInput(const std::string& recorded, const std::string& override,
                           const std::string& directory, const std::string& what,
                           std::size_t pointCount, const std::string& output, bool quiet);

/// MST orientation of a cloud whose file gave a viewpoint (a PCD's VIEWPOINT): each piece of the
/// tree faces it (NormalOrientationOptions::faceViewpoint).
void faceFileViewpoint(const PointCloud& cloud, NormalOrientationOptions& orientation);

/// Estimates (PCA, 10 neighbours; `estimation` widens it) and orients (MST, facing the file's
/// viewpoint if any) normals when the cloud has none; says so on stderr unless quiet. The APSS
/// fits need oriented normals. Returns what the orientation found (closedSurface: whether the
/// visibility rays found every component of the cloud closed); all false and 0 when the cloud had
/// normals.
NormalOrientationResult ensureNormals(PointCloud& cloud, bool quiet,
                                      const OrientedNormalsOptions& options = {});

/// What a command writes, for checkOutput.
enum class OutputKind {
  Cloud,              // a point cloud whose result is per-point columns (.ply .xyz .txt .csv .pts
                      // .las .pcd; not .pwn, which has no place for them)
  PointsWithNormals,  // positions and normals are the result (`normals`, `generate`): .pwn too
  Png,                // an image (.png)
  Csv,                // a table (.csv)
  Stack,              // a scale stack folder: replaces only an earlier stack
  PlanesResult,       // the planes' folder: new, empty, or an earlier result
  Lines,              // polylines (.ply with edges, .obj)
  CylindersResult     // the cylinders' folder: new, empty, or an earlier result
};

/// Checks an output before any work, so that a long run never fails at its end: the output is
/// none of `inputs` and holds none of them, its extension suits `kind`, an existing path may be
/// replaced (a file where a file goes; a folder only as OutputKind allows), and the nearest
/// existing folder above it is writable (missing folders are created when writing). Throws
/// OptionError or FileError naming the path.
void checkOutput(const std::string& output, OutputKind kind,
                 const std::vector<std::string>& inputs);

/// Refuses a second output (`flag`) that names the same file as the first one (-o), however the
/// two paths are spelled (./a.ply, a symlink): one file would silently replace the other.
void checkSecondOutput(const std::string& second, const std::string& flag,
                       const std::string& output);

/// "warning: ..." lines on stderr, also with --quiet: they are about the results, not progress.
void printWarnings(const std::vector<std::string>& warnings);

/// OUT.ply -> OUT.json
std::string summaryPathFor(const std::string& output);

/// Writes `summary` atomically (temp file + rename).
void writeJson(const std::string& path, const nlohmann::json& summary);

/// Limits TBB to `threads` worker threads for its lifetime (0 = all cores).
class ThreadScope {
 public:
  explicit ThreadScope(int threads);
  ~ThreadScope();
  ThreadScope(const ThreadScope&) = delete;
  ThreadScope& operator=(const ThreadScope&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scalespace::cli
