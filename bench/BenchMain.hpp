#pragma once
// A benchmark's main, guarded as the CLI's is: a bad option value or an error from the library
// ends the program with one line that says what was wrong, and exit status 2 (bad values and
// options) or 1 (anything else), instead of aborting on an uncaught exception.
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include "scalespace/core/Error.hpp"

namespace scalespace::bench {

/// `text`, the value given to `flag`, read whole as a number; throws std::invalid_argument naming
/// the flag otherwise ("1e-3" and "7" are numbers, "abc", "" and "7x" are not).
inline double parseNumber(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::invalid_argument(flag + " takes a number, not '" + text + "'");
  return value;
}

/// The same, for a count: a whole number >= 0.
inline std::size_t parseCount(const std::string& flag, const std::string& text) {
  const double value = parseNumber(flag, text);
  if (!(value >= 0 && value <= 1e15) || value != double(std::size_t(value)))
    throw std::invalid_argument(flag + " takes a whole number >= 0, not '" + text + "'");
  return std::size_t(value);
}

/// The same, for a whole number of either sign.
inline int parseInteger(const std::string& flag, const std::string& text) {
  const double value = parseNumber(flag, text);
  if (!(std::abs(value) <= 1e9) || value != double(int(value)))
    throw std::invalid_argument(flag + " takes a whole number, not '" + text + "'");
  return int(value);
}

/// The value after the flag argv[i - 1].
inline double numberArgument(char** argv, int i) { return parseNumber(argv[i - 1], argv[i]); }
inline std::size_t countArgument(char** argv, int i) { return parseCount(argv[i - 1], argv[i]); }
inline int integerArgument(char** argv, int i) { return parseInteger(argv[i - 1], argv[i]); }

/// Runs `body` (the benchmark, returning its exit status) and turns what it throws into one line
/// on stderr, "NAME: error: WHAT".
template <class Body>
int guardedMain(const char* name, Body&& body) {
  try {
    return body();
  } catch (const std::exception& error) {
    // A bad value or option (ours or the library's) is the caller's mistake: exit 2, as CLI11.
    const bool usage = dynamic_cast<const std::invalid_argument*>(&error) != nullptr ||
                       dynamic_cast<const OptionError*>(&error) != nullptr;
    std::fprintf(stderr, "%s: error: %s\n", name, error.what());
    return usage ? 2 : 1;
  }
}

}  // namespace scalespace::bench
