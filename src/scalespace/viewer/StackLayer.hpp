#pragma once
// A scale stack (`scalespace scales`, docs/STACK_FORMAT.md), read through ScaleStackReader: every
// answer is what the reader returns (the compact encoding decoded by it), nothing recomputed.
//   GET /api/stack/values?quantity=Q&scale=J   float32 per displayed point (the cloud layer's
//        order): quantity Q at scale j
//   GET /api/stack/series?point=I[&quantities=Q1,Q2]  float32, quantity after quantity (in the
//        order asked; default: every quantity of the manifest), each over the M scales: point I
//        (the cloud's own index, input order) at every scale
// The manifest lists the quantities (names as `scalespace export --scale` writes them), the scale
// values, the point count and the encoding. The positions are the stack's input positions, served
// by the CloudLayer beside it.
#include <memory>
#include <string>
#include <vector>

#include "scalespace/scales/ScaleStackReader.hpp"
#include "scalespace/viewer/DisplaySample.hpp"
#include "scalespace/viewer/ViewerLayer.hpp"

namespace scalespace::viewer {

class StackLayer : public ViewerLayer {
 public:
  /// `sample` is the display sample of the cloud layer (same point count as the stack).
  StackLayer(std::shared_ptr<const ScaleStackReader> reader, DisplaySample sample);
  std::string name() const override { return "stack"; }
  /// point_count, display_count, scale_count, scales, encoding, format_version and
  /// quantities (name and description each).
  nlohmann::json manifest() const override;
  ViewerResponse handle(const std::string& endpoint, const ViewerRequest& request) const override;

  /// The scalar quantities a stack of this encoding stores (compact stacks have no gls_fitness).
  static std::vector<std::string> quantityNames(StackEncoding encoding);

 private:
  std::size_t quantityIndex(const std::string& name, const std::string& parameter) const;

  std::shared_ptr<const ScaleStackReader> reader_;
  DisplaySample sample_;
  std::vector<std::size_t> quantities_;  // indices into the table of StackLayer.cpp
};

}  // namespace scalespace::viewer
