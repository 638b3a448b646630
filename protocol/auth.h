#pragma once
/// \file
/// Datagram security: an optional pre-shared key with a per-datagram tag (libsodium crypto_auth,
/// HMAC-SHA512-256, 32 bytes, over header and payload, appended after the payload with
/// kFlagMac set), replay protection by a sliding window over sequence numbers, and a token-bucket
/// rate limit. Server and client threads; not for the servo thread.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "protocol/messages.h"

namespace hapticd::proto {

/// A pre-shared key (crypto_auth_KEYBYTES = 32 bytes).
using Key = std::array<std::uint8_t, 32>;

/// Parses 64 hex digits (surrounding whitespace allowed). On failure returns nullopt and says why.
std::optional<Key> parseKeyHex(std::string_view text, std::string* error);
/// The key as 64 lowercase hex digits.
std::string keyToHex(const Key& key);
/// A fresh random key (libsodium randombytes).
Key randomKey();
/// A random nonzero 64-bit value (session ids).
std::uint64_t randomU64();

/// Encodes `m` like encode() and, with a key, sets kFlagMac and appends the tag. Returns the
/// datagram size or 0 with *error set (see encode(); kBufferTooSmall also when the tag does not
/// fit). Any thread.
std::size_t encodeDatagram(Header h,
                           const Message& m,
                           const Key* key,
                           std::span<std::uint8_t> out,
                           Errc* error = nullptr);

/// Verifies the tag at the end of `datagram` (whose header says kFlagMac and whose length
/// decodeHeader() checked). Constant time. Any thread.
bool verifyTag(std::span<const std::uint8_t> datagram, const Key& key);

/// Replay protection for one sender: accepts each sequence number at most once, and refuses
/// numbers more than kWindow below the largest accepted (RFC 6479 style bitmap).
class ReplayWindow {
 public:
  static constexpr std::uint64_t kWindow = 1024;
  /// True when `seq` (≥ 1) is new and inside the window. Does not record it.
  bool check(std::uint64_t seq) const;
  /// Records `seq` (call after check() and after the tag verified).
  void accept(std::uint64_t seq);
  std::uint64_t top() const { return top_; }

 private:
  static constexpr std::size_t kWords = kWindow / 64;
  std::uint64_t top_ = 0;  // largest accepted
  std::array<std::uint64_t, kWords>
      bits_{};  // bit (s % kWindow) set: s accepted, s > top - kWindow
};

/// Rate limit of one peer. Defaults allow a 1 kHz pose stream plus a fast scene upload.
struct RateLimitConfig {
  double packets_per_s = 20000.0;  ///< sustained rate, datagrams/s (0: unlimited)
  double burst = 2000.0;           ///< bucket size, datagrams
};

/// A token bucket on the caller's monotonic clock (ns). Any single thread.
class TokenBucket {
 public:
  explicit TokenBucket(RateLimitConfig c = {}, std::uint64_t now_ns = 0)
      : config_(c), tokens_(c.burst), last_ns_(now_ns) {}
  /// Takes one token; false (and no token taken) when the bucket is empty.
  bool take(std::uint64_t now_ns);

 private:
  RateLimitConfig config_;
  double tokens_;
  std::uint64_t last_ns_;
};

}  // namespace hapticd::proto
