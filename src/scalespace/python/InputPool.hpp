#pragma once
// The memory of the input copies, kept from one call to the next. Every call copies its (N, 3)
// arrays into a PointCloud (positions recentred, normals), 48 MB for 1M points with normals. glibc
// serves blocks that large with mmap and unmaps them when freed, so without reuse each call paid
// the kernel for faulting 48 MB of fresh pages in (about 8 ms per 1M points) and for unmapping
// them at the end (about 6 ms): more than the copies themselves. The pool keeps the last call's
// positions' and normals' buffers (up to kMaxPooledBytes), so a repeated call of a similar size
// copies into memory that is already mapped. Only this module's own buffers are kept: the
// allocator of the Python process is left as it is (scalespace.retain_freed_memory() is the
// opt-in that changes it for every block).
//
// Thread-safe: a call takes the pooled buffers out (a concurrent call finds none and allocates
// its own), and gives its buffers back when its cloud is destroyed; of two sets given back the
// larger one stays. scalespace.release_buffers() frees what the pool holds.
#include <cstddef>
#include <utility>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::python {

/// Buffers above this are freed, not kept (a 5M-point call with normals holds 240 MB): for such
/// clouds the page faults are a negligible share of any library call, and keeping them would
/// hold that much memory while the process does something else.
inline constexpr std::size_t kMaxPooledBytes = std::size_t(256) << 20;

/// A cloud built on the pool's buffers that gives them back to the pool when destroyed. Build it
/// with makeCloud (Bridge.hpp); otherwise it is the PointCloud every algorithm takes.
class PooledCloud : public PointCloud {
 public:
  PooledCloud() = default;  // no buffers taken: filled by assigning a makeCloud result
  /// Takes the pool's buffers (none when another call holds them).
  static PooledCloud fromPool();
  PooledCloud(PooledCloud&&) noexcept = default;
  PooledCloud& operator=(PooledCloud&&) noexcept = default;
  using PointCloud::operator=;  // e.g. a mesh's sampled cloud replacing the input
  ~PooledCloud() { recycle(); }

  /// Gives the buffers back to the pool now (the cloud is left empty), e.g. once the results are
  /// out; the destructor does it otherwise.
  void recycle();

 private:
  explicit PooledCloud(Storage storage) : PointCloud(std::move(storage)) {}
};

/// Frees the pooled buffers; returns how many bytes they held.
std::size_t releaseBuffers();

}  // namespace scalespace::python
