#pragma once
// Atomic file writing, reusable by every layer: the content goes to a temporary file in the same
// directory (same file system, so the final rename is atomic), which is flushed, synced and then
// renamed over the target. On any failure the temporary file is removed and the target is left
// untouched, so a crash or a cancelled run never leaves a half-written output behind.
#include <functional>
#include <ostream>
#include <string>

namespace scalespace {

/// Calls `write` with a binary stream on a temporary file `<path>.tmp-<pid>-<random>`, then renames
/// it to `path`. Missing parent folders are created first. Exceptions thrown by `write` (e.g.
/// Cancelled) propagate after the cleanup; I/O failures throw FileError naming `path`.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace scalespace
