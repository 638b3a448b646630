#include "protocol/upload.h"

#include <sodium.h>

#include <algorithm>
#include <cstring>
#include <iterator>

namespace hapticd::proto {

std::array<std::uint8_t, 32> sha256(std::span<const std::uint8_t> bytes) {
  static const int init = sodium_init();  // idempotent and thread-safe; < 0 only without entropy
  (void)init;
  std::array<std::uint8_t, 32> h{};
  crypto_hash_sha256(h.data(), bytes.data(), bytes.size());
  return h;
}

namespace {
// in ChunkOutcome order
constexpr const char* kChunkOutcomeTexts[] = {
    "stored",
    "duplicate (already held)",
    "chunk reaches past the announced total size",
    "chunk larger than the server's max chunk size",
    "too many disjoint chunks held: send in order",
    "no upload in progress with this id: send scene_begin"};
static_assert(std::size(kChunkOutcomeTexts) ==
              static_cast<std::size_t>(ChunkOutcome::kNotBegun) + 1);
}  // namespace

const char* chunkOutcomeText(ChunkOutcome o) {
  return nameOf(o, kChunkOutcomeTexts);
}

bool Reassembly::begin(const SceneBegin& b, std::uint64_t now_ns, std::string* error) {
  if (active_ && b.upload_id == begin_.upload_id && b.total_bytes == begin_.total_bytes &&
      b.sha256 == begin_.sha256) {
    last_activity_ns_ = now_ns;  // a resent begin: keep what is held
    return true;
  }
  reset();
  if (b.total_bytes == 0 || b.total_bytes > limits_.max_scene_bytes) {
    if (error)
      *error = "scene of " + std::to_string(b.total_bytes) + " bytes refused: the limit is " +
               std::to_string(limits_.max_scene_bytes) + " bytes (upload.max_scene_bytes)";
    return false;
  }
  begin_ = b;
  bytes_.assign(static_cast<std::size_t>(b.total_bytes), 0);
  active_ = true;
  last_activity_ns_ = now_ns;
  return true;
}

void Reassembly::reset() {
  active_ = false;
  verified_ = false;
  begin_ = {};
  std::vector<std::uint8_t>().swap(bytes_);
  ranges_.clear();
  received_ = 0;
}

ChunkOutcome Reassembly::add(std::uint64_t offset,
                             std::span<const std::uint8_t> data,
                             std::uint64_t now_ns) {
  if (!active_)
    return ChunkOutcome::kNotBegun;
  if (data.size() > limits_.max_chunk_bytes)
    return ChunkOutcome::kTooLarge;
  const std::uint64_t total = begin_.total_bytes;
  if (data.empty() || offset > total || data.size() > total - offset)
    return ChunkOutcome::kOutOfRange;
  last_activity_ns_ = now_ns;
  const std::uint64_t a = offset, b = offset + data.size();

  // the first range that could touch [a, b]: the one before a if it reaches a, else the next
  auto it = ranges_.upper_bound(a);
  if (it != ranges_.begin() && std::prev(it)->second >= a)
    --it;
  const bool touches = it != ranges_.end() && it->first <= b;
  if (!touches && ranges_.size() >= limits_.max_ranges)
    return ChunkOutcome::kTooFragmented;

  // copy the gaps between held ranges inside [a, b), merging the ranges met
  std::uint64_t cur = a, lo = a, hi = b, stored = 0;
  auto copy = [&](std::uint64_t from, std::uint64_t to) {
    if (to <= from)
      return;
    std::memcpy(bytes_.data() + from, data.data() + (from - a),
                static_cast<std::size_t>(to - from));
    stored += to - from;
  };
  while (it != ranges_.end() && it->first <= b) {
    copy(cur, std::min(it->first, b));
    cur = std::max(cur, it->second);
    lo = std::min(lo, it->first);
    hi = std::max(hi, it->second);
    it = ranges_.erase(it);
  }
  copy(cur, b);
  ranges_.emplace(lo, hi);
  received_ += stored;
  if (stored == 0)
    return ChunkOutcome::kDuplicate;
  verified_ = false;
  return ChunkOutcome::kStored;
}

CommitOutcome Reassembly::commit(std::uint64_t now_ns) {
  if (!active_)
    return CommitOutcome::kNotBegun;
  last_activity_ns_ = now_ns;
  if (received_ != begin_.total_bytes)
    return CommitOutcome::kIncomplete;
  if (!verified_) {
    if (sha256(bytes_) != begin_.sha256) {
      reset();
      return CommitOutcome::kHashMismatch;
    }
    verified_ = true;
  }
  return CommitOutcome::kComplete;
}

std::vector<std::uint8_t> Reassembly::take() {
  if (!active_ || !verified_)
    return {};
  std::vector<std::uint8_t> out = std::move(bytes_);
  reset();
  return out;
}

std::vector<SceneStatus::Range> Reassembly::missing(std::size_t max) const {
  std::vector<SceneStatus::Range> out;
  if (!active_)
    return out;
  std::uint64_t cur = 0;
  for (const auto& [s, e] : ranges_) {
    if (out.size() >= max)
      return out;
    if (s > cur)
      out.push_back({cur, s - cur});
    cur = e;
  }
  if (out.size() < max && cur < begin_.total_bytes)
    out.push_back({cur, begin_.total_bytes - cur});
  return out;
}

}  // namespace hapticd::proto
