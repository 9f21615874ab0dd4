#include "scalespace/io/Lzf.hpp"

#include <cstring>

namespace scalespace::io_detail {

bool lzfDecompress(const unsigned char* input, std::size_t inputSize, unsigned char* output,
                   std::size_t outputSize) {
  std::size_t in = 0, out = 0;
  while (in < inputSize) {
    const unsigned control = input[in++];
    if (control < 32) {
      // Literal run of control + 1 bytes.
      const std::size_t length = control + 1;
      if (length > inputSize - in || length > outputSize - out) return false;
      std::memcpy(output + out, input + in, length);
      in += length;
      out += length;
      continue;
    }
    // Back reference: 3-bit length (7 = extended by the next byte), 13-bit distance - 1.
    std::size_t length = control >> 5;
    if (length == 7) {
      if (in >= inputSize) return false;
      length += input[in++];
    }
    if (in >= inputSize) return false;
    const std::size_t distance = ((std::size_t(control & 0x1F) << 8) | input[in++]) + 1;
    length += 2;
    if (distance > out || length > outputSize - out) return false;
    // Byte by byte: the source may overlap the bytes being written (run-length repeats).
    for (std::size_t k = 0; k < length; ++k, ++out) output[out] = output[out - distance];
  }
  return out == outputSize;
}

}  // namespace scalespace::io_detail
