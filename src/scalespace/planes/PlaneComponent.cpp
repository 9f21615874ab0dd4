#include "scalespace/planes/PlaneComponent.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

const std::vector<Index>& componentPointsAt(const RegionGraph& graph, int id, int level) {
  static const std::vector<Index> none;
  const GraphComponent& c = graph.components.at(std::size_t(id));
  if (level < c.birthLevel || level > c.deathLevel) return none;
  const int region = c.regionAt[std::size_t(level - c.birthLevel)];
  if (region < 0) return none;  // a bridged gap
  return graph.levels[std::size_t(level)].regions[std::size_t(region)];
}

std::vector<PlaneComponent> extractComponents(const RegionGraph& graph,
                                              const std::vector<Vec3>& positions,
                                              const ComponentOptions& options,
                                              const ProgressCallback& progress) {
  std::vector<PlaneComponent> out(graph.components.size());
  ProgressTracker tracker(progress, "components", out.size());
  tbb::parallel_for(std::size_t(0), out.size(), [&](std::size_t id) {
    const GraphComponent& g = graph.components[id];
    PlaneComponent& c = out[id];
    c.id = int(id);
    c.birthLevel = g.birthLevel;
    c.deathLevel = g.deathLevel;
    c.birthScale = g.birthScale;
    c.deathScale = g.deathScale;
    c.persistence = g.persistence();
    c.representativeLevel = g.birthLevel;
    for (int level = g.birthLevel; level <= g.deathLevel; ++level) {
      const std::size_t count = componentPointsAt(graph, int(id), level).size();
      if (count > c.pointCount) {
        c.pointCount = count;
        c.representativeLevel = level;
      }
    }
    const auto& points = componentPointsAt(graph, int(id), c.representativeLevel);
    c.plane = fitPlane(positions, points);
    c.representativeScale = graph.levels[std::size_t(c.representativeLevel)].t;
    const double radius = options.alphaFactor * graph.levels[std::size_t(c.representativeLevel)].t;
    const AlphaShape shape =
        alphaShape2(projectOnPlane(c.plane, positions, points), radius * radius, options.outlines);
    c.area = shape.area;
    for (const auto& loop : shape.outlines) {
      std::vector<Vec3> loop3;
      loop3.reserve(loop.size());
      for (const Vec2& p : loop) loop3.push_back(liftFromPlane(c.plane, p));
      c.outlines.push_back(std::move(loop3));
    }
    tracker.advance(1);
  });
  tracker.finish();
  // Sensor noise puts the RMS of a flat component at sigma whatever its scale, so 5% of a scale
  // below 20 sigma cannot hold (the table scan: 84% of its components, nearly all at t < 2 cm).
  // The noise is given (PlaneDetection::noiseRms, read from the points' neighbourhoods) or, as
  // a fallback, the typical (lower median) component RMS: most components are small, fine ones.
  // A plane describes its points when its RMS is within the larger of the two bounds.
  std::vector<double> rms;
  for (const PlaneComponent& c : out)
    if (c.plane.valid) rms.push_back(c.plane.rms);
  double noise = options.noiseRms;
  if (noise < 0) noise = rms.empty() ? 0.0 : lowerMedian(std::move(rms));
  for (PlaneComponent& c : out) {
    const double scaleBound = options.maxRelativeRms * c.representativeScale;
    c.planar = c.plane.valid && c.plane.rms <= std::max(scaleBound, options.noiseFactor * noise);
    c.noiseLimited = c.planar && c.plane.rms > scaleBound;
  }
  return out;
}

}  // namespace scalespace
