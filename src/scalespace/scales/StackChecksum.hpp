#pragma once
// INTERNAL to the stack store (ScaleStackWriter, ScaleStackReader): the checksum the manifest
// lists for every file of a stack ("checksum_algorithm": "fnv1a64-words", docs/STACK_FORMAT.md),
// computed by the writer while it streams the data and recomputed by
// ScaleStackReader::verifyChecksums.
#include <cstddef>
#include <cstdint>
#include <string>

namespace scalespace::store {

/// 64-bit FNV-1a-style hash over 8-byte little-endian words of the whole data stream (a final
/// partial word is zero-padded): one multiply per 8 bytes, fast enough to run while writing
/// gigabytes. Streaming: add() may be called with any split of the data.
struct Checksum {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  unsigned char carry[8] = {};
  std::size_t carried = 0;
  void add(const unsigned char* p, std::size_t n);
  std::uint64_t value() const;

 private:
  void word(const unsigned char* p);
};

/// 16 lower-case hex digits, as the manifest writes checksums (the files' and input_checksum).
std::string hex64(std::uint64_t v);

}  // namespace scalespace::store
