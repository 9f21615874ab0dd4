#pragma once
// `parametrize` and `distortion`: the meshless parametrization of Chapter 4 and its distortion.
#include <CLI/CLI.hpp>

namespace scalespace::cli {

void addParamCommands(CLI::App& app);

}  // namespace scalespace::cli
