#include "scalespace/viewer/ViewerToken.hpp"

#include <sys/random.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>

#include "scalespace/core/Error.hpp"

namespace scalespace::viewer {

std::string makeViewerToken() {
  unsigned char bytes[16];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error("the viewer token: the kernel gave no random bytes (getrandom failed)");
    got += std::size_t(n);
  }
  static const char* const kHex = "0123456789abcdef";
  std::string token;
  for (unsigned char b : bytes) {
    token += kHex[b >> 4];
    token += kHex[b & 15];
  }
  return token;
}

bool tokensEqual(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;  // the length is not secret (always 32)
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= std::uint8_t(a[i] ^ b[i]);
  return diff == 0;
}

}  // namespace scalespace::viewer
