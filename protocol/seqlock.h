#pragma once
/// \file
/// An in-process seqlock for one writer and any number of readers of a trivially copyable
/// value whose size is a multiple of 8 bytes (STYLE rule 6). The value is stored as relaxed
/// 64-bit atomics between two sequence loads, so a reader never sees a torn value and the
/// program has no data race (Boehm, "Can seqlocks get along with programming language memory
/// models?", MSPC 2012). The daemon's servo thread writes each tick's ShmState here; the server
/// thread reads it in ServerHandlers::fill_state (toState() in shm.h converts it).

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace hapticd::proto {

template <class T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert(sizeof(T) % 8 == 0, "pad T to a multiple of 8 bytes");
  static constexpr std::size_t kWords = sizeof(T) / 8;

 public:
  /// Publishes `v`. One writer thread only; wait-free, no allocation: servo-thread safe.
  void write(const T& v) noexcept {
    std::uint64_t w[kWords];
    std::memcpy(w, &v, sizeof v);
    const std::uint64_t q = seq_.load(std::memory_order_relaxed);
    seq_.store(q + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i)
      words_[i].store(w[i], std::memory_order_relaxed);
    seq_.store(q + 2, std::memory_order_release);
  }
  /// Copies the newest value into `out`; false when nothing was written yet or the writer kept
  /// it busy for max_tries attempts. Any thread; never blocks.
  bool read(T& out, int max_tries = 10000) const noexcept {
    std::uint64_t w[kWords];
    for (int t = 0; t < max_tries; ++t) {
      const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
      if (s1 == 0)
        return false;
      if (s1 & 1)
        continue;
      for (std::size_t i = 0; i < kWords; ++i)
        w[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s1) {
        std::memcpy(&out, w, sizeof out);
        return true;
      }
    }
    return false;
  }
  /// Values written so far (a snapshot). Any thread.
  std::uint64_t writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  alignas(64) std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace hapticd::proto
