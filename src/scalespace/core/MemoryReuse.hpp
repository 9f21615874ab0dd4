#pragma once
// Keeping freed memory for reuse. The per-scale work of the library (a layer of every point's
// fits, region growing's seeds, labels and regions) allocates and frees arrays of tens of MB at
// every scale. glibc serves such blocks with mmap and gives them back with munmap, so each scale
// touches fresh pages: 700k page faults for `scalespace planes` on 1M points x 50 scales, which
// on this project's (virtual) machines cost more than the region growing itself.
//
// Programs (the CLI, the benchmarks) call retainFreedMemory() once at start-up: freed blocks then
// stay in the process and are reused by the next scale. The library itself never changes the
// allocator of the program it is linked into.
//
//   int main() { scalespace::retainFreedMemory(); ... }
//
// Measured (`scalespace planes` on Stairs 1M, --no-robust, 2 cores, runs interleaved with and
// without): 52.2 / 53.3 s against 56.8 / 70.3 s, 184k against 634k page faults, peak RSS 740
// against 654 MB; identical output.

namespace scalespace {

/// Makes glibc serve large blocks from the heap (no mmap) and never trim it, so that memory
/// freed by one step is reused by the next. Returns false when the C library is not glibc or
/// refused (nothing changes then: only speed is at stake).
bool retainFreedMemory();

}  // namespace scalespace
