// SerialWorker: jobs run in order on one thread, the queue is bounded, failures come back.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "scalespace/core/SerialWorker.hpp"

using namespace scalespace;

TEST(SerialWorker, RunsJobsInSubmissionOrder) {
  std::vector<int> done;  // touched by the worker only until finish()
  SerialWorker worker(2);
  for (int k = 0; k < 100; ++k) worker.submit([&done, k] { done.push_back(k); });
  worker.finish();
  ASSERT_EQ(done.size(), 100u);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(done[std::size_t(k)], k);
  worker.submit([&done] { done.push_back(100); });  // usable again after finish()
  worker.finish();
  EXPECT_EQ(done.back(), 100);
}

TEST(SerialWorker, SubmitBlocksWhileTheQueueIsFull) {
  std::atomic<bool> release{false};
  std::atomic<int> started{0};
  SerialWorker worker(1);
  auto slow = [&] {
    ++started;
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  worker.submit(slow);  // runs
  while (started == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  worker.submit(slow);  // waits in the queue
  std::atomic<bool> thirdSubmitted{false};
  std::thread producer([&] {
    worker.submit([] {});
    thirdSubmitted = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(thirdSubmitted);  // the queue holds one job: the producer waits
  release = true;
  producer.join();
  worker.finish();
  EXPECT_TRUE(thirdSubmitted);
  EXPECT_EQ(started, 2);
}

TEST(SerialWorker, AFailingJobSkipsTheRestAndIsRethrown) {
  std::atomic<int> ran{0};
  SerialWorker worker(8);
  worker.submit([&] { ++ran; });
  worker.submit([] { throw std::runtime_error("region growing failed"); });
  for (int k = 0; k < 5; ++k) {
    try {
      worker.submit([&] { ++ran; });
    } catch (const std::runtime_error&) {
      break;  // the failure may already be known when submitting
    }
  }
  EXPECT_THROW(
      {
        try {
          worker.finish();
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "region growing failed");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_EQ(ran, 1);
}

TEST(SerialWorker, DestructorFinishesTheRunningJobAndDropsTheWaitingOnes) {
  std::atomic<int> ran{0};
  std::atomic<bool> started{false};
  {
    SerialWorker worker(4);
    worker.submit([&] {
      started = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++ran;
    });
    for (int k = 0; k < 3; ++k) worker.submit([&] { ran += 10; });
    while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }                   // e.g. a cancelled stack unwinding
  EXPECT_EQ(ran, 1);  // the running job completed; the three waiting ones never ran
}
