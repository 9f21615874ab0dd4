#pragma once
// `lines` and `features`: the curvature lines and feature curves of Chapter 3 (Sec. 3.3-3.4).
#include <CLI/CLI.hpp>

namespace scalespace::cli {

void addFeatureCommands(CLI::App& app);

}  // namespace scalespace::cli
