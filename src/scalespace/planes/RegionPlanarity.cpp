#include "scalespace/planes/RegionPlanarity.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "scalespace/core/Error.hpp"
#include "scalespace/planes/AlphaShapeArea.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

void validate(const PlanarityOptions& options) {
  if (!(options.maxRelativeRms >= 0) || !std::isfinite(options.maxRelativeRms))
    throw OptionError("PlanarityOptions::maxRelativeRms must be finite and >= 0");
  if (!(options.noiseFactor >= 0) || !std::isfinite(options.noiseFactor))
    throw OptionError("PlanarityOptions::noiseFactor must be finite and >= 0");
}

namespace {
std::vector<double> regionRms(const std::vector<Vec3>& positions, const RegionLevel& level) {
  std::vector<double> rms(level.regions.size(), 0.0);
  tbb::parallel_for(std::size_t(0), rms.size(), [&](std::size_t r) {
    const PlaneFit plane = fitPlane(positions, level.regions[r]);
    rms[r] = plane.valid ? plane.rms : std::numeric_limits<double>::infinity();
  });
  return rms;
}
}  // namespace

std::vector<std::vector<std::uint8_t>> regionPlanarity(const std::vector<Vec3>& positions,
                                                       const std::vector<RegionLevel>& levels,
                                                       double noise,
                                                       const PlanarityOptions& options) {
  validate(options);
  std::vector<std::vector<std::uint8_t>> planar(levels.size());
  for (std::size_t j = 0; j < levels.size(); ++j) {
    planar[j].assign(levels[j].regions.size(), 1);
    if (options.maxRelativeRms == 0) continue;
    const std::vector<double> rms = regionRms(positions, levels[j]);
    const double bound =
        std::max(options.maxRelativeRms * levels[j].t, options.noiseFactor * noise);
    for (std::size_t r = 0; r < rms.size(); ++r) planar[j][r] = rms[r] <= bound;
  }
  return planar;
}

}  // namespace scalespace
