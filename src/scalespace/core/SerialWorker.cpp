#include "scalespace/core/SerialWorker.hpp"

#include <utility>

namespace scalespace {

SerialWorker::SerialWorker(std::size_t capacity)
    : capacity_(capacity < 1 ? 1 : capacity), thread_([this] { run(); }) {}

SerialWorker::~SerialWorker() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    jobs_.clear();
  }
  changed_.notify_all();
  thread_.join();
}

void SerialWorker::submit(std::function<void()> job) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return jobs_.size() < capacity_ || failure_; });
  if (failure_) {
    lock.unlock();
    rethrowFailure();
  }
  jobs_.push_back(std::move(job));
  lock.unlock();
  changed_.notify_all();
}

void SerialWorker::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return (jobs_.empty() && !busy_) || failure_; });
  lock.unlock();
  rethrowFailure();
}

void SerialWorker::rethrowFailure() {
  std::exception_ptr failure;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    failure = failure_;  // sticky: every later submit() and finish() reports it
  }
  if (failure) std::rethrow_exception(failure);
}

void SerialWorker::run() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
      if (stopping_) return;
      job = std::move(jobs_.front());
      jobs_.pop_front();
      busy_ = true;
    }
    std::exception_ptr failure;
    try {
      job();
    } catch (...) {
      failure = std::current_exception();
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      if (failure) {
        failure_ = failure;
        jobs_.clear();  // the later jobs depend on a failed run: skip them
      }
    }
    changed_.notify_all();
  }
}

}  // namespace scalespace
