#pragma once
// The automatic part of Chapter 2 (Fig. 2.4): per-scale segmentation and filtering, the region
// graph and its components, with the time spent in each step (Table 2.1 columns).
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/core/RegionGraph.hpp"
#include "scalespace/planes/BoundaryRefinement.hpp"
#include "scalespace/planes/PlaneComponent.hpp"
#include "scalespace/planes/RegionGrowing.hpp"
#include "scalespace/planes/RegionMerging.hpp"
#include "scalespace/planes/RegionPlanarity.hpp"
#include "scalespace/planes/ScaleFeatures.hpp"

namespace scalespace {

struct PlaneDetectionOptions {
  /// theta = 5 degrees (Sec. 2.3.1) and a step limit of 0.05 t (a departure, docs/THESIS_NOTES.md,
  /// region growing offset; maxStep 0 is the thesis' criterion). The scale features must then
  /// carry the projections.
  RegionGrowingOptions growing{5.0, 0.05};
  /// Adjacent grown regions whose union a plane describes are merged before the filter (a
  /// departure, docs/THESIS_NOTES.md, coplanar merging; maxRelativeRms 0: the thesis).
  RegionMergeOptions merging;
  /// Then the points between two regions go to the nearer plane (a departure, docs/THESIS_NOTES.md,
  /// boundary refinement; maxRelativeDistance 0: the thesis).
  BoundaryRefinementOptions refinement;
  double alphaFactor = 2.0;    // alpha-shape radius and minimum extent: 2t
  PlanarityOptions planarity;  // RMS <= 5% of t or 2 x noise (maxRelativeRms 0: the thesis)
  double minJaccard = 0.5;     // Sec. 2.3.2
  bool outlines = true;
};

struct PlaneDetectionTimings {
  double segmentation = 0, filtering = 0, graph = 0, components = 0;  // seconds
};

struct PlaneDetection {
  RegionGraph graph;
  /// The sensor noise the planarity test and the components' `planar` flags allow for
  /// (pointNoiseRms), and how many regions are not planar (kept, linked to no planar one).
  double noiseRms = 0.0;
  std::size_t nonPlanarRegions = 0;
  bool planaritySplit = false;  // planarity.maxRelativeRms > 0: chains split, labels prefer planar
  std::vector<PlaneComponent> components;  // same ids as graph.components
  PlaneDetectionTimings timings;
  int scaleCount() const { return int(graph.levels.size()); }
};

/// OptionError naming the field unless every option is in its range (angle in (0, 180), maxStep
/// and the planarity bounds finite and >= 0, alphaFactor > 0, minJaccard in [0, 1)); the entry
/// points check it first, a caller can check it before reading its input.
void validatePlaneDetectionOptions(const PlaneDetectionOptions& options);

/// Sec. 2.3.1 for one scale: region growing, the coplanar merging (with options.merging, allowing
/// for `noiseRms`, the cloud's pointNoiseRms), the alpha-shape filter, then the boundary
/// refinement of the kept regions (options.refinement, same noise); adds the time spent
/// to `timings` (segmentation, filtering).
RegionLevel segmentScale(const std::vector<Vec3>& positions, const KnnGraph& knn,
                         const ScaleFeatures& scale, double noiseRms,
                         const PlaneDetectionOptions& options, PlaneDetectionTimings& timings);

/// Sec. 2.3.2-2.3.3 on the filtered levels: the regions' planarity (allowing for `noiseRms`, the
/// cloud's pointNoiseRms), graph, components, planes and outlines.
PlaneDetection buildPlaneDetection(const std::vector<Vec3>& positions,
                                   std::vector<RegionLevel> levels, double noiseRms,
                                   const PlaneDetectionOptions& options,
                                   PlaneDetectionTimings timings,
                                   const ProgressCallback& progress = {});

/// Runs Sec. 2.3 on precomputed scale features (increasing t) and the k-NN graph of `positions`.
/// With the default step limit (growing.maxStep > 0) the features must carry their projections
/// (OptionError otherwise; growing.maxStep = 0 is the thesis' angle-only criterion).
PlaneDetection detectPlanes(const std::vector<Vec3>& positions, const KnnGraph& knn,
                            const std::vector<ScaleFeatures>& scales,
                            const PlaneDetectionOptions& options = {},
                            const ProgressCallback& progress = {});

}  // namespace scalespace
