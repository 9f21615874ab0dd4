#include "scalespace/scales/StackEncoding.hpp"

#include "scalespace/core/Error.hpp"

namespace scalespace {

const char* stackEncodingName(StackEncoding encoding) {
  return encoding == StackEncoding::Compact ? "compact" : "float32";
}

StackEncoding parseStackEncoding(const std::string& name) {
  if (name == "compact") return StackEncoding::Compact;
  if (name == "float32") return StackEncoding::Float32;
  throw OptionError("StackWriteOptions::encoding must be compact or float32, not '" + name + "'");
}

}  // namespace scalespace
