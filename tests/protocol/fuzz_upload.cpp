// libFuzzer target: chunk reassembly driven by a byte program (begin, add, commit, missing,
// stale). Invariants: received bytes never exceed the total; the bytes handed over are exactly
// the reference data; a corrupt chunk never leads to a hand-over of wrong bytes.
#include <cstdint>
#include <span>
#include <vector>

#include "protocol/upload.h"

namespace {
const std::vector<std::uint8_t>& reference() {
  static const std::vector<std::uint8_t> r = [] {
    std::vector<std::uint8_t> v(70000);
    std::uint32_t x = 12345;
    for (auto& b : v) {
      x = x * 1664525u + 1013904223u;
      b = static_cast<std::uint8_t>(x >> 24);
    }
    return v;
  }();
  return r;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hapticd::proto;
  UploadLimits lim;
  lim.max_scene_bytes = 65536;
  lim.max_chunk_bytes = 4096;
  lim.max_ranges = 64;
  lim.stale_timeout_ns = 1000;
  Reassembly r(lim);
  const auto& ref = reference();
  std::vector<std::uint8_t> corrupt;
  std::uint64_t now = 0;
  std::size_t i = 0;
  auto next = [&]() -> std::uint32_t { return i < size ? data[i++] : 0; };
  auto next16 = [&]() { return next() | (next() << 8); };
  while (i < size) {
    now += next();
    switch (next() % 5) {
      case 0: {
        const std::uint64_t total = next16() + 1u;  // 1..65536 (+ beyond when > limit)
        SceneBegin b;
        b.upload_id = next() % 3 + 1;
        b.total_bytes = total + (next() == 255 ? 100000 : 0);
        b.sha256 = sha256(std::span(ref).first(
            static_cast<std::size_t>(std::min<std::uint64_t>(total, ref.size()))));
        (void)r.begin(b, now, nullptr);
        break;
      }
      case 1: {
        const std::uint64_t off = next16();
        const std::size_t len = next16() % 5000;
        const bool bad = next() == 0x5a;
        if (off >= ref.size() || len == 0) {
          (void)r.add(off, std::span(ref).first(std::min<std::size_t>(len, ref.size())), now);
          break;
        }
        const std::size_t n = std::min<std::size_t>(len, ref.size() - off);
        std::span<const std::uint8_t> chunk = std::span(ref).subspan(off, n);
        if (bad) {
          corrupt.assign(chunk.begin(), chunk.end());
          corrupt[0] ^= 1;
          chunk = corrupt;
        }
        (void)r.add(off, chunk, now);
        break;
      }
      case 2: {
        if (r.commit(now) == CommitOutcome::kComplete) {
          const std::uint64_t total = r.totalBytes();
          const auto out = r.take();
          if (out.size() != total)
            __builtin_trap();
          if (!std::equal(out.begin(), out.end(), ref.begin()))
            __builtin_trap();
        }
        break;
      }
      case 3: {
        std::uint64_t gaps = 0;
        for (const auto& g : r.missing(next() % 70))
          gaps += g.length;
        if (r.active() && r.missing(1u << 20).size() <= 64 && gaps > r.totalBytes())
          __builtin_trap();
        break;
      }
      case 4:
        if (r.stale(now))
          r.reset();
        break;
    }
    if (r.receivedBytes() > r.totalBytes())
      __builtin_trap();
    if (r.rangeCount() > lim.max_ranges)
      __builtin_trap();
  }
  return 0;
}
