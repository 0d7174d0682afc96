// The worker pool runs every chunk of a job exactly once, on more than one thread, and falls back
// to the caller's thread when it is busy; jobs follow each other without loss.
#include "liversim/engine/worker_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace liversim {
namespace {

TEST(WorkerPool, RunsEveryChunkOnceOverManyJobs) {
  WorkerPool pool(2);
  EXPECT_EQ(pool.thread_count(), 2);
  std::vector<std::atomic<int>> runs(97);
  for (int job = 0; job < 2000; ++job) {
    const std::size_t chunks = 1 + job % runs.size();
    pool.run(chunks, [&](std::size_t c) { runs[c].fetch_add(1, std::memory_order_relaxed); });
  }
  // Chunk c belongs to every job with more than c chunks.
  for (std::size_t c = 0; c < runs.size(); ++c) {
    int expected = 0;
    for (int job = 0; job < 2000; ++job) expected += (1 + job % runs.size()) > c;
    EXPECT_EQ(runs[c].load(), expected) << "chunk " << c;
  }
}

TEST(WorkerPool, SharesTheChunksOfALongJob) {
  WorkerPool pool(2);
  std::mutex mutex;
  std::set<std::thread::id> threads;
  // Chunks long enough that the worker wakes up before the caller has done them all.
  for (int attempt = 0; attempt < 20 && threads.size() < 2; ++attempt)
    pool.run(64, [&](std::size_t) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
      while (std::chrono::steady_clock::now() < until) {
      }
      const std::lock_guard lock(mutex);
      threads.insert(std::this_thread::get_id());
    });
  EXPECT_EQ(threads.size(), 2u);
}

TEST(WorkerPool, ANestedJobRunsOnTheCallingThread) {
  WorkerPool pool(2);
  std::atomic<int> inner{0};
  pool.run(8, [&](std::size_t) {
    const auto self = std::this_thread::get_id();
    pool.run(4, [&](std::size_t) {
      EXPECT_EQ(std::this_thread::get_id(), self);
      inner.fetch_add(1);
    });
  });
  EXPECT_EQ(inner.load(), 32);
}

TEST(WorkerPool, TwoCallersAtOnceBothFinish) {
  WorkerPool pool(2);
  std::atomic<long> total{0};
  auto caller = [&] {
    for (int job = 0; job < 500; ++job) pool.run(16, [&](std::size_t c) { total += c; });
  };
  std::thread other(caller);
  caller();
  other.join();
  EXPECT_EQ(total.load(), 2L * 500 * (15 * 16 / 2));
}

// A bad LIVERSIM_THREADS is named with its value, not silently replaced by the default.
TEST(WorkerPool, ABadThreadCountInTheEnvironmentIsNamed) {
  for (const char* bad : {"abc", "0", "-2", "3x", "", "1000"}) {
    ASSERT_EQ(setenv("LIVERSIM_THREADS", bad, 1), 0);
    try {
      default_engine_threads();
      ADD_FAILURE() << "no error for LIVERSIM_THREADS='" << bad << "'";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("LIVERSIM_THREADS = '" + std::string(bad) + "'"), std::string::npos)
          << message;
    }
  }
  ASSERT_EQ(setenv("LIVERSIM_THREADS", "3", 1), 0);
  EXPECT_EQ(default_engine_threads(), 3);
  ASSERT_EQ(unsetenv("LIVERSIM_THREADS"), 0);
  EXPECT_GE(default_engine_threads(), 1);
}

TEST(WorkerPool, TheRealTimeLoopLeavesOneCoreToTheServoAndTheFrame) {
  const char* set = std::getenv("LIVERSIM_THREADS");
  const std::string kept = set ? set : "";
  ASSERT_EQ(unsetenv("LIVERSIM_THREADS"), 0);
  const int hardware = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 256u));
  EXPECT_EQ(default_engine_threads(), hardware);
  EXPECT_EQ(realtime_engine_threads(), std::max(1, hardware - 1));
  // The variable, when set, is the real-time loop's too, and a bad one is named as for the rest.
  ASSERT_EQ(setenv("LIVERSIM_THREADS", "2", 1), 0);
  EXPECT_EQ(realtime_engine_threads(), 2);
  ASSERT_EQ(setenv("LIVERSIM_THREADS", "0", 1), 0);
  EXPECT_THROW(realtime_engine_threads(), std::invalid_argument);
  if (set)
    setenv("LIVERSIM_THREADS", kept.c_str(), 1);
  else
    unsetenv("LIVERSIM_THREADS");
}

TEST(WorkerPool, RefusesAThreadCountOutOfRange) {
  EXPECT_THROW(WorkerPool(0), std::invalid_argument);
  EXPECT_EQ(make_worker_pool(1), nullptr);  // one thread: no pool
  EXPECT_GE(default_engine_threads(), 1);
}

}  // namespace
}  // namespace liversim
