#include "scalespace/viewer/BinaryArrays.hpp"

#include <cstring>

namespace scalespace::viewer {

namespace {
template <typename U>
void appendLittleEndian(std::string& out, U bits) {
  for (std::size_t k = 0; k < sizeof(U); ++k) out += char((bits >> (8 * k)) & 0xff);
}
}  // namespace

void appendUint32(std::string& out, std::uint32_t v) { appendLittleEndian(out, v); }

void appendInt32(std::string& out, std::int32_t v) { appendLittleEndian(out, std::uint32_t(v)); }

void appendFloat32(std::string& out, float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  appendLittleEndian(out, bits);
}

void appendFloat64(std::string& out, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  appendLittleEndian(out, bits);
}

}  // namespace scalespace::viewer
