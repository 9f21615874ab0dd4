#include "scalespace/core/MemoryReuse.hpp"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace scalespace {

bool retainFreedMemory() {
#if defined(__GLIBC__)
  // M_MMAP_MAX 0: no block is mmapped (large ones come from the heap, the main arena's when a
  // thread's arena cannot hold them); M_TRIM_THRESHOLD at its maximum: the heap's free top is
  // kept. M_MMAP_MAX 0 rather than a raised mmap threshold (e.g. 32 MB): a threshold keeps in the
  // heap only the arrays below it, not those of clouds of a few million points.
  const bool noMmap = mallopt(M_MMAP_MAX, 0) == 1;
  const bool noTrim = mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
  return noMmap && noTrim;
#else
  return false;
#endif
}

}  // namespace scalespace
