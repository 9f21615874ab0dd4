#pragma once
// Keeping freed memory for reuse. The per-scale work of the library (a layer of every point's
// fits, region growing's seeds, labels and regions) allocates and frees arrays of tens of MB at
// every scale. glibc serves such blocks with mmap and gives them back with munmap, so each scale
// touches fresh pages, and on virtual machines those page faults can cost more than the region
// growing itself.
//
// Programs (the CLI, the benchmarks) call retainFreedMemory() once at start-up: freed blocks then
// stay in the process and are reused by the next scale. The library itself never changes the
// allocator of the program it is linked into.
//
//   int main() { scalespace::retainFreedMemory(); ... }
//
// The output is identical; the price is a somewhat higher peak memory, since freed blocks stay in
// the process (figures of `scalespace planes` with and without it: bench/README.md).

namespace scalespace {

/// Makes glibc serve large blocks from the heap (no mmap) and never trim it, so that memory
/// freed by one step is reused by the next. Returns false when the C library is not glibc or
/// refused (nothing changes then: only speed is at stake).
bool retainFreedMemory();

}  // namespace scalespace
