#pragma once
// A bounded single-producer / single-consumer queue without locks: the producer (the 1 kHz servo)
// never waits and never allocates; when the consumer falls behind, new items are dropped and
// counted rather than blocking the producer.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace liversim {

template <typename T>
class SpscRing {
 public:
  // Storage for `capacity` items, allocated here, once.
  explicit SpscRing(std::size_t capacity) : items_(capacity + 1) {}

  // Producer. Returns false (and counts the item dropped) when the ring is full.
  bool push(const T& item) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = head + 1 == items_.size() ? 0 : head + 1;
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    items_[head] = item;
    head_.store(next, std::memory_order_release);
    return true;
  }

  // Consumer. Returns false when empty.
  bool pop(T& item) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    item = items_[tail];
    tail_.store(tail + 1 == items_.size() ? 0 : tail + 1, std::memory_order_release);
    return true;
  }

  std::size_t capacity() const { return items_.size() - 1; }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::vector<T> items_;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace liversim
