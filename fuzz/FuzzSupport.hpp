#pragma once
// Shared by the libFuzzer targets: parse the input from memory (no file system), treat
// scalespace::Error as the expected outcome for bad input, and check a property on success: a
// cloud that was read can be written and read back with the same size (otherwise abort, which
// libFuzzer reports as a crash).
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/PlyFormat.hpp"

namespace scalespace::fuzz {

inline std::string_view asText(const std::uint8_t* data, std::size_t size) {
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

/// Writes `cloud` as binary PLY and reads it back; aborts if the size changes.
inline void checkPlyRoundTrip(const PointCloud& cloud) {
  std::ostringstream out;
  try {
    writePly(cloud, out, PlyEncoding::BinaryLittleEndian);
  } catch (const Error&) {
    return;  // e.g. an attribute name that cannot be written
  }
  ReadOptions keepAll;
  keepAll.dropNonFinite = true;
  if (readPly(out.str(), "roundtrip.ply", keepAll).size() != cloud.size()) std::abort();
}

}  // namespace scalespace::fuzz
