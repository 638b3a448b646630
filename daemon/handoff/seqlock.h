#pragma once
/// \file
/// A seqlock block: one writer publishes a trivially copyable value, any number of readers on
/// other threads take consistent snapshots, and nobody waits for the writer (PipeWire's
/// spa_io_position, the Linux kernel's seqcount). The payload lives in relaxed atomic words so
/// that a reader racing a write is well defined; the sequence number tells it to retry.
///
/// Threads: one writer (the servo thread) calls write(); any thread calls read(). write()
/// never allocates, locks or blocks; read() retries while a write is in progress.

#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace hapticd::daemon {

template <class T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "Seqlock holds trivially copyable values");
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

 public:
  Seqlock() { write(T{}); }

  /// Writer only (one thread). Never blocks.
  void write(const T& value) noexcept {
    std::uint64_t words[kWords] = {};
    std::memcpy(words, &value, sizeof(T));
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i)
      data_[i].store(words[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// A byte range of T (offset and length in bytes) for writeRanges().
  struct Range {
    std::size_t offset = 0;
    std::size_t bytes = 0;
  };

  /// Writer only: publishes only the words that cover `ranges` of `value` (each rounded out to
  /// whole 8-byte words); the other words keep what an earlier write left there. For a block
  /// with fixed-capacity lists of which a count says how much is used: a tick copies what it
  /// uses, not the whole capacity. Ranges must lie inside T. Never blocks.
  void writeRanges(const T& value, const Range* ranges, std::size_t count) noexcept {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t r = 0; r < count; ++r) {
      const std::size_t first = ranges[r].offset / 8;
      std::size_t end = (ranges[r].offset + ranges[r].bytes + 7) / 8;
      if (end > kWords)
        end = kWords;
      for (std::size_t i = first; i < end; ++i) {
        std::uint64_t w = 0;
        const std::size_t at = i * 8;
        std::memcpy(&w, bytes + at, at + 8 <= sizeof(T) ? 8 : sizeof(T) - at);
        data_[i].store(w, std::memory_order_relaxed);
      }
    }
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Any thread. A consistent copy of the last write.
  T read() const noexcept {
    std::uint64_t words[kWords];
    for (;;) {
      const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
      if (s1 & 1u)
        continue;
      for (std::size_t i = 0; i < kWords; ++i)
        words[i] = data_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s1)
        break;
    }
    T value;
    std::memcpy(&value, words, sizeof(T));
    return value;
  }

  /// Writes so far (any thread).
  std::uint64_t writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::atomic<std::uint64_t> data_[kWords];
};

}  // namespace hapticd::daemon
