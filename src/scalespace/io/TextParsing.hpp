#pragma once
// Text helpers shared by the text readers and writers (internal to the io layer): a line scanner
// that counts lines for error messages, tokenisers, locale-independent number parsing, and
// shortest round-trip number formatting (std::to_chars), so text round trips are exact.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::io_detail {

inline std::string lineWhere(std::size_t line) { return "line " + std::to_string(line); }

class LineScanner {
 public:
  explicit LineScanner(std::string_view data) : data_(data) {}
  /// Next line without its "\n" / "\r\n"; false at the end of the data.
  bool next(std::string_view& line);
  std::size_t lineNumber() const { return line_; }  // 1-based number of the last line returned
  std::size_t offset() const { return offset_; }    // byte offset after the last line returned
  std::size_t remainingBytes() const { return data_.size() - offset_; }

 private:
  std::string_view data_;
  std::size_t offset_ = 0;
  std::size_t line_ = 0;
};

bool isSpace(char c);
std::string_view trim(std::string_view s);
/// Splits on spaces and tabs, dropping empty tokens.
void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens);
/// Splits on `separator`, trimming each field and keeping empty fields (so "1,,2" has 3 fields).
void splitOn(std::string_view line, char separator, std::vector<std::string_view>& tokens);

/// Locale-independent decimal parsing of the whole token (accepts a leading '+', "nan", "inf").
std::optional<double> parseNumber(std::string_view token);
/// Whole-token unsigned integer parsing (no sign, no exponent).
std::optional<unsigned long long> parseUnsigned(std::string_view token);
/// True if `value` is an integer within the range of `type` (floating types accept anything).
bool fitsScalarType(double value, ScalarType type);

/// Shortest text that reads back to exactly `value` ("nan", "inf", "-inf" for non-finite).
std::string formatNumber(double value);
/// As formatNumber, but the value is first converted to `type` (rounded/saturated for integer
/// types, rounded to float for Float32) so the text is what a binary writer would store.
std::string formatScalar(double value, ScalarType type);
/// `value` converted to `type` exactly as the binary writers store it (see formatScalar).
double toStoredValue(double value, ScalarType type);

std::string toLower(std::string_view s);
/// `token` in single quotes for an error message: at most 32 characters, non-printable bytes
/// shown as '?', so binary garbage never ends up in a terminal.
std::string quoted(std::string_view token);

}  // namespace scalespace::io_detail
