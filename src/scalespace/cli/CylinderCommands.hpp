#pragma once
// `cylinders`: cylinders across scales (Sec. 3.5, with the persistence of Ch. 2).
#include <CLI/CLI.hpp>
#include <string>

namespace scalespace::cli {

void addCylinderCommands(CLI::App& app);

/// Whether `directory` is a `scalespace cylinders` result (its components.json names it).
bool isCylinderResult(const std::string& directory);

/// FileError unless `directory` is absent, an empty folder or an earlier cylinders result.
void checkCylinderResultDestination(const std::string& directory);

}  // namespace scalespace::cli
