#pragma once
// Regularity of a minimal-curvature line (Sec. 3.5.1): its length L (Eq. 3.5), total curvature K,
// the sum of its vertex angles (Eq. 3.6), and total normalised geometric variation V, the sum of
// tanh(nu) over its vertices (Eq. 3.7). The cylinders keep the lines with L >= L_min, K <= K_max
// and V <= V_max.
//
// The thesis sets the three thresholds by hand per cloud. Here they follow the scale t, so one
// setting holds at every scale (docs/THESIS_NOTES.md, "Cylinders"):
//   L_min = minLengthFactor t                 (a line crossing a few supports, not a stub)
//   K_max = maxCurvatureFactor L / t          (the line turns by at most that many radians per t
//                                              of length: its mean curvature is <= factor / t)
//   V_max = maxMeanVariation n                (the mean tanh(nu) over its n vertices)
#include "scalespace/features/CurvatureLines.hpp"

namespace scalespace {

struct LineRegularity {
  double length = 0;          // L, Eq. 3.5
  double totalCurvature = 0;  // K, Eq. 3.6 (radians)
  double totalVariation = 0;  // V, Eq. 3.7
};

/// Eq. 3.5-3.7 of one line (a closed line also turns at its first vertex).
LineRegularity lineRegularity(const CurvatureLine& line);

struct LineFilterOptions {
  double minLengthFactor = 2;     // L_min = 2 t
  double maxCurvatureFactor = 1;  // K_max = 1 L / t
  double maxMeanVariation = 0.5;  // V_max = 0.5 n
};

/// OptionError naming the field unless the factors are finite and >= 0.
void validateLineFilterOptions(const LineFilterOptions& options);

/// Whether a line of scale t passes the three thresholds.
bool isRegularLine(const CurvatureLine& line, double t, const LineFilterOptions& options);

}  // namespace scalespace
