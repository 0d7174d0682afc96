#pragma once
// One piece of work at a time on a thread of its own, for work that must not hold up the thread
// that starts it (building a scene, a session's metrics, a study): the owner starts it, is told
// when it has finished (`finished` runs on the worker, to wake the owner: a queued call in a Qt
// window, nothing for an owner that polls done()), and takes it with wait(). The result travels in
// whatever the work writes; done() (acquire) makes it visible to the owner.

#include <atomic>
#include <functional>
#include <thread>

namespace liversim {

class BackgroundJob {
 public:
  BackgroundJob() = default;
  BackgroundJob(const BackgroundJob&) = delete;
  BackgroundJob& operator=(const BackgroundJob&) = delete;
  ~BackgroundJob() { wait(); }

  // Starts `work`; a job started before is waited for first.
  void start(std::function<void()> work, std::function<void()> finished = {}) {
    wait();
    done_.store(false, std::memory_order_relaxed);
    thread_ = std::thread([this, work = std::move(work), finished = std::move(finished)] {
      work();
      done_.store(true, std::memory_order_release);
      if (finished) finished();
    });
  }
  // Started and not yet waited for.
  bool started() const { return thread_.joinable(); }
  // Its work has finished (its thread may still be ending: wait() takes it).
  bool done() const { return thread_.joinable() && done_.load(std::memory_order_acquire); }
  // Blocks until the work has finished and its thread has ended.
  void wait() {
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::thread thread_;
  std::atomic<bool> done_{false};
};

}  // namespace liversim
