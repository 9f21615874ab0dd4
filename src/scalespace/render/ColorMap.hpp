#pragma once
// Colours for scalar and label attributes: a perceptual map (viridis) for scalars over a robust
// range, and well separated hues for integer labels.
#include <vector>

#include "scalespace/render/Image.hpp"

namespace scalespace {

/// Viridis at t in [0, 1] (clamped), interpolated linearly between tabulated control points.
Rgb viridis(double t);

struct ScalarRange {
  double lo = 0.0;
  double hi = 1.0;
};

/// The [lowQuantile, highQuantile] quantiles of the finite values (default 2nd-98th percentile),
/// so a few outliers do not flatten the map. {0, 1} when no value is finite.
ScalarRange robustRange(const std::vector<double>& values, double lowQuantile = 0.02,
                        double highQuantile = 0.98);

/// Viridis of (v - lo) / (hi - lo); non-finite values are grey.
std::vector<Rgb> colorizeScalars(const std::vector<double>& values, const ScalarRange& range);

/// Distinct colour for an integer label: hues spaced by the golden ratio so consecutive labels
/// differ strongly; negative labels (unlabelled, -1) are grey.
Rgb labelColor(long long label);
/// Colours for the labels present: they are ranked by decreasing point count (ties: smaller
/// label first) and label of rank k gets labelColor(k). Ranking rather than using the label value
/// keeps the largest labels far apart in hue whatever their ids (component ids run into the
/// thousands, where two ids can land on nearly the same hue). Negative or non-finite: grey.
std::vector<Rgb> colorizeLabels(const std::vector<double>& labels);

/// Grey used for unlabelled points and invalid values.
constexpr Rgb kUnlabelledGrey{128, 128, 128};

}  // namespace scalespace
