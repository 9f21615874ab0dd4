#pragma once
// Components as planes (Sec. 2.3.3 and what users asked for beyond the thesis: equations and
// outlines): per component its persistence, a best-fit plane, the alpha-shape area and outlines.
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/RegionGraph.hpp"
#include "scalespace/planes/AlphaShapeArea.hpp"

namespace scalespace {

struct PlaneComponent {
  int id = 0;
  int birthLevel = 0, deathLevel = 0;
  double birthScale = 0.0, deathScale = 0.0;
  int persistence = 0;  // deathLevel - birthLevel
  /// The level where the component holds the most points (lowest such level on ties): its
  /// plane, area and outlines are computed there, where the region is the largest sample of it.
  int representativeLevel = 0;
  std::size_t pointCount = 0;        // at the representative level
  double representativeScale = 0.0;  // t of the representative level
  PlaneFit plane;                    // in the cloud's relative coordinates
  /// Whether the plane describes the component's points: plane.rms <= maxRelativeRms times the
  /// representative scale, or <= noiseFactor times the sensor noise, which no scale can go below
  /// (ComponentOptions). A chain of regions can drift from a plane into a curved or folded set
  /// (each step keeping Jaccard > 0.5, Sec. 2.3.2); the planarity split
  /// (planes/RegionPlanarity.hpp) ends the chain there and starts a flagged one.
  bool planar = true;
  /// Planar only by the noise bound: rms > maxRelativeRms times the representative scale but
  /// within noiseFactor times the noise. Below 40 sigma the noise alone can exceed 5% of t, so
  /// the plane is as good as the points allow but not confirmed to 5% of its scale; a user who
  /// needs that drops these (false whenever planar is false).
  bool noiseLimited = false;
  double area = 0.0;  // alpha shape (radius alphaFactor * t) at the representative level
  std::vector<std::vector<Vec3>> outlines;  // boundary loops of that alpha shape, in 3D
};

struct ComponentOptions {
  double alphaFactor = 2.0;      // same alpha-shape radius as the region filter: alphaFactor * t
  double maxRelativeRms = 0.05;  // PlaneComponent::planar: rms <= 5% of the representative scale
  double noiseFactor = 2.0;      // ... or rms <= 2 x the sensor noise:
  double noiseRms = -1;          // given (PlaneDetection::noiseRms), or < 0: the lower median
                                 // RMS of all components
  bool outlines = true;
};

/// One PlaneComponent per graph component, same order/ids. Parallel over components.
std::vector<PlaneComponent> extractComponents(const RegionGraph& graph,
                                              const std::vector<Vec3>& positions,
                                              const ComponentOptions& options = {},
                                              const ProgressCallback& progress = {});

/// Points of component `id` at `level` (empty outside its life span).
const std::vector<Index>& componentPointsAt(const RegionGraph& graph, int id, int level);

}  // namespace scalespace
