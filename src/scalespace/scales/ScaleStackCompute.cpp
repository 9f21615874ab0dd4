#include "scalespace/scales/ScaleStackCompute.hpp"

#include <memory>

#include "scalespace/core/Error.hpp"

namespace scalespace {

ScaleSpaceSummary computeScaleStackToDisk(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                          const std::string& path, const ProgressCallback& progress,
                                          const StackWriteOptions& write) {
  std::unique_ptr<ScaleStackWriter> writer;
  ScaleSpaceOptions all = options;
  all.layerContents = LayerContents::All;  // the stack stores every quantity
  // The writer puts the encoded bytes in input order (encodeCompact).
  all.layerOrder =
      write.encoding == StackEncoding::Compact ? LayerOrder::Processing : LayerOrder::Input;
  ScaleSpaceSummary summary = runScaleSpace(
      cloud, all,
      [&](std::size_t j, const ScaleLayer& layer, const ScaleStats& stats) {
        // The series is known only once runScaleSpace resolved t_min; M is the option count.
        if (!writer)
          writer = std::make_unique<ScaleStackWriter>(path, cloud, options,
                                                      std::size_t(options.series.count), write);
        writer->writeScale(j, layer, stats.t);
      },
      progress);
  if (!writer) throw Error("computeScaleStackToDisk: no scale was computed");
  writer->finish(summary);
  return summary;
}

}  // namespace scalespace
