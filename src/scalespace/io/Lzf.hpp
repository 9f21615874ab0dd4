#pragma once
// LZF decompression (the liblzf format used by PCD's binary_compressed data), internal to the io
// layer. Every read and write is bounds-checked: corrupt input returns false, never overruns.
#include <cstddef>

namespace scalespace::io_detail {

/// Largest expansion LZF can encode: a 3-byte back reference yields at most 264 bytes.
constexpr std::size_t kLzfMaxRatio = 88;

/// Decompresses `input` into exactly `outputSize` bytes at `output`; false if the data is corrupt
/// or does not decompress to exactly that size.
bool lzfDecompress(const unsigned char* input, std::size_t inputSize, unsigned char* output,
                   std::size_t outputSize);

}  // namespace scalespace::io_detail
