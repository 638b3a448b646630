#pragma once
/// \file
/// A bounded single-producer single-consumer ring of trivially copyable values, without locks
/// (the shape of PipeWire's spa/utils/ringbuffer.h). Capacity fixed at construction.
///
/// Threads: exactly one thread calls push() and exactly one (other) thread calls pop(); the
/// construction allocates, push() and pop() never allocate, lock or block.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace hapticd::daemon {

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing holds trivially copyable values");

 public:
  /// `capacity` is rounded up to a power of two (at least 2). Allocates; off the servo thread.
  explicit SpscRing(std::size_t capacity) {
    std::size_t c = 2;
    while (c < capacity)
      c <<= 1;
    mask_ = c - 1;
    slots_ = std::make_unique<T[]>(c);
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  /// Producer only. False (and nothing stored) when the ring is full.
  bool push(const T& value) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) > mask_)
      return false;
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only. False when the ring is empty.
  bool pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire))
      return false;
    out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only: the value pop() would take next, without taking it (nullptr when empty).
  /// Valid until the consumer's next pop().
  const T* front() const noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire))
      return nullptr;
    return &slots_[tail & mask_];
  }

  /// Consumer only: drops the front value (after front()); false when empty.
  bool dropFront() noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire))
      return false;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Either side: values queued now (a snapshot).
  std::size_t size() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_acquire));
  }
  std::size_t capacity() const noexcept { return mask_ + 1; }
  bool empty() const noexcept { return size() == 0; }

 private:
  std::unique_ptr<T[]> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // written by the producer
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // written by the consumer
};

}  // namespace hapticd::daemon
