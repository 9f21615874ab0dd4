#pragma once
// Progress reporting: the library never prints; long operations call a ProgressCallback with the
// fraction done in [0, 1] and the name of the current stage. Returning false cancels: the
// operation throws scalespace::Cancelled at its next check and leaves no output behind.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

#include "scalespace/core/Error.hpp"

namespace scalespace {

using ProgressCallback = std::function<bool(double fraction, std::string_view stage)>;

/// Thread-safe helper for parallel loops: workers call advance(n); the callback is invoked at most
/// every `interval` (from whichever thread crosses it), never concurrently.
class ProgressTracker {
 public:
  ProgressTracker(const ProgressCallback& callback, std::string stage, std::size_t total,
                  std::chrono::milliseconds interval = std::chrono::milliseconds(100))
      : callback_(callback), stage_(std::move(stage)), total_(total), interval_(interval) {}

  /// Adds `n` finished items. Throws Cancelled if the callback asked to stop.
  void advance(std::size_t n) {
    const std::size_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (cancelled_.load(std::memory_order_relaxed)) throw Cancelled();
    if (!callback_) return;
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    auto last = lastReport_.load(std::memory_order_relaxed);
    if (now - last <
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(interval_).count())
      return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    lastReport_.store(now, std::memory_order_relaxed);
    report(done);
  }

  /// Reports completion (fraction 1). Call once, from one thread, after the loop.
  void finish() {
    if (callback_) {
      std::lock_guard<std::mutex> lock(mutex_);
      report(total_);
    }
    if (cancelled_.load()) throw Cancelled();
  }

  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  void report(std::size_t done) {
    const double f = total_ == 0 ? 1.0 : std::min(1.0, double(done) / double(total_));
    if (!callback_(f, stage_)) cancelled_.store(true);
  }

  ProgressCallback callback_;  // a copy: callers may pass a temporary (a wrapping lambda)
  std::string stage_;
  std::size_t total_;
  std::chrono::milliseconds interval_;
  std::atomic<std::size_t> done_{0};
  std::atomic<long long> lastReport_{0};
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;
};

/// The part [from, to] of a progress callback, for one stage of a longer operation (empty when
/// `progress` is).
inline ProgressCallback subProgress(const ProgressCallback& progress, double from, double to) {
  if (!progress) return {};
  return [progress, from, to](double f, std::string_view stage) {
    return progress(from + f * (to - from), stage);
  };
}

}  // namespace scalespace
