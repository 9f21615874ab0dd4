#pragma once
// INTERNAL to the stack store (ScaleStackWriter, ScaleStackReader): which files an encoding has
// (the quantity tables) and how one scale of a ScaleLayer becomes their bytes and back
// (docs/STACK_FORMAT.md, "Compact encoding"). The per-value codecs (float16, octahedral frame,
// shared-exponent offsets, 8-bit log codes, bit packing) are StackQuantization.hpp's; this file
// applies them to whole scales, in parallel, and counts what they clamp.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/StackEncoding.hpp"
#include "scalespace/scales/StackLayout.hpp"
#include "scalespace/scales/StackQuantization.hpp"

namespace scalespace::store {

// The files of the compact encodings, format version 3 (written, 19.125 bytes per point and
// scale) and version 2 (read, and written only on request: 23.125 bytes). Both have the same files
// in the same order, the order of the buffers of encodeCompact / decodeCompact; version 3 stores
// the offset with a shared exponent and the anisotropy and nu as 8-bit log codes.
enum CompactFile {
  kOffset,
  kFrame,
  kCurvMax,
  kCurvMin,
  kTau,
  kKappa,
  kAnisotropy,
  kVariation,
  kNeighbors,
  kValidBits,
  kCompactFiles
};

/// A table of quantities, one per file, in file order.
struct QuantityTable {
  const Quantity* begin_;
  const Quantity* end_;
  const Quantity* begin() const { return begin_; }
  const Quantity* end() const { return end_; }
};
/// The files of an encoding; compact stacks by format version (2, or 3 for any other value).
QuantityTable quantities(StackEncoding e, int compactVersion);

/// The float32 encoding stores a ScaleLayer's arrays as they are: the bytes of the array of `q`.
const unsigned char* layerBytes(const Quantity& q, const ScaleLayer& layer);
unsigned char* layerBytes(const Quantity& q, ScaleLayer& layer);

/// The codecs of a compact stack: its format version and, for version 3, the offset exponent bias
/// and the ranges of the log codes (the writer's constants; the reader's come from the manifest).
struct CompactCodecs {
  int version = kStackFormatVersion;
  int offsetBias = quant::kOffsetBias;
  quant::Log8Code anisotropy{quant::kAnisotropyLogMin, quant::kAnisotropyLogMax, true};
  quant::Log8Code variation{quant::kVariationLogMin, quant::kVariationLogMax};
};

/// Encodes one scale (t: its scale value; rel: the input positions relative to the origin, 3 N, in
/// the layer's order) into buf (kCompactFiles buffers, resized here) in input order, adding the
/// values clamped to clamped[k] of file k. A layer in processing order (L.inputIndex) is read in
/// its own order and each point's codes are stored at its input index; validScratch is working
/// memory kept by the caller between scales.
void encodeCompact(const ScaleLayer& L, double t, const std::vector<double>& rel,
                   const CompactCodecs& codecs, std::vector<std::vector<unsigned char>>& buf,
                   std::vector<std::size_t>& clamped, std::vector<std::uint8_t>& validScratch);

/// Decodes `count` consecutive points of one scale: data[k] points at the first point's bytes of
/// file k (for the bit-packed flags: the byte holding it, whose bit is firstBit); rel are the
/// points' input positions relative to the origin. Point p goes to entry out0 + p of `out`, which
/// must be zero-initialised (invalid fits are left as zeros, never NaN).
void decodeCompact(const CompactCodecs& codecs, const std::vector<const unsigned char*>& data,
                   std::size_t firstBit, std::size_t count, double t, const double* rel,
                   ScaleLayer& out, std::size_t out0);

}  // namespace scalespace::store
