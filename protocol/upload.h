#pragma once
/// \file
/// Reassembly of a chunked scene upload: chunks arrive out of order, duplicated, overlapping or
/// not at all; the whole is handed over only when every byte is present and its SHA-256
/// (libsodium crypto_hash_sha256) equals the one announced in SceneBegin. Where chunks overlap the
/// first bytes received win (later copies of a byte are ignored), so a lying overlap shows up as a
/// hash mismatch. Server thread only (allocates; not for the servo thread).

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "protocol/messages.h"

namespace hapticd::proto {

/// Limits of one upload. Every field has its default here; the daemon's config may override.
struct UploadLimits {
  std::uint64_t max_scene_bytes = 64ull << 20;  ///< largest total_bytes, bytes (64 MiB)
  std::uint32_t max_chunk_bytes = 8192;         ///< largest chunk data, bytes (≤ kMaxChunkBytes)
  std::uint64_t stale_timeout_ns = 10'000'000'000;  ///< no chunk for this long: dropped (10 s)
  std::size_t max_ranges = 65536;  ///< most disjoint received ranges (fragmentation)
};

/// What a chunk did.
enum class ChunkOutcome {
  kStored,         ///< at least one new byte stored
  kDuplicate,      ///< every byte was already held (nothing changed; ack it again)
  kOutOfRange,     ///< offset + length beyond total_bytes
  kTooLarge,       ///< data longer than max_chunk_bytes
  kTooFragmented,  ///< would exceed max_ranges disjoint pieces
  kNotBegun,       ///< no upload in progress
};
/// A sentence for an outcome. Any thread.
const char* chunkOutcomeText(ChunkOutcome o);

/// What commit found.
enum class CommitOutcome {
  kComplete,      ///< every byte held and the hash matches: take() the bytes
  kIncomplete,    ///< bytes missing: missing() lists them
  kHashMismatch,  ///< complete but SHA-256 differs (the upload is reset: begin again)
  kNotBegun,
};

/// One upload in progress. Not thread-safe; owned by the server thread.
class Reassembly {
 public:
  explicit Reassembly(UploadLimits limits = {}) : limits_(limits) {}

  /// Starts upload `b` at time now_ns (any monotonic clock, ns). A SceneBegin equal to the
  /// current one (same id, size and hash) keeps the bytes received so far, so a resent begin
  /// costs nothing. Fails with a sentence (the upload is then not begun) when total_bytes is 0
  /// or over max_scene_bytes.
  [[nodiscard]] bool begin(const SceneBegin& b, std::uint64_t now_ns, std::string* error);

  /// Stores bytes [offset, offset + data.size()) that are not yet held.
  ChunkOutcome add(std::uint64_t offset, std::span<const std::uint8_t> data, std::uint64_t now_ns);

  /// Checks completeness, then the hash (once; a complete upload is hashed only at commit).
  CommitOutcome commit(std::uint64_t now_ns);

  /// The bytes, moved out, after commit() said kComplete; the upload then ends. Else empty.
  std::vector<std::uint8_t> take();

  /// The first `max` missing ranges in offset order.
  std::vector<SceneStatus::Range> missing(std::size_t max) const;

  /// True when begun and nothing arrived for stale_timeout_ns.
  bool stale(std::uint64_t now_ns) const {
    return active_ && now_ns - last_activity_ns_ > limits_.stale_timeout_ns;
  }
  /// Drops the upload and frees its bytes.
  void reset();

  bool active() const { return active_; }
  std::uint32_t uploadId() const { return begin_.upload_id; }
  const SceneBegin& announced() const { return begin_; }
  std::uint64_t receivedBytes() const { return received_; }
  std::uint64_t totalBytes() const { return begin_.total_bytes; }
  std::size_t rangeCount() const { return ranges_.size(); }
  const UploadLimits& limits() const { return limits_; }

 private:
  UploadLimits limits_;
  SceneBegin begin_;
  bool active_ = false;
  bool verified_ = false;
  std::vector<std::uint8_t> bytes_;
  std::map<std::uint64_t, std::uint64_t> ranges_;  // start -> end, disjoint, not adjacent
  std::uint64_t received_ = 0;
  std::uint64_t last_activity_ns_ = 0;
};

/// SHA-256 of `bytes` (libsodium crypto_hash_sha256). Any thread.
std::array<std::uint8_t, 32> sha256(std::span<const std::uint8_t> bytes);

}  // namespace hapticd::proto
