#include "scalespace/scales/StackChecksum.hpp"

#include <cstdio>
#include <cstring>

namespace scalespace::store {

void Checksum::word(const unsigned char* p) {
  std::uint64_t w;
  std::memcpy(&w, p, 8);
  h = (h ^ w) * 0x100000001b3ULL;
}

void Checksum::add(const unsigned char* p, std::size_t n) {
  while (carried > 0 && carried < 8 && n > 0) {
    carry[carried++] = *p++;
    --n;
  }
  if (carried == 8) {
    word(carry);
    carried = 0;
  }
  for (; n >= 8; n -= 8, p += 8) word(p);
  for (; n > 0; --n) carry[carried++] = *p++;
}

std::uint64_t Checksum::value() const {
  if (carried == 0) return h;
  unsigned char last[8] = {};
  std::memcpy(last, carry, carried);
  std::uint64_t w;
  std::memcpy(&w, last, 8);
  return (h ^ w) * 0x100000001b3ULL;
}

std::string hex64(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

}  // namespace scalespace::store
