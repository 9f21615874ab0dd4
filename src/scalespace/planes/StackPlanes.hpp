#pragma once
// The full pipeline of Fig. 2.4 on a point cloud: the multi-scale stack (scales layer, robust
// APSS) is computed scale by scale and each scale is segmented as soon as it is available, so
// the stack never has to be held in memory; then the graph and the components.
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/planes/PlaneDetection.hpp"
#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"

namespace scalespace {

/// The plane pipeline's view of one scale of the stack: normals, principal curvatures, validity.
ScaleFeatures scaleFeaturesFromLayer(const ScaleLayer& layer, double t);

struct StackPlaneDetection {
  PlaneDetection detection;
  ScaleSpaceSummary stack;  // scales, per-scale statistics and time
  /// Table 2.1 "Surf. Recon.": wall time of the stack. Each scale is segmented and filtered
  /// while the next one is projected, so detection.timings' segmentation and filtering (the
  /// tasks' own durations) overlap it; segmentationWaitSeconds is what was left after it.
  double stackSeconds = 0;
  double segmentationWaitSeconds = 0;
  double knnSeconds = 0;
  double totalSeconds = 0;  // wall time of the whole detection
};

/// Computes the stack with `stackOptions` (the cloud needs normals) and detects the planes.
StackPlaneDetection detectPlanesInCloud(const PointCloud& cloud,
                                        const ScaleSpaceOptions& stackOptions,
                                        const PlaneDetectionOptions& options = {},
                                        const ProgressCallback& progress = {});

/// Same pipeline on a stack already on disk (`scalespace scales`), read one scale at a time.
/// Throws FileError when the stack was not computed from `cloud` (checksum).
PlaneDetection detectPlanesFromStack(const PointCloud& cloud, const ScaleStackReader& stack,
                                     const PlaneDetectionOptions& options = {},
                                     const ProgressCallback& progress = {});

}  // namespace scalespace
