#include "scalespace/io/TextParsing.hpp"

#include <charconv>
#include <cmath>
#include <limits>

namespace scalespace::io_detail {

bool LineScanner::next(std::string_view& line) {
  if (offset_ >= data_.size()) return false;
  std::size_t end = data_.find('\n', offset_);
  const std::size_t next = end == std::string_view::npos ? data_.size() : end + 1;
  if (end == std::string_view::npos) end = data_.size();
  line = data_.substr(offset_, end - offset_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  offset_ = next;
  ++line_;
  return true;
}

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

void splitOn(std::string_view line, char separator, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(separator, start);
    tokens.push_back(trim(line.substr(start, end == std::string_view::npos ? end : end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
}

std::optional<double> parseNumber(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // A well-formed number beyond the double range: overflow gives +-inf (then rejected as a
    // non-finite coordinate, or kept in an attribute), underflow (negative exponent) +-0, as
    // strtod would.
    const bool negative = token.front() == '-';
    const std::size_t e = token.find_first_of("eE");
    const bool underflow =
        e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
    const double magnitude = underflow ? 0.0 : std::numeric_limits<double>::infinity();
    return negative ? -magnitude : magnitude;
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

std::optional<unsigned long long> parseUnsigned(std::string_view token) {
  unsigned long long value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (token.empty() || ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

namespace {
template <class T>
bool fitsInteger(double value) {
  return std::isfinite(value) && std::floor(value) == value &&
         value >= double(std::numeric_limits<T>::lowest()) &&
         value <= double(std::numeric_limits<T>::max());
}
template <class T>
double saturate(double value) {
  if (std::isnan(value)) return 0.0;
  const double lo = double(std::numeric_limits<T>::lowest());
  const double hi = double(std::numeric_limits<T>::max());
  return std::min(hi, std::max(lo, std::round(value)));
}
}  // namespace

bool fitsScalarType(double value, ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return fitsInteger<std::int8_t>(value);
    case ScalarType::UInt8:
      return fitsInteger<std::uint8_t>(value);
    case ScalarType::Int16:
      return fitsInteger<std::int16_t>(value);
    case ScalarType::UInt16:
      return fitsInteger<std::uint16_t>(value);
    case ScalarType::Int32:
      return fitsInteger<std::int32_t>(value);
    case ScalarType::UInt32:
      return fitsInteger<std::uint32_t>(value);
    case ScalarType::Float32:
    case ScalarType::Float64:
      return true;
  }
  return false;
}

double toStoredValue(double value, ScalarType type) {
  // Integer columns hold integers by construction; values computed by other layers may not, so
  // they are rounded and saturated (NaN -> 0) rather than cast with undefined behaviour.
  switch (type) {
    case ScalarType::Int8:
      return saturate<std::int8_t>(value);
    case ScalarType::UInt8:
      return saturate<std::uint8_t>(value);
    case ScalarType::Int16:
      return saturate<std::int16_t>(value);
    case ScalarType::UInt16:
      return saturate<std::uint16_t>(value);
    case ScalarType::Int32:
      return saturate<std::int32_t>(value);
    case ScalarType::UInt32:
      return saturate<std::uint32_t>(value);
    case ScalarType::Float32: {
      // Values beyond the float range become +-inf, as a float cast would, without the UB.
      const double max = double(std::numeric_limits<float>::max());
      if (std::isfinite(value) && std::abs(value) > max)
        return value > 0 ? std::numeric_limits<double>::infinity()
                         : -std::numeric_limits<double>::infinity();
      return double(float(value));
    }
    case ScalarType::Float64:
      return value;
  }
  return value;
}

std::string formatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string formatScalar(double value, ScalarType type) {
  const double stored = toStoredValue(value, type);
  if (type == ScalarType::Float32 && std::isfinite(stored)) {
    // Shortest float text: reads back to the same float (and the same double after widening).
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), float(stored));
    return std::string(buffer, result.ptr);
  }
  return formatNumber(stored);
}

std::string quoted(std::string_view token) {
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < 32; ++i)
    out += token[i] >= 32 && token[i] < 127 ? token[i] : '?';
  if (token.size() > 32) out += "...";
  return out + "'";
}

std::string toLower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  return out;
}

}  // namespace scalespace::io_detail
