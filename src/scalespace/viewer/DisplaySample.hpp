#pragma once
// The points the page draws, as the cloud's indices in coarse-to-fine order (coarseToFineOrder):
// every prefix is spread evenly over the cloud. A cloud beyond the point budget reaches the browser
// as the budget's first points, an even level of detail rather than a freezing tab; the page draws
// a shorter prefix while the view moves. Every per-point array the viewer serves (positions,
// attributes, labels, stack values) is taken at the same points in the same order; indices the page
// sends back (brush, series) are the cloud's own, looked up in /api/cloud/indices.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace::viewer {

struct DisplaySample {
  std::size_t pointCount = 0;                        // the cloud's
  std::shared_ptr<const std::vector<Index>> points;  // the drawn points, coarse to fine
  std::size_t count() const { return points ? points->size() : 0; }
  Index operator[](std::size_t k) const { return (*points)[k]; }
};

/// The first min(size, budget) points of coarseToFineOrder(positions). Throws OptionError when
/// budget is 0.
DisplaySample displaySampleFor(const std::vector<Vec3>& positions, std::size_t budget);

/// Values v[sample[k]], k < count(), encoded with `append` (BinaryArrays.hpp).
template <typename Values, typename Append>
std::string sampledArray(const DisplaySample& sample, const Values& values, Append append) {
  std::string out;
  out.reserve(sample.count() * 4);
  for (std::size_t k = 0; k < sample.count(); ++k) append(out, values[sample[k]]);
  return out;
}

}  // namespace scalespace::viewer
