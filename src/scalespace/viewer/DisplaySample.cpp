#include "scalespace/viewer/DisplaySample.hpp"

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialOrder.hpp"

namespace scalespace::viewer {

DisplaySample displaySampleFor(const std::vector<Vec3>& positions, std::size_t budget) {
  if (budget == 0) throw OptionError("displaySampleFor: the point budget must be >= 1");
  std::vector<Index> order = coarseToFineOrder(positions);
  if (order.size() > budget) {
    order.resize(budget);
    order.shrink_to_fit();
  }
  DisplaySample sample;
  sample.pointCount = positions.size();
  sample.points = std::make_shared<const std::vector<Index>>(std::move(order));
  return sample;
}

}  // namespace scalespace::viewer
