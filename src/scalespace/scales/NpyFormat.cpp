#include "scalespace/scales/NpyFormat.hpp"

#include <cstring>

namespace scalespace::store {

std::string npyShapeText(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k)
    s += std::to_string(shape[k]) + (shape.size() == 1 ? "," : k + 1 < shape.size() ? ", " : "");
  return s + ")";
}

std::string npyHeader(const std::string& dtype, const std::vector<std::size_t>& shape) {
  std::string dict =
      "{'descr': '" + dtype + "', 'fortran_order': False, 'shape': " + npyShapeText(shape) + ", }";
  std::size_t total = kNpyPreludeBytes + dict.size() + 1;
  const std::size_t padded = (total + 63) / 64 * 64;
  dict.append(padded - total, ' ');
  dict.push_back('\n');
  std::string h = "\x93NUMPY";
  h.push_back(char(1));
  h.push_back(char(0));
  h.push_back(char(dict.size() & 0xff));
  h.push_back(char(dict.size() >> 8));
  return h + dict;
}

bool isNpyVersion1(const unsigned char* prelude) {
  return std::memcmp(prelude, "\x93NUMPY", 6) == 0 && prelude[6] == 1;
}

std::size_t npyDictLength(const unsigned char* prelude) {
  return std::size_t(prelude[8]) | (std::size_t(prelude[9]) << 8);
}

}  // namespace scalespace::store
