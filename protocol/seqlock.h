#pragma once
/// \file
/// The seqlock, the project's one: one writer publishes a trivially copyable value, any number of
/// readers on other threads (or, in shared memory, other processes) take consistent snapshots,
/// and nobody waits for the writer (PipeWire's spa_io_position, the Linux kernel's seqcount). The
/// value lives in relaxed 64-bit atomic words between two loads of a sequence number, so a reader
/// never sees a torn value and the program has no data race (Boehm, "Can seqlocks get along with
/// programming language memory models?", MSPC 2012).
///
/// SeqlockBlock<T> is the storage and the protocol, a standard-layout block that may be placed in
/// a shared-memory segment (protocol/shm.h's state block is one); Seqlock<T> is the in-process
/// form (the daemon's servo state), written once at construction so that a read always succeeds.
///
/// Threads: one writer calls write() / writeRanges(); any thread calls the reads. The writer
/// never allocates, locks or blocks (servo-thread safe); a reader retries while a write is in
/// progress.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace hapticd::proto {

template <class T>
class SeqlockBlock {
  static_assert(std::is_trivially_copyable_v<T>, "a seqlock holds trivially copyable values");
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

 public:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

  /// A byte range of T (offset and length in bytes) for writeRanges().
  struct Range {
    std::size_t offset = 0;
    std::size_t bytes = 0;
  };

  /// Writer only (one thread). Publishes `value`. Never blocks.
  void write(const T& value) noexcept {
    std::uint64_t words[kWords] = {};
    std::memcpy(words, &value, sizeof(T));
    const std::uint64_t s = begin();
    for (std::size_t i = 0; i < kWords; ++i)
      words_[i].store(words[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Writer only: publishes only the words that cover `ranges` of `value` (each rounded out to
  /// whole 8-byte words); the other words keep what an earlier write left there. For a block
  /// with fixed-capacity lists of which a count says how much is used: a tick copies what it
  /// uses, not the whole capacity. Ranges must lie inside T. Never blocks.
  void writeRanges(const T& value, const Range* ranges, std::size_t count) noexcept {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    const std::uint64_t s = begin();
    for (std::size_t r = 0; r < count; ++r) {
      const std::size_t first = ranges[r].offset / 8;
      std::size_t end = (ranges[r].offset + ranges[r].bytes + 7) / 8;
      if (end > kWords)
        end = kWords;
      for (std::size_t i = first; i < end; ++i) {
        std::uint64_t w = 0;
        const std::size_t at = i * 8;
        std::memcpy(&w, bytes + at, at + 8 <= sizeof(T) ? 8 : sizeof(T) - at);
        words_[i].store(w, std::memory_order_relaxed);
      }
    }
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Any thread. Copies the newest value into `out`; false (out unchanged) when nothing was
  /// written yet or the writer kept the block busy for `max_tries` attempts. Never blocks.
  bool tryRead(T& out, int max_tries = 10000) const noexcept {
    std::uint64_t words[kWords];
    for (int t = 0; t < max_tries; ++t) {
      const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
      if (s1 == 0)
        return false;
      if (s1 & 1u)
        continue;
      for (std::size_t i = 0; i < kWords; ++i)
        words[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s1) {
        std::memcpy(&out, words, sizeof(T));
        return true;
      }
    }
    return false;
  }

  /// Writes so far (a snapshot). Any thread.
  std::uint64_t writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  // odd sequence: the writer is inside
  std::uint64_t begin() noexcept {
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    return s;
  }

  alignas(64) std::atomic<std::uint64_t> seq_{0};
  std::atomic<std::uint64_t> words_[kWords] = {};
};

/// The in-process seqlock: holds T{} from construction, so read() always has a value.
template <class T>
class Seqlock : public SeqlockBlock<T> {
 public:
  Seqlock() noexcept { this->write(T{}); }

  /// Any thread. A consistent copy of the last write; retries while a write is in progress.
  T read() const noexcept {
    T value;
    while (!this->tryRead(value)) {
    }
    return value;
  }
};

}  // namespace hapticd::proto
