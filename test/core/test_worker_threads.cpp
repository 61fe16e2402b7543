#include "klt_contour_tracker/core/worker_threads.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace kct {
namespace {

TEST(WorkerThreads, RejectsFewerThanOneThread) {
  EXPECT_THROW(WorkerThreads(0), std::invalid_argument);
  EXPECT_EQ(WorkerThreads(1).threads(), 1);
  EXPECT_EQ(WorkerThreads(3).threads(), 3);
}

TEST(WorkerThreads, ParallelForCallsEveryIndexOnce) {
  for (int threads : {1, 2, 4}) {
    WorkerThreads workers(threads);
    for (int n : {0, 1, 2, 3, 7, 100}) {
      std::vector<std::atomic<int>> calls(static_cast<std::size_t>(n));
      workers.parallel_for(n, [&](int i) { ++calls[static_cast<std::size_t>(i)]; });
      for (int i = 0; i < n; ++i)
        EXPECT_EQ(calls[static_cast<std::size_t>(i)].load(), 1)
            << "threads " << threads << ", n " << n << ", i " << i;
    }
  }
}

// What the leak fix rests on: the work runs on the same threads call after call, never on a
// new thread per call (OpenCV keeps data of every thread that called it). A thread_local flag
// counts thread instances (thread ids may be reused by a new thread).
std::atomic<int> threads_seen{0};
void note_thread() {
  thread_local bool seen = false;
  if (!seen) {
    seen = true;
    ++threads_seen;
  }
}

TEST(WorkerThreads, ReusesTheSameThreadsOnEveryCall) {
  note_thread();  // the caller
  const int before = threads_seen.load();
  WorkerThreads workers(3);
  for (int call = 0; call < 200; ++call) {
    workers.parallel_for(6, [&](int) {
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      note_thread();
    });
    workers.start([&]() { note_thread(); }).wait();
  }
  EXPECT_LE(threads_seen.load() - before, 2);  // the two workers at most
  EXPECT_GE(threads_seen.load() - before, 1);  // they took part
}

TEST(WorkerThreads, ParallelForRethrowsAfterEveryCallReturned) {
  WorkerThreads workers(2);
  std::atomic<int> calls{0};
  EXPECT_THROW(workers.parallel_for(10,
                                    [&](int i) {
                                      ++calls;
                                      if (i == 3) throw std::runtime_error("index 3");
                                    }),
               std::runtime_error);
  EXPECT_EQ(calls.load(), 10);
  // Still usable.
  std::atomic<int> again{0};
  workers.parallel_for(5, [&](int) { ++again; });
  EXPECT_EQ(again.load(), 5);
}

TEST(WorkerThreads, StartRunsOnAWorkerAndWaitRethrows) {
  WorkerThreads workers(2);
  std::thread::id ran_on;
  std::atomic<bool> ran{false};
  WorkerThreads::Pending pending = workers.start([&]() {
    ran_on = std::this_thread::get_id();
    ran = true;
  });
  // Not waited for yet: only the worker can run it (wait() would run it here if still queued).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!ran && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
  pending.wait();
  EXPECT_NE(ran_on, std::this_thread::get_id());

  WorkerThreads::Pending failing = workers.start([]() { throw std::runtime_error("boom"); });
  EXPECT_THROW(failing.wait(), std::runtime_error);
  EXPECT_FALSE(failing.valid());
}

TEST(WorkerThreads, StartWithoutWorkersRunsOnTheWaitingThread) {
  WorkerThreads workers(1);
  std::thread::id ran_on;
  bool ran = false;
  WorkerThreads::Pending pending = workers.start([&]() {
    ran = true;
    ran_on = std::this_thread::get_id();
  });
  EXPECT_TRUE(pending.valid());
  pending.wait();
  EXPECT_TRUE(ran);
  EXPECT_EQ(ran_on, std::this_thread::get_id());
}

TEST(WorkerThreads, DestroyingAPendingTaskWaitsForIt) {
  WorkerThreads workers(2);
  std::atomic<bool> started{false}, finished{false};
  {
    WorkerThreads::Pending pending = workers.start([&]() {
      started = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      finished = true;
    });
    while (!started) std::this_thread::yield();
  }
  EXPECT_TRUE(finished.load());
}

// A task of the only worker calls parallel_for on the same object (as the Tracker's
// preparation could): the caller does the work itself instead of waiting for a busy worker.
TEST(WorkerThreads, ParallelForInsideATaskOfTheSameObjectCompletes) {
  WorkerThreads workers(2);
  std::atomic<int> calls{0};
  workers.start([&]() { workers.parallel_for(8, [&](int) { ++calls; }); }).wait();
  EXPECT_EQ(calls.load(), 8);
}

}  // namespace
}  // namespace kct
