#pragma once
// Why fits are invalid, in words a user can act on. A run where most fits fail must say so (the
// output alone is a column of zeros): the causes we can tell from the input are normals that are
// NaN/Inf or zero (a fit that reads one is invalid), a scale beyond the cloud's extent, and
// neighbourhoods with fewer points than a fit needs.
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace {

struct FitCounts {
  std::size_t total = 0;     // fits made
  std::size_t invalid = 0;   // of which invalid
  double largestScale = 0;   // the largest t used (per-point or per-scale)
  double meanNeighbors = 0;  // mean neighbours per fit, over every fit
  int minNeighbors = 6;      // FitOptions::minNeighbors of the run
};

/// Points whose normal is NaN/Inf or of (near) zero length: 0 for a cloud without normals.
std::size_t unusableNormalCount(const PointCloud& cloud);

/// Empty when at most half the fits are invalid; otherwise one sentence saying how many fits are
/// invalid and each cause found (the library never prints: callers show it).
std::vector<std::string> invalidFitWarnings(const PointCloud& cloud, const FitCounts& counts);

}  // namespace scalespace
