#include "scalespace/planes/ScaleFeatures.hpp"

#include <string>

#include "scalespace/core/Error.hpp"

namespace scalespace {

void checkScaleFeatures(const std::vector<ScaleFeatures>& scales, std::size_t pointCount) {
  for (std::size_t j = 0; j < scales.size(); ++j) {
    const ScaleFeatures& s = scales[j];
    if (s.normals.size() != pointCount || s.kMax.size() != pointCount ||
        s.kMin.size() != pointCount || s.valid.size() != pointCount ||
        (!s.projections.empty() && s.projections.size() != pointCount))
      throw OptionError("scale " + std::to_string(j) + " has features for a different number of " +
                        "points than the cloud (" + std::to_string(pointCount) + ")");
    if (!(s.t > 0) || (j > 0 && !(s.t > scales[j - 1].t)))
      throw OptionError("scales must be positive and strictly increasing (scale " +
                        std::to_string(j) + ")");
  }
}

}  // namespace scalespace
