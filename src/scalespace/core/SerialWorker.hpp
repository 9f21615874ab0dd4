#pragma once
// SerialWorker: runs jobs one after the other on a background thread, in submission order, while
// the caller goes on. A driver whose per-step work has a sequential part (e.g. region growing
// after each scale of the multi-scale stack) hands it over, so that the next step's parallel
// work fills the core that the sequential part would leave idle.
//
//   SerialWorker worker(2);          // at most 2 jobs waiting
//   for (...) worker.submit([=] { ... });
//   worker.finish();                 // waits for all jobs; rethrows the first job's exception
//
// Results must not depend on timing: jobs write to their own slots. Submitting blocks while
// `capacity` jobs are waiting (this bounds the memory the jobs hold). If a job throws, the later
// jobs are skipped and every later submit() and finish() rethrows its exception. The destructor
// drops waiting jobs and joins (when the caller unwinds from an exception or a cancellation).
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace scalespace {

class SerialWorker {
 public:
  explicit SerialWorker(std::size_t capacity);
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void submit(std::function<void()> job);
  void finish();

 private:
  void run();
  void rethrowFailure();

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr failure_;
  std::thread thread_;
};

}  // namespace scalespace
