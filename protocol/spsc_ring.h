#pragma once
/// \file
/// A bounded single-producer single-consumer ring of trivially copyable values, lock-free and
/// allocation-free after construction (STYLE rule 6; after PipeWire spa/utils/ringbuffer.h).
/// The daemon carries CommandEvents from the server thread (producer) to the servo thread
/// (consumer) in one. push() on the producer thread only, pop() on the consumer thread only;
/// both are wait-free and servo-thread safe.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>

namespace hapticd::proto {

template <class T, std::size_t N>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert(N >= 2 && (N & (N - 1)) == 0, "capacity must be a power of two");

 public:
  /// Adds `v`; false (nothing added) when full. Producer thread.
  bool push(const T& v) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= N)
      return false;
    slots_[head & (N - 1)] = v;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  /// Takes the oldest value into `out`; false when empty. Consumer thread.
  bool pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire))
      return false;
    out = slots_[tail & (N - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  /// Values waiting (a snapshot). Any thread.
  std::size_t size() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_acquire));
  }
  static constexpr std::size_t capacity() { return N; }

 private:
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
  alignas(64) std::array<T, N> slots_{};
};

}  // namespace hapticd::proto
