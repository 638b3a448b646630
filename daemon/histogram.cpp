#include "daemon/histogram.h"

#include <cinttypes>
#include <cstdio>

namespace hapticd::daemon {

std::size_t DurationHistogram::bucketOf(std::int64_t ns) noexcept {
  if (ns < 0)
    ns = 0;
  const std::int64_t us = ns / 1000;
  if (us < 200)
    return static_cast<std::size_t>(us);
  if (us < 2000)
    return kFine + static_cast<std::size_t>((us - 200) / 10);
  if (us < 20000)
    return kFine + kMid + static_cast<std::size_t>((us - 2000) / 100);
  return kBuckets - 1;
}

std::int64_t DurationHistogram::upperEdgeNs(std::size_t b) noexcept {
  const auto i = static_cast<std::int64_t>(b);
  if (b < kFine)
    return (i + 1) * 1000;
  if (b < kFine + kMid)
    return (200 + (i - static_cast<std::int64_t>(kFine) + 1) * 10) * 1000;
  if (b < kBuckets - 1)
    return (2000 + (i - static_cast<std::int64_t>(kFine + kMid) + 1) * 100) * 1000;
  return INT64_MAX;
}

void DurationHistogram::add(std::int64_t ns) noexcept {
  if (ns < 0)
    ns = 0;
  auto& b = buckets_[bucketOf(ns)];
  b.store(b.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (ns > max_ns_.load(std::memory_order_relaxed))
    max_ns_.store(ns, std::memory_order_relaxed);
}

std::int64_t DurationHistogram::quantileNs(double q) const noexcept {
  std::uint64_t total = 0;
  for (const auto& b : buckets_)
    total += b.load(std::memory_order_relaxed);
  if (total == 0)
    return 0;
  if (q < 0.0)
    q = 0.0;
  if (q > 1.0)
    q = 1.0;
  // the smallest bucket whose cumulative count reaches ceil(q * total) (at least 1)
  auto rank = static_cast<std::uint64_t>(q * static_cast<double>(total));
  if (static_cast<double>(rank) < q * static_cast<double>(total))
    ++rank;
  if (rank == 0)
    rank = 1;
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i].load(std::memory_order_relaxed);
    if (seen >= rank)
      return i == kBuckets - 1 ? maxNs() : upperEdgeNs(i);
  }
  return maxNs();
}

void DurationHistogram::reset() noexcept {
  for (auto& b : buckets_)
    b.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  max_ns_.store(0, std::memory_order_relaxed);
}

std::string DurationHistogram::summary() const {
  char buf[160];
  std::snprintf(
      buf, sizeof buf, "p50 %.0f us, p99 %.0f us, p99.9 %.0f us, max %.1f us (n=%" PRIu64 ")",
      static_cast<double>(quantileNs(0.5)) / 1e3, static_cast<double>(quantileNs(0.99)) / 1e3,
      static_cast<double>(quantileNs(0.999)) / 1e3, static_cast<double>(maxNs()) / 1e3, count());
  return buf;
}

std::string DurationHistogram::table() const {
  std::string out;
  char buf[64];
  for (std::size_t i = 0; i < kBuckets; ++i) {
    const std::uint64_t n = buckets_[i].load(std::memory_order_relaxed);
    if (n == 0)
      continue;
    if (i == kBuckets - 1)
      std::snprintf(buf, sizeof buf, ">20000 %" PRIu64 "\n", n);
    else
      std::snprintf(buf, sizeof buf, "%" PRId64 " %" PRIu64 "\n", upperEdgeNs(i) / 1000, n);
    out += buf;
  }
  return out;
}

}  // namespace hapticd::daemon
