#pragma once
// Thin helpers over TBB so that drivers and the CLI (--threads N) control parallelism in one place.
// Every parallel loop of the library computes each item independently of the partition, so
// results are identical for any thread count; these helpers only decide how many threads run.
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <optional>

#include "scalespace/core/Error.hpp"

namespace scalespace {

/// Calls f(i) for every i in [0, n) in parallel, in chunks of about `grain` items.
template <class F>
void parallelFor(std::size_t n, F f, std::size_t grain = 256) {
  if (grain == 0) grain = 1;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

/// While alive, limits every TBB loop of the process to `threads` threads (0 = all cores).
/// Create one in main() from the --threads option; nested limits take the smallest value.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads) {
    if (threads < 0)
      throw OptionError("the thread count (threads option) must be >= 0 (0 = all cores), got " +
                        std::to_string(threads));
    if (threads > 0)
      control_.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  }
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

  /// The number of threads TBB loops may use now (all limits in force taken into account).
  static std::size_t active() {
    return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  }

 private:
  std::optional<tbb::global_control> control_;
};

}  // namespace scalespace
