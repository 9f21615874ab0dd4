#pragma once
// Small pieces shared by the command files: loading with the common input options, output-path
// checks (inputs are never overwritten), the JSON summary written beside outputs, thread limits.
#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::cli {

struct InputOptions {
  std::string path;
  bool dropInvalid = false;  // skip points with NaN/Inf coordinates instead of failing
};

/// Adds the positional IN argument and --drop-invalid to `command`.
void addInputOptions(CLI::App& command, InputOptions& input);

/// Reads the cloud; throws if it has no points (nothing to analyse).
PointCloud loadCloud(const InputOptions& input, bool quiet);

/// Estimates (PCA, 10 neighbours) and orients (MST) normals when the cloud has none; says so on
/// stderr unless quiet. The APSS fits need oriented normals.
void ensureNormals(PointCloud& cloud, bool quiet);

/// Throws OptionError when `output` names the same file as `input` (we never overwrite inputs).
void checkOutputPath(const std::string& input, const std::string& output);

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
