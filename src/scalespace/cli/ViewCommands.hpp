#pragma once
// `view`: the interactive exploration of Sec. 2.4 in the browser (the viewer layer's server).
#include <CLI/CLI.hpp>

namespace scalespace::cli {

void addViewCommand(CLI::App& app);

}  // namespace scalespace::cli
