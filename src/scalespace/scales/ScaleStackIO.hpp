#pragma once
// The scale stack on disk (docs/STACK_FORMAT.md), the store of the multi-scale representation of
// Sec. 1.5: an umbrella header over its parts, kept so that code written before they were split
// into files still compiles. New code includes what it uses:
//   StackEncoding.hpp      the encodings (compact, float32) and format versions
//   ScaleStackWriter.hpp   ScaleStackWriter, writeScaleStack, StackWriteOptions
//   ScaleStackReader.hpp   ScaleStackReader, StackInfo, isScaleStack
//   ScaleStackCompute.hpp  computeScaleStackToDisk (the in-memory twin: ScaleSpace.hpp)
// The store's internals, not part of the interface: StackLayout.hpp (files, shapes, offsets),
// StackCodecs.hpp (quantity tables, encoding of whole scales; the per-value codecs are
// StackQuantization.hpp), StackChecksum.hpp, NpyFormat.hpp.
#include <string>

#include "scalespace/scales/ScaleStackCompute.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"
#include "scalespace/scales/ScaleStackWriter.hpp"
#include "scalespace/scales/StackEncoding.hpp"

namespace scalespace {

/// The former name of computeScaleStackToDisk, for code written before the rename (e.g. the
/// stack fuzzer, fuzz/fuzz_stack.cpp).
inline ScaleSpaceSummary computeScaleStack(const PointCloud& cloud,
                                           const ScaleSpaceOptions& options,
                                           const std::string& path,
                                           const ProgressCallback& progress = {},
                                           const StackWriteOptions& write = {}) {
  return computeScaleStackToDisk(cloud, options, path, progress, write);
}

}  // namespace scalespace
