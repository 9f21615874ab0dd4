#pragma once
// Little-endian encodings of the arrays the viewer serves (whatever the host's byte order), which
// the page reads as Float32Array / Int32Array / Float64Array without parsing.
#include <cstdint>
#include <string>

namespace scalespace::viewer {

void appendUint32(std::string& out, std::uint32_t v);
void appendInt32(std::string& out, std::int32_t v);
void appendFloat32(std::string& out, float v);
void appendFloat64(std::string& out, double v);

}  // namespace scalespace::viewer
