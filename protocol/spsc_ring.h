#pragma once
/// \file
/// The bounded single-producer single-consumer ring, the project's one (the shape of PipeWire's
/// spa/utils/ringbuffer.h): trivially copyable values, no locks, the capacity a power of two.
///
/// SpscRingRef<T> is the protocol over storage the caller owns: two indices on their own cache
/// lines (SpscIndices) and the slots. Placed in a shared-memory segment it is protocol/shm.h's
/// command ring; SpscRing<T> is the in-process form that owns its slots (the daemon's command,
/// edit, event and record rings).
///
/// Threads: exactly one thread calls the producer's push() and exactly one (other) thread the
/// consumer's pop(), front(), dropFront() and resync(); size() any thread. None of them allocates,
/// locks or blocks (servo-thread safe); SpscRing's construction allocates.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace hapticd::proto {

/// The ring's indices: head written by the producer, tail by the consumer; both count every value
/// ever pushed or popped (slot = index & (capacity − 1)).
struct SpscIndices {
  alignas(64) std::atomic<std::uint64_t> head{0};  ///< next slot the producer writes
  alignas(64) std::atomic<std::uint64_t> tail{0};  ///< next slot the consumer reads
};
static_assert(sizeof(SpscIndices) == 128);
static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

/// The ring protocol on caller-owned indices and `capacity` (a power of two, at least 2) slots.
template <class T>
class SpscRingRef {
  static_assert(std::is_trivially_copyable_v<T>, "a ring holds trivially copyable values");

 public:
  SpscRingRef(SpscIndices& indices, T* slots, std::size_t capacity) noexcept
      : ix_(indices), slots_(slots), mask_(capacity - 1) {}

  /// Producer only. False (and nothing stored) when the ring is full.
  bool push(const T& value) noexcept {
    const std::uint64_t head = ix_.head.load(std::memory_order_relaxed);
    if (head - ix_.tail.load(std::memory_order_acquire) > mask_)
      return false;
    slots_[head & mask_] = value;
    ix_.head.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only. False when the ring is empty.
  bool pop(T& out) noexcept {
    const std::uint64_t tail = ix_.tail.load(std::memory_order_relaxed);
    if (tail == ix_.head.load(std::memory_order_acquire))
      return false;
    out = slots_[tail & mask_];
    ix_.tail.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only: the value pop() would take next, without taking it (nullptr when empty).
  /// Valid until the consumer's next pop() or dropFront().
  const T* front() const noexcept {
    const std::uint64_t tail = ix_.tail.load(std::memory_order_relaxed);
    if (tail == ix_.head.load(std::memory_order_acquire))
      return nullptr;
    return &slots_[tail & mask_];
  }

  /// Consumer only: drops the front value (after front()); false when empty.
  bool dropFront() noexcept {
    const std::uint64_t tail = ix_.tail.load(std::memory_order_relaxed);
    if (tail == ix_.head.load(std::memory_order_acquire))
      return false;
    ix_.tail.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only: when the head is more than a capacity ahead of the tail (a broken producer,
  /// e.g. another process writing the indices of a shared segment) skips everything queued and
  /// returns how many values that was; 0 (nothing done) otherwise.
  std::uint64_t resync() noexcept {
    const std::uint64_t tail = ix_.tail.load(std::memory_order_relaxed);
    const std::uint64_t head = ix_.head.load(std::memory_order_acquire);
    if (head - tail <= mask_ + 1)
      return 0;
    ix_.tail.store(head, std::memory_order_release);
    return head - tail;
  }

  /// Either side: values queued now (a snapshot).
  std::size_t size() const noexcept {
    return static_cast<std::size_t>(ix_.head.load(std::memory_order_acquire) -
                                    ix_.tail.load(std::memory_order_acquire));
  }
  std::size_t capacity() const noexcept { return mask_ + 1; }

 private:
  SpscIndices& ix_;
  T* slots_;
  std::size_t mask_;
};

/// The in-process ring: owns its slots; capacity fixed at construction.
template <class T>
class SpscRing {
 public:
  /// `capacity` is rounded up to a power of two (at least 2). Allocates; off the servo thread.
  explicit SpscRing(std::size_t capacity) {
    std::size_t c = 2;
    while (c < capacity)
      c <<= 1;
    capacity_ = c;
    slots_ = std::make_unique<T[]>(c);
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  /// Producer only. False (and nothing stored) when the ring is full.
  bool push(const T& value) noexcept { return ref().push(value); }
  /// Consumer only. False when the ring is empty.
  bool pop(T& out) noexcept { return ref().pop(out); }
  /// Consumer only: the value pop() would take next (nullptr when empty); valid until the
  /// consumer's next pop() or dropFront().
  const T* front() const noexcept { return ref().front(); }
  /// Consumer only: drops the front value (after front()); false when empty.
  bool dropFront() noexcept { return ref().dropFront(); }
  /// Either side: values queued now (a snapshot).
  std::size_t size() const noexcept { return ref().size(); }
  std::size_t capacity() const noexcept { return capacity_; }
  bool empty() const noexcept { return size() == 0; }

 private:
  SpscRingRef<T> ref() const noexcept { return {ix_, slots_.get(), capacity_}; }

  std::unique_ptr<T[]> slots_;
  std::size_t capacity_ = 0;
  mutable SpscIndices ix_;  // the atomics; const members only read them
};

}  // namespace hapticd::proto
