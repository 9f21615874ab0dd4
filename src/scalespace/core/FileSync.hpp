#pragma once
// The POSIX file primitives that every writer and reader of the library shares: durable renames
// need an fsync of the file and of its directory, and write() / pread() may transfer fewer bytes
// than asked (or be interrupted), so each call site would otherwise loop on its own. In core so
// that io (AtomicFile.cpp) and scales (the stack store, docs/STACK_FORMAT.md) use the same code
// without scales linking io.
#include <cstddef>
#include <cstdint>
#include <string>

namespace scalespace {

/// fsync of a file or a directory by path, so that a following rename never exposes a file whose
/// content (or a directory whose entries) is still only in the page cache. Best effort: a path that
/// cannot be opened is skipped (the data was written; only its durability is not waited for).
void syncPath(const std::string& path);

/// Writes all `size` bytes to `fd`, retrying short writes and EINTR. FileError naming `file` on
/// failure (e.g. a full disk).
void writeAll(int fd, const void* data, std::size_t size, const std::string& file);

/// Reads exactly `size` bytes at `offset` of `fd`, retrying short reads and EINTR. FileError naming
/// `file` and the offset on a read error or an early end of file, with `fix` as its fix (what the
/// caller knows about repairing the file, e.g. recomputing it).
void preadAll(int fd, void* data, std::size_t size, std::uint64_t offset, const std::string& file,
              const std::string& fix);

}  // namespace scalespace
