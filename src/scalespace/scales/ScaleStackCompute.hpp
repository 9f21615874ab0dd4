#pragma once
// Computing the scale stack of Sec. 1.5 straight to disk: each scale is written
// (ScaleStackWriter, docs/STACK_FORMAT.md) as soon as runScaleSpace hands it over, so that peak
// memory is one scale, not the whole stack. The in-memory twin, for small clouds and tests, is
// computeScaleStackInMemory (ScaleSpace.hpp).
#include <string>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/ScaleStackWriter.hpp"

namespace scalespace {

/// Computes the scale space of `cloud` and streams it into the stack `path`. An older stack at
/// `path` is replaced only once the new one is complete; a failure or a cancel leaves it as it was.
ScaleSpaceSummary computeScaleStackToDisk(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                          const std::string& path,
                                          const ProgressCallback& progress = {},
                                          const StackWriteOptions& write = {});

}  // namespace scalespace
