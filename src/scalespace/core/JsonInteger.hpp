#pragma once
// Integers read from JSON files without undefined behaviour. nlohmann's get<int>() and
// get<std::size_t>() convert a floating-point value with static_cast, which is undefined when the
// value is out of range ("point_count": 1e300, "id": -1.5): UBSan reports it, and anything may
// happen. Header-only, for the layers that read JSON and link nlohmann_json (scales: the stack
// manifest; planes: components.json).
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace scalespace {

/// `value` as an Int: a JSON integer in Int's range, or a float with an integral value in it.
/// Otherwise throws nlohmann::json::type_error, as get<Int>() does for a value of another type
/// (a non-number named by its type: dump() of deeply nested JSON recurses as deep).
template <class Int>
Int jsonInteger(const nlohmann::json& value) {
  using Limits = std::numeric_limits<Int>;
  if (value.is_number_unsigned()) {
    const std::uint64_t v = value.get<std::uint64_t>();
    if (v <= std::uint64_t(Limits::max())) return Int(v);
  } else if (value.is_number_integer()) {
    const std::int64_t v = value.get<std::int64_t>();
    if (v >= std::int64_t(Limits::min()) &&
        (v < 0 || std::uint64_t(v) <= std::uint64_t(Limits::max())))
      return Int(v);
  } else if (value.is_number_float()) {
    // Int's range is [-2^digits, 2^digits) (signed) or [0, 2^digits): exact in a double.
    const double v = value.get<double>(), bound = std::ldexp(1.0, Limits::digits);
    if (v == std::trunc(v) && v < bound && v >= (Limits::is_signed ? -bound : 0.0)) return Int(v);
  }
  throw nlohmann::json::type_error::create(
      302,
      "expected an integer from " + std::to_string(Limits::min()) + " to " +
          std::to_string(Limits::max()) + ", got " +
          (value.is_number() ? value.dump() : std::string(value.type_name())),
      &value);
}

/// A JSON array of Int (jsonInteger for each element); type_error if it is not an array.
template <class Int>
std::vector<Int> jsonIntegers(const nlohmann::json& array) {
  if (!array.is_array())
    throw nlohmann::json::type_error::create(
        302, "expected an array, got " + std::string(array.type_name()), &array);
  std::vector<Int> out;
  for (const auto& value : array) out.push_back(jsonInteger<Int>(value));
  return out;
}

}  // namespace scalespace
