// libFuzzer target for the XYZ reader: any input must either parse or throw scalespace::Error
// (never crash, hang or over-allocate); a parsed cloud must survive a PLY write/read round trip.
#include "FuzzSupport.hpp"
#include "scalespace/io/XyzFormat.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = scalespace::fuzz::asText(data, size);
  scalespace::ReadOptions options;
  options.dropNonFinite = size % 2 == 1;  // both policies
  try {
    scalespace::fuzz::checkPlyRoundTrip(scalespace::readXyz(text, "fuzz.xyz", options));
  } catch (const scalespace::Error&) {
  }
  return 0;
}
