#include "scalespace/viewer/DisplaySample.hpp"

#include "scalespace/core/Error.hpp"

namespace scalespace::viewer {

DisplaySample displaySampleFor(std::size_t pointCount, std::size_t budget) {
  if (budget == 0) throw OptionError("ViewerOptions::pointBudget must be >= 1");
  DisplaySample sample;
  sample.pointCount = pointCount;
  sample.step = pointCount <= budget ? 1 : (pointCount + budget - 1) / budget;
  return sample;
}

}  // namespace scalespace::viewer
