#pragma once
// The encodings and format versions of the scale stack on disk (docs/STACK_FORMAT.md; the
// multi-scale representation of Sec. 1.5 stored one .npy file per quantity). Shared by the writer
// (ScaleStackWriter.hpp), the reader (ScaleStackReader.hpp) and the codecs (StackCodecs.hpp).
#include <string>

namespace scalespace {

/// The newest format version this program writes and reads. Version 1: float32 only; version 2
/// adds the "encoding" key and the compact encoding; version 3 changes three compact files
/// (projection_offset, anisotropy, geometric_variation: 4 bytes less per point per scale, so that
/// 1M points x 50 scales fit in 1 GB). Float32 stacks are still written as version 1 (identical to
/// what older programs wrote and read); compact stacks are version 3. All three are read.
constexpr int kStackFormatVersion = 3;

/// How the per-scale quantities are stored (docs/STACK_FORMAT.md).
enum class StackEncoding {
  Compact,  // quantised, 19.125 bytes per point per scale (version 3; version 2: 23.125)
  Float32,  // every ScaleLayer field as float32 / uint16 / uint8, 83 bytes per point per scale
};
const char* stackEncodingName(StackEncoding encoding);
/// "compact" | "float32"; OptionError otherwise.
StackEncoding parseStackEncoding(const std::string& name);

}  // namespace scalespace
