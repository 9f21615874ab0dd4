#pragma once
// `render`, `generate` (synthetic scenes of Table 2.1), `planes` and `segment` (Chapter 2).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::cli {

struct GenerateOptions {
  std::size_t pointCount = 100000;
  double noise = 0.0;  // fraction of the bounding-box diagonal
  std::uint64_t seed = 1;
};

/// Fills `cloud` with the named scene (tri, stairs, cubes, box) and returns true; returns false
/// when `name` is not one of them, so a caller with more shapes (sphere, torus...) can try its own.
bool generateScene(const std::string& name, const GenerateOptions& options, PointCloud& cloud);

/// Registers render, generate (unless the app already has one), planes and segment.
void addPlanesCommands(CLI::App& app);

}  // namespace scalespace::cli
