#pragma once
// Lock-free single-producer / single-consumer exchange of the newest value: the producer never
// waits for the consumer and the consumer always gets the most recent complete value.

#include <array>
#include <atomic>

namespace liversim {

template <typename T>
class TripleBuffer {
 public:
  // Fills every slot with `initial` so that storage is allocated once, up front.
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}

  T& back() { return slots_[back_]; }  // producer: write here, then publish()
  void publish() { back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex; }

  // Consumer: swaps in the newest published slot if there is one; returns whether it did.
  bool update() {
    if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return true;
  }
  const T& front() const { return slots_[front_]; }

 private:
  static constexpr int kIndex = 3, kFresh = 4;
  std::array<T, 3> slots_;
  int back_ = 0, front_ = 1;
  std::atomic<int> middle_{2};
};

}  // namespace liversim
