#pragma once
// The CLI's side of progress reporting: the library calls a ProgressCallback; this draws it on
// stderr — a bar redrawn in place on a terminal, a line every few seconds otherwise (logs, CI).
#include <chrono>
#include <string>

#include "scalespace/core/Progress.hpp"

namespace scalespace::cli {

/// A callback for library calls; it cancels (returns false) once cancelOnInterrupt's signals came.
/// `quiet` suppresses the drawing.
ProgressCallback makeProgressBar(bool quiet = false);

/// Makes SIGINT, SIGTERM and SIGHUP cancel the running library call through the progress
/// callbacks (the command then exits 130 and leaves no temporary output); a second signal ends
/// the program at once.
void cancelOnInterrupt();

/// Prints "<what> done in 1.23 s" on stderr (the final line of a long command).
void reportDone(const std::string& what, std::chrono::steady_clock::time_point start,
                bool quiet = false);

}  // namespace scalespace::cli
