#pragma once
// `cylinders`: cylinders across scales (Sec. 3.5, with the persistence of Ch. 2).
#include <CLI/CLI.hpp>

namespace scalespace::cli {

void addCylinderCommands(CLI::App& app);

/// FileError unless `directory` is absent, an empty folder or an earlier cylinders result.
void checkCylinderResultDestination(const std::string& directory);

}  // namespace scalespace::cli
