#include "scalespace/python/InputPool.hpp"

#include <mutex>
#include <utility>

namespace scalespace::python {
namespace {

std::mutex poolMutex;
PointCloud::Storage pooled;  // guarded by poolMutex

// Swaps `storage` with the pool's under the lock; the buffers that come out are freed by the
// caller, outside it (unmapping tens of MB takes milliseconds).
void exchange(PointCloud::Storage& storage) {
  std::lock_guard<std::mutex> lock(poolMutex);
  std::swap(storage, pooled);
}

}  // namespace

PooledCloud PooledCloud::fromPool() {
  PointCloud::Storage storage;
  exchange(storage);
  return PooledCloud(std::move(storage));
}

void PooledCloud::recycle() {
  PointCloud::Storage storage = releaseStorage();
  const std::size_t bytes = storage.bytes();
  if (bytes == 0 || bytes > kMaxPooledBytes) return;  // nothing to keep, or too much
  std::lock_guard<std::mutex> lock(poolMutex);
  // Of two calls' buffers (concurrent calls), the larger serve both sizes: keep those.
  if (bytes > pooled.bytes()) std::swap(storage, pooled);
  // The unlock comes before `storage` (now the smaller set) is freed: declared first, it is
  // destroyed after the lock_guard.
}

std::size_t releaseBuffers() {
  PointCloud::Storage storage;
  exchange(storage);
  return storage.bytes();
}

}  // namespace scalespace::python
