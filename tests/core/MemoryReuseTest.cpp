// MemoryReuse: after retainFreedMemory(), large blocks come from the heap and stay for reuse.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "scalespace/core/MemoryReuse.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

TEST(MemoryReuse, LargeBlocksAreNotMappedAndFreedOnesAreKept) {
  if (!scalespace::retainFreedMemory())
    GTEST_SKIP() << "not glibc, or the allocator is replaced (sanitizer builds)";
#if defined(__GLIBC__)
  const std::size_t bytes = 48u << 20;  // far above glibc's default 128 kB mmap threshold
  {
    std::vector<char> block(bytes, 1);
    EXPECT_EQ(mallinfo2().hblks, 0u);  // no mmapped block
  }
  // Freed, not returned to the system: the heap still holds at least the block.
  EXPECT_GE(mallinfo2().fordblks + mallinfo2().uordblks, bytes);
  std::vector<char> again(bytes, 2);
  EXPECT_EQ(again[bytes - 1], 2);
#endif
}
