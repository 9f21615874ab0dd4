#pragma once
// `info`, `generate`, `normals` and `curvature`: the per-point commands of Chapter 1.
#include <CLI/CLI.hpp>

namespace scalespace::cli {

void addCloudCommands(CLI::App& app);

}  // namespace scalespace::cli
