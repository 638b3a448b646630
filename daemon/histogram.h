#pragma once
/// \file
/// A fixed-bucket histogram of durations in nanoseconds: no allocation, written by one thread
/// (the servo thread) and read by any (relaxed atomic counters, so a reader sees each bucket
/// whole; a snapshot taken while ticks run may be a tick or two out of step between buckets).
///
/// Buckets: 1 µs wide from 0 to 200 µs, 10 µs wide from 200 µs to 2 ms, 100 µs wide from 2 ms to
/// 20 ms, then one overflow bucket. A percentile is reported as its bucket's upper edge.

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

namespace hapticd::daemon {

class DurationHistogram {
 public:
  static constexpr std::size_t kFine = 200;    // 1 µs buckets
  static constexpr std::size_t kMid = 180;     // 10 µs buckets, 200 µs .. 2 ms
  static constexpr std::size_t kCoarse = 180;  // 100 µs buckets, 2 ms .. 20 ms
  static constexpr std::size_t kBuckets = kFine + kMid + kCoarse + 1;

  /// Servo thread (the one writer). Negative durations count as 0.
  void add(std::int64_t ns) noexcept;

  /// Any thread.
  std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  /// Largest value added (ns), any thread.
  std::int64_t maxNs() const noexcept { return max_ns_.load(std::memory_order_relaxed); }
  /// Upper edge (ns) of the bucket holding quantile q in [0, 1]; 0 when empty. Any thread.
  std::int64_t quantileNs(double q) const noexcept;
  /// Zeroes every bucket. Only while the writer is not running.
  void reset() noexcept;

  /// Bucket of a duration, and the bucket's upper edge (ns).
  static std::size_t bucketOf(std::int64_t ns) noexcept;
  static std::int64_t upperEdgeNs(std::size_t bucket) noexcept;
  std::uint64_t bucketCount(std::size_t bucket) const noexcept {
    return buckets_[bucket].load(std::memory_order_relaxed);
  }

  /// "p50 3 µs, p99 12 µs, p99.9 40 µs, max 73 µs (n=1000)". Any thread, allocates.
  std::string summary() const;
  /// Non-empty buckets as "upper_edge_us count" lines. Any thread, allocates.
  std::string table() const;

 private:
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> max_ns_{0};
};

}  // namespace hapticd::daemon
