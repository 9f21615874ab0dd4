#pragma once
// Error policy of the library (docs/ERRORS.md):
//  - The library never prints and never returns NaN silently. Failures throw one of the types
//  below.
//  - FileError names the file, the place in it (line or byte offset) and what was expected, and
//    a fix when one is known; the CLI prints what() on one line and exits non-zero.
//  - OptionError is thrown for invalid parameters (names the option and the accepted range).
//  - Cancelled is thrown when a progress callback asks to stop; no output is left behind.
//  - Per-point numerical failures (too few neighbours, degenerate fit) are not exceptions: they
//    are reported through a validity flag in the result.
#include <stdexcept>
#include <string>

namespace scalespace {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FileError : public Error {
 public:
  /// `where` is e.g. "line 12" or "byte 4096"; may be empty. `fix` may be empty.
  FileError(const std::string& file, const std::string& where, const std::string& what,
            const std::string& fix = {})
      : Error(compose(file, where, what, fix)), file_(file) {}
  const std::string& file() const { return file_; }

 private:
  static std::string compose(const std::string& file, const std::string& where,
                             const std::string& what, const std::string& fix) {
    std::string s = file;
    if (!where.empty()) s += ": " + where;
    s += ": " + what;
    if (!fix.empty()) s += " (" + fix + ")";
    return s;
  }
  std::string file_;
};

class OptionError : public Error {
 public:
  using Error::Error;
};

class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled by the progress callback") {}
};

}  // namespace scalespace
