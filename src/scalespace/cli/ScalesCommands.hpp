#pragma once
// `scales` (compute a multi-scale stack, Sec. 1.5), `export` (one scale as PLY, one point as CSV)
// and `stack-info`; printStackInfo lets `info` describe a stack too.
#include <CLI/CLI.hpp>
#include <ostream>
#include <string>

namespace scalespace::cli {

void addScalesCommands(CLI::App& app);

/// Prints a summary of the stack at `path`; returns false (printing nothing) when `path` is not a
/// stack directory. Throws FileError when it is one but is damaged.
bool printStackInfo(const std::string& path, std::ostream& out);

}  // namespace scalespace::cli
