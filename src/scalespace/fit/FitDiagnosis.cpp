#include "scalespace/fit/FitDiagnosis.hpp"

#include <algorithm>
#include <cstdio>

namespace scalespace {

std::size_t unusableNormalCount(const PointCloud& cloud) {
  return std::size_t(
      cloud.normals().size() -
      std::size_t(std::count_if(cloud.normals().begin(), cloud.normals().end(), isUsableNormal)));
}

std::vector<std::string> invalidFitWarnings(const PointCloud& cloud, const FitCounts& counts) {
  if (counts.total == 0 || 2 * counts.invalid <= counts.total) return {};
  char text[512];
  std::vector<std::string> out;
  std::snprintf(text, sizeof text, "%zu of %zu fits (%.0f%%) are invalid", counts.invalid,
                counts.total, 100.0 * double(counts.invalid) / double(counts.total));
  std::string summary = text;
  std::vector<std::string> causes;
  const double diagonal = cloud.boundingBoxDiagonal();
  if (!(diagonal > 0) && cloud.size() > 1) {
    // No scale helps here: advising a larger one (the neighbour count below) would mislead.
    std::snprintf(text, sizeof text,
                  "all %zu points are at one position: there is no surface to fit", cloud.size());
    return {summary + ": " + text};
  }
  if (const std::size_t bad = unusableNormalCount(cloud); bad > 0) {
    std::snprintf(text, sizeof text,
                  "%zu input normals are NaN/Inf or zero and every fit reaching one of them is "
                  "invalid: estimate normals again (scalespace normals) or drop those points",
                  bad);
    causes.push_back(text);
  }
  const bool beyondCloud = counts.largestScale > diagonal && diagonal > 0;
  if (beyondCloud) {
    std::snprintf(text, sizeof text,
                  "the scale t = %.6g is %.3g times the cloud's diagonal (%.6g): a fit over the "
                  "whole cloud describes no local surface; choose t below the diagonal",
                  counts.largestScale, counts.largestScale / diagonal, diagonal);
    causes.push_back(text);
  }
  // A scale beyond the cloud with few neighbours: the fits read a sparse level (Poisson-disk
  // radius alpha t), and a larger scale makes it sparser; the advice above stands alone.
  if (counts.meanNeighbors < 2.0 * counts.minNeighbors && !beyondCloud) {
    std::snprintf(text, sizeof text,
                  "fits have %.1f neighbours on average and need at least %d: choose a larger "
                  "scale",
                  counts.meanNeighbors, counts.minNeighbors);
    causes.push_back(text);
  }
  if (causes.empty())
    causes.push_back(
        "the neighbourhoods are degenerate (points on a line, or a sphere fit that fails): "
        "check the input and the scale");
  for (const std::string& c : causes) out.push_back(summary + ": " + c);
  return out;
}

}  // namespace scalespace
