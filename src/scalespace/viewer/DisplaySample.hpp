#pragma once
// The points the page draws: every step-th point, so that a cloud beyond the point budget reaches
// the browser decimated instead of freezing the tab. Every per-point array the viewer serves
// (positions, attributes, labels) is taken at the same points; indices the page sends back (brush,
// search domain) are the cloud's own, k * step.
#include <cstddef>
#include <string>

namespace scalespace::viewer {

struct DisplaySample {
  std::size_t pointCount = 0;  // the cloud's
  std::size_t step = 1;
  std::size_t count() const { return step == 0 ? 0 : (pointCount + step - 1) / step; }
};

/// The smallest step that keeps count() <= budget. Throws OptionError naming
/// ViewerOptions::pointBudget when budget is 0.
DisplaySample displaySampleFor(std::size_t pointCount, std::size_t budget);

/// Values v[k * step], k < count(), encoded with `append` (BinaryArrays.hpp).
template <typename Values, typename Append>
std::string sampledArray(const DisplaySample& sample, const Values& values, Append append) {
  std::string out;
  out.reserve(sample.count() * 4);
  for (std::size_t i = 0; i < sample.pointCount; i += sample.step) append(out, values[i]);
  return out;
}

}  // namespace scalespace::viewer
