#pragma once
// INTERNAL to the stack store (StackCodecs, ScaleStackWriter, ScaleStackReader): not part of the
// library's interface, may change with the format. Include ScaleStackWriter.hpp /
// ScaleStackReader.hpp instead.
//
// Where the bytes of a scale stack are (docs/STACK_FORMAT.md): one NumPy .npy file per quantity,
// shaped (M, N), (M, N, 3) or (M, ceil(N / 8)) for bit-packed flags, so that scale j is one
// contiguous slice and point i of scale j sits at a computed offset (the reader's pread). The
// writer and the reader both derive sizes, shapes and offsets from these functions, so that they
// cannot disagree.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/StackQuantization.hpp"

namespace scalespace::store {

/// The manifest, written last (a directory without it is never a valid stack), and its format tag.
constexpr const char* kManifest = "manifest.json";
constexpr const char* kFormatTag = "scalespace-stack";

/// One .npy file per quantity: a row of the tables of StackCodecs.cpp. dtype strings are NumPy's
/// ('<f4' little-endian float32, ...).
struct Quantity {
  const char* name;
  const char* dtype;
  std::size_t itemSize;
  int components;  // 1: shape (M, N); 3: shape (M, N, 3); 0: bit-packed, shape (M, ceil(N / 8))
  const char* description;
  std::vector<float> ScaleLayer::*floats;  // float32 encoding; nullptr for integers and compact
  const char* scaling;                     // compact: how the stored value relates to t_j
  const char* codec;                       // compact version 3: how the number is stored
};

/// Bytes of one scale of a quantity (one row of its file).
inline std::size_t sliceBytes(const Quantity& q, std::size_t n) {
  return q.components == 0 ? quant::packedBytes(n) : n * std::size_t(q.components) * q.itemSize;
}
/// Bytes of one point of a quantity (bit-packed: the byte holding it).
inline std::size_t pointBytes(const Quantity& q) {
  return q.components == 0 ? 1 : std::size_t(q.components) * q.itemSize;
}
/// Offset of point i of scale j in the data of a quantity's file (after the .npy header).
inline std::uint64_t pointOffset(const Quantity& q, std::size_t n, std::size_t j, std::size_t i) {
  if (q.components == 0) return std::uint64_t(j) * quant::packedBytes(n) + i / 8;
  return (std::uint64_t(j) * n + i) * pointBytes(q);
}
/// The .npy shape of a quantity for m scales of n points (also what the manifest lists).
inline std::vector<std::size_t> quantityShape(const Quantity& q, std::size_t m, std::size_t n) {
  if (q.components == 0) return {m, quant::packedBytes(n)};
  if (q.components == 1) return {m, n};
  return {m, n, std::size_t(q.components)};
}

}  // namespace scalespace::store
