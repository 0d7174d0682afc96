#pragma once
// A fixed set of threads that run the chunks of one job at a time, for the element and node loops
// of a step. A job allocates nothing: chunks are claimed from one atomic word, and idle workers
// spin briefly (the next job of a step follows within microseconds) before they sleep on a
// condition variable (the lock is taken only to wake a sleeping worker; the haptic servo never
// runs a job). Which thread runs a chunk never changes a result: callers write each
// chunk's output to its own place and combine chunk results in chunk order.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace liversim {

class WorkerPool {
 public:
  // thread_count threads in all, the caller of run() counted: thread_count − 1 are started here.
  explicit WorkerPool(int thread_count);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int thread_count() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls task(chunk) once for every chunk in [0, chunk_count), on the pool's threads and the
  // caller's, and returns when all are done. The task must not throw. A call made while the pool
  // is busy with another job (from another thread, or from inside a task) runs its chunks on the
  // calling thread alone.
  template <typename Task>
  void run(std::size_t chunk_count, Task&& task) {
    using Callable = std::remove_reference_t<Task>;
    run_erased(chunk_count, const_cast<void*>(static_cast<const void*>(&task)),
               [](void* t, std::size_t chunk) noexcept { (*static_cast<Callable*>(t))(chunk); });
  }

  static constexpr std::size_t kMaxChunks = (std::size_t{1} << 20) - 1;

 private:
  using Call = void (*)(void*, std::size_t) noexcept;
  void run_erased(std::size_t chunk_count, void* task, Call call);
  void work();
  // Claims and runs chunks of the current job until none is left.
  void run_claimed_chunks();
  void wake_workers();

  std::vector<std::thread> workers_;
  // The current job, packed as [job number: 24 bits][chunk count: 20][next chunk: 20], so that a
  // claim from a finished job can never succeed against a new one.
  alignas(64) std::atomic<std::uint64_t> job_{0};
  alignas(64) std::atomic<std::size_t> done_{0};  // chunks of the current job finished
  alignas(64) std::atomic<std::uint32_t> generation_{
      0};                         // bumped per job and at shutdown: wakes workers
  std::atomic<int> sleepers_{0};  // workers asleep or about to be
  std::mutex sleep_mutex_;
  std::condition_variable wake_;
  std::atomic<bool> busy_{false};  // a job is in flight
  std::atomic<bool> stop_{false};
  void* task_ = nullptr;  // written before a job is published, read only after a claim
  Call call_ = nullptr;
};

// The threads the engine uses by default: LIVERSIM_THREADS when set, else the hardware's threads
// (at least 1). Throws std::invalid_argument naming the variable and its value when it is set to
// anything but a whole number from 1 to 256.
int default_engine_threads();

// A pool of `thread_count` threads, or null for one thread (no pool needed).
std::shared_ptr<WorkerPool> make_worker_pool(int thread_count);

// The process's pool of default_engine_threads() threads, made on first use (null: one thread);
// throws as default_engine_threads does.
// The command line and the benchmarks step with it (the real-time loop with realtime_worker_pool);
// tests make their own.
std::shared_ptr<WorkerPool> shared_worker_pool();

// The threads the real-time loop steps with: LIVERSIM_THREADS when set, else the hardware's
// threads less one (at least 1). The core left over is the haptic servo's, the station's frame's
// (metrics, the database writer) and the window's rendering: on 2 cores they otherwise preempt the
// force loop's worker in the middle of its chunk and the loop waits for it (the bimanual wedge
// resection fell behind in 25–29 of 32 s on two threads, 11–19 on one: docs/cutting.md).
// Throws as default_engine_threads does.
int realtime_engine_threads();

// The process's pool of realtime_engine_threads() threads, made on first use (null: one thread).
// What the workstation's real-time loop and its replays step with.
std::shared_ptr<WorkerPool> realtime_worker_pool();

}  // namespace liversim
