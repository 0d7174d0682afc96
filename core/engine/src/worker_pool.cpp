#include "liversim/engine/worker_pool.h"

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define LIVERSIM_CPU_RELAX() _mm_pause()
#else
#define LIVERSIM_CPU_RELAX() ((void)0)
#endif

namespace liversim {
namespace {

constexpr std::uint64_t kField = (std::uint64_t{1} << 20) - 1;
// Idle polls before a worker sleeps: about 50 µs, longer than the gap between the loops of one
// step, much shorter than the gap between frames.
constexpr int kSpinPolls = 20000;

std::uint64_t pack(std::uint64_t job, std::uint64_t count, std::uint64_t next) {
  return (job << 40) | (count << 20) | next;
}

}  // namespace

WorkerPool::WorkerPool(int thread_count) {
  if (thread_count < 1 || thread_count > 256)
    throw std::invalid_argument("worker pool: " + std::to_string(thread_count) +
                                " threads is invalid: expected 1 to 256");
  workers_.reserve(static_cast<std::size_t>(thread_count - 1));
  for (int i = 1; i < thread_count; ++i) workers_.emplace_back([this] { work(); });
}

WorkerPool::~WorkerPool() {
  stop_.store(true);
  generation_.fetch_add(1);
  {
    const std::lock_guard lock(sleep_mutex_);
    wake_.notify_all();
  }
  for (std::thread& worker : workers_) worker.join();
}

// After a bump of generation_: a worker counts itself a sleeper before it checks the generation
// and the publisher bumps before it reads the count (both sequentially consistent), so either
// the worker sees the new job or the publisher sees the sleeper and wakes it.
void WorkerPool::wake_workers() {
  if (sleepers_.load() == 0) return;
  const std::lock_guard lock(sleep_mutex_);
  wake_.notify_all();
}

void WorkerPool::run_claimed_chunks() {
  std::uint64_t job = job_.load(std::memory_order_acquire);
  for (;;) {
    const std::uint64_t count = (job >> 20) & kField, next = job & kField;
    if (next >= count) return;
    if (!job_.compare_exchange_weak(job, job + 1, std::memory_order_acquire,
                                    std::memory_order_acquire))
      continue;  // `job` now holds the current word
    call_(task_, static_cast<std::size_t>(next));
    done_.fetch_add(1, std::memory_order_release);
    job = job_.load(std::memory_order_acquire);
  }
}

void WorkerPool::run_erased(std::size_t chunk_count, void* task, Call call) {
  if (chunk_count == 0) return;
  if (workers_.empty() || chunk_count == 1 || chunk_count > kMaxChunks ||
      busy_.exchange(true, std::memory_order_acquire)) {
    for (std::size_t c = 0; c < chunk_count; ++c) call(task, c);
    return;
  }
  task_ = task;
  call_ = call;
  done_.store(0, std::memory_order_relaxed);
  const std::uint64_t number = ((job_.load(std::memory_order_relaxed) >> 40) + 1) & 0xffffff;
  job_.store(pack(number, chunk_count, 0), std::memory_order_release);
  generation_.fetch_add(1);
  wake_workers();
  run_claimed_chunks();
  // The last chunks may still run on workers.
  for (int polls = 0; done_.load(std::memory_order_acquire) < chunk_count; ++polls) {
    if (polls < kSpinPolls)
      LIVERSIM_CPU_RELAX();
    else
      std::this_thread::yield();
  }
  busy_.store(false, std::memory_order_release);
}

void WorkerPool::work() {
  // A worker that starts after a job was published leaves that job to the others; one that
  // starts after shutdown began sees stop_ (set before the last bump) and ends.
  std::uint32_t seen = generation_.load();
  for (;;) {
    int polls = 0;
    while (generation_.load(std::memory_order_acquire) == seen && !stop_.load() &&
           polls < kSpinPolls) {
      LIVERSIM_CPU_RELAX();
      ++polls;
    }
    if (generation_.load() == seen && !stop_.load()) {
      std::unique_lock lock(sleep_mutex_);
      sleepers_.fetch_add(1);
      wake_.wait(lock, [&] { return generation_.load() != seen || stop_.load(); });
      sleepers_.fetch_sub(1);
    }
    if (stop_.load()) return;
    seen = generation_.load(std::memory_order_acquire);
    run_claimed_chunks();
  }
}

namespace {

// LIVERSIM_THREADS, or nothing when it is not set; throws naming it when it is not a thread count.
std::optional<int> threads_from_environment() {
  if (const char* value = std::getenv("LIVERSIM_THREADS")) {
    char* end = nullptr;
    const long threads = std::strtol(value, &end, 10);
    if (end == value || *end != '\0' || threads < 1 || threads > 256)
      throw std::invalid_argument("LIVERSIM_THREADS = '" + std::string(value) +
                                  "' is invalid: expected a whole number of threads from 1 to 256");
    return static_cast<int>(threads);
  }
  return std::nullopt;
}

int hardware_threads() {
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware == 0 ? 1 : static_cast<int>(std::min(hardware, 256u));
}

}  // namespace

int default_engine_threads() {
  return threads_from_environment().value_or(hardware_threads());
}

int realtime_engine_threads() {
  return threads_from_environment().value_or(std::max(1, hardware_threads() - 1));
}

std::shared_ptr<WorkerPool> make_worker_pool(int thread_count) {
  if (thread_count <= 1) return nullptr;
  return std::make_shared<WorkerPool>(thread_count);
}

std::shared_ptr<WorkerPool> shared_worker_pool() {
  static const std::shared_ptr<WorkerPool> pool = make_worker_pool(default_engine_threads());
  return pool;
}

std::shared_ptr<WorkerPool> realtime_worker_pool() {
  static const std::shared_ptr<WorkerPool> pool = make_worker_pool(realtime_engine_threads());
  return pool;
}

}  // namespace liversim
