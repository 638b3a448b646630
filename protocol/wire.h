#pragma once
/// \file
/// The hapticd wire format: version, fixed header, byte-by-byte little-endian reader and writer,
/// and the reasons a datagram is refused. Shared by the daemon and every client (STYLE rule 9).
/// Layouts of every message are in protocol/README.md; keep the two in step.

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

namespace hapticd::proto {

// Protocol version. This comment is the protocol's changelog: add a line for every change.
//
//   1.0  2026-12-01  first version: hello/welcome, chunked scene upload (begin, chunk, ack,
//                    commit, status), scene update, pose command, subscribe, state, arm, disarm,
//                    heartbeat, error, ack, status request/reply, bye; HMAC-SHA512-256 tag.
//   1.1  2026-12-01  State appends 24 bytes after its lists: pairs_tested u32, pairs_skipped
//                    u32, max_penetration_m f64 (>= 0), tick_ns u32, reserved u32. A 1.0
//                    State decodes with these 0; a 1.0 reader ignores them. Subscribe flag
//                    bit 2 each_tick: only states of ticks not sent before (a 1.0 server
//                    ignores it). StatusReply appends, after its texts, the shm and
//                    scene-edit counters (6 u64), shm_flags u32, shm_name_length u16,
//                    reserved u16, shm_name.
//   1.2  2026-12-03  StatusReply appends, after shm_name, loading_length u16, reserved u16 and
//                    loading: what a scene build (SIGHUP reload, upload) is doing, "" when none
//                    runs (a 1.1 sender's reads as ""; a 1.1 reader ignores it).
//
// Rules for later versions. A minor version may only (a) append fields at the end of a
// message's payload (after its lists and strings) or (b) add message types; a receiver of an
// older minor decodes the prefix it knows and ignores the rest, and answers an unknown type with
// Error kUnknownType. Anything else (moved fields, changed units, new header fields) is a new
// major version, which a receiver refuses (Errc::kBadMajor).
inline constexpr std::uint8_t kVersionMajor = 1;
inline constexpr std::uint8_t kVersionMinor = 2;

/// "HPTC" in the first four bytes of every datagram (0x43545048 read little-endian).
inline constexpr std::uint32_t kMagic = 0x43545048u;
/// Bytes of the fixed header (see Header).
inline constexpr std::size_t kHeaderSize = 40;
/// Bytes of the MAC tag appended when Header::flags has kFlagMac (crypto_auth_BYTES).
inline constexpr std::size_t kMacSize = 32;
/// The largest UDP payload over IPv4; no configured max datagram may exceed it.
inline constexpr std::size_t kMaxDatagramLimit = 65507;

/// Header::flags bits.
inline constexpr std::uint16_t kFlagMac = 1u << 0;  ///< a kMacSize tag follows the payload
inline constexpr std::uint16_t kKnownFlags = kFlagMac;

/// The entry of `names` (listed in value order from 0) for the enum or integer value `v`,
/// `fallback` past its end: the protocol's names of its enum values come from such tables.
template <class E, std::size_t N>
constexpr const char* nameOf(E v, const char* const (&names)[N], const char* fallback = "unknown") {
  const auto i = static_cast<std::size_t>(v);
  return i < N ? names[i] : fallback;
}

/// Message types (Header::type). Values are part of the wire format: never reuse one.
enum class MsgType : std::uint16_t {
  kHello = 1,
  kWelcome = 2,
  kSceneBegin = 3,
  kSceneChunk = 4,
  kSceneChunkAck = 5,
  kSceneCommit = 6,
  kSceneStatus = 7,
  kSceneUpdate = 8,
  kPoseCommand = 9,
  kSubscribe = 10,
  kState = 11,
  kArm = 12,
  kDisarm = 13,
  kHeartbeat = 14,
  kError = 15,
  kStatusRequest = 16,
  kStatusReply = 17,
  kAck = 18,
  kBye = 19,
};
/// One past the largest MsgType value.
inline constexpr std::uint16_t kMsgTypeEnd = 20;
/// The name of a message type ("hello", ...), "unknown" for other values. Any thread.
const char* msgTypeName(std::uint16_t type);

/// Why a datagram was refused, or why a message could not be encoded. Every value is also a
/// counter in the server's status (RefusalCounters). Values are on the wire (StatusReply, Error):
/// append only.
enum class Errc : std::uint16_t {
  kOk = 0,
  kTooShort,          ///< shorter than the header, or than its declared payload
  kTooLong,           ///< larger than the configured max datagram, or bytes after payload+tag
  kBadMagic,          ///< first four bytes are not kMagic
  kBadMajor,          ///< a major version this build does not speak
  kBadFlags,          ///< a flag bit this version does not define
  kUnknownType,       ///< a message type this version does not define
  kBadPayloadLength,  ///< payload length wrong for the message type (exact or bounded)
  kNotFinite,         ///< a NaN or Inf in a float field
  kBadValue,          ///< a field out of its documented range (counts, rates, quaternion norm)
  kNoMac,             ///< a key is set and this message needs authentication it lacks
  kBadMac,            ///< the tag does not verify with the key
  kReplay,            ///< an authenticated sequence number seen before or too old for the window
  kRateLimited,       ///< the peer's token bucket is empty
  kUnknownSession,    ///< session id not known (send hello first) or expired
  kWrongPeer,         ///< session id known but from another address (no key set)
  kServerFull,        ///< no free session or upload slot
  kUploadError,       ///< a scene upload chunk or commit the reassembly refused
  kNotExpected,       ///< a message type a server does not accept (e.g. a State sent to it)
  kBufferTooSmall,    ///< encode: the output buffer cannot hold the message
  kCount
};
inline constexpr std::size_t kErrcCount = static_cast<std::size_t>(Errc::kCount);
/// A short stable name for an Errc ("too_short", ...), used in status output. Any thread.
const char* errcName(Errc e);

/// The fixed header at offset 0 of every datagram (40 bytes, little-endian):
///
/// | off | size | type | field | meaning |
/// |---|---|---|---|---|
/// | 0 | 4 | u32 | magic | kMagic |
/// | 4 | 1 | u8 | major | kVersionMajor of the sender |
/// | 5 | 1 | u8 | minor | kVersionMinor of the sender |
/// | 6 | 2 | u16 | type | MsgType |
/// | 8 | 2 | u16 | flags | kFlagMac |
/// | 10 | 2 | u16 | reserved | zero on send, ignored on receive |
/// | 12 | 4 | u32 | payload_length | bytes after the header, tag excluded |
/// | 16 | 8 | u64 | session_id | 0 in Hello; else the id Welcome gave |
/// | 24 | 8 | u64 | sequence | per sender and session, starts at 1, +1 per datagram |
/// | 32 | 8 | u64 | timestamp_ns | sender's CLOCK_MONOTONIC when sent, ns |
struct Header {
  std::uint8_t major = kVersionMajor;  ///< the sender's major version
  std::uint8_t minor = kVersionMinor;  ///< the sender's minor version
  std::uint16_t type = 0;              ///< MsgType
  std::uint16_t flags = 0;             ///< kFlag* bits
  std::uint32_t payload_length = 0;    ///< bytes after the header, tag excluded
  std::uint64_t session_id = 0;        ///< 0 in Hello; else the id Welcome gave
  std::uint64_t sequence = 0;          ///< per sender and session, from 1, +1 per datagram
  std::uint64_t timestamp_ns = 0;      ///< the sender's CLOCK_MONOTONIC when sent, ns
};

/// A refusal with the values that explain it. `describe()` turns it into a sentence.
struct DecodeError {
  Errc code = Errc::kOk;
  std::uint16_t type = 0;      ///< the message type, when known
  std::uint64_t got = 0;       ///< the offending value (a length, a version, a count)
  std::uint64_t expected = 0;  ///< what was expected (or the bound)
  const char* field = "";      ///< the field or part concerned (static string)
};
/// A sentence naming what is wrong and where, e.g. "state: payload length 12 bytes, expected at
/// least 296". Any thread; allocates.
std::string describe(const DecodeError& e);

/// Decodes and checks the header of `datagram`: magic, major version, known flags, and that the
/// datagram is exactly header + payload_length (+ kMacSize with kFlagMac). Does not check the
/// type or the payload. Any thread; no allocation.
DecodeError decodeHeader(std::span<const std::uint8_t> datagram, Header& out);
/// Writes `h` at out[0..kHeaderSize). `out` must hold kHeaderSize bytes. Any thread.
void encodeHeader(const Header& h, std::span<std::uint8_t> out);

/// Reads little-endian fields one byte at a time; a read past the end returns zero and marks
/// the reader failed, a non-finite f64 marks it non-finite. Any thread; no allocation.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : b_(bytes) {}

  std::uint8_t u8() { return le<std::uint8_t>(); }
  std::uint16_t u16() { return le<std::uint16_t>(); }
  std::uint32_t u32() { return le<std::uint32_t>(); }
  std::uint64_t u64() { return le<std::uint64_t>(); }
  /// An IEEE-754 binary64; NaN and Inf are read as 0 and mark the reader non-finite.
  double f64() {
    const std::size_t at = pos_;
    const double v = std::bit_cast<double>(u64());
    if (!std::isfinite(v)) {
      if (!nonfinite_)
        nonfinite_at_ = at;
      nonfinite_ = true;
      return 0.0;
    }
    return v;
  }
  /// The next n bytes as a view into the input (empty and failed when fewer remain).
  std::span<const std::uint8_t> bytes(std::size_t n) {
    if (!need(n))
      return {};
    auto s = b_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  std::size_t remaining() const { return b_.size() - pos_; }
  std::size_t position() const { return pos_; }
  bool failed() const { return failed_; }
  bool nonFinite() const { return nonfinite_; }
  /// Offset of the first non-finite f64 read.
  std::size_t nonFiniteAt() const { return nonfinite_at_; }

 private:
  // an unsigned integer of sizeof(T) bytes, least significant first
  template <class T>
  T le() {
    if (!need(sizeof(T)))
      return 0;
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(b_[pos_ + i]) << (8 * i);
    pos_ += sizeof(T);
    return static_cast<T>(v);
  }
  bool need(std::size_t n) {
    if (failed_ || b_.size() - pos_ < n) {
      failed_ = true;
      return false;
    }
    return true;
  }
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
  std::size_t nonfinite_at_ = 0;
  bool failed_ = false;
  bool nonfinite_ = false;
};

/// Writes little-endian fields one byte at a time into a fixed buffer; a write past the end or a
/// non-finite f64 marks the writer failed (the bytes are then meaningless). Any thread.
class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) : b_(out) {}

  void u8(std::uint8_t v) {
    if (need(1))
      b_[pos_++] = v;
  }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void f64(double v) {
    if (!std::isfinite(v)) {
      nonfinite_ = true;
      failed_ = true;
      return;
    }
    le(std::bit_cast<std::uint64_t>(v), 8);
  }
  void bytes(std::span<const std::uint8_t> s) {
    if (!need(s.size()))
      return;
    if (!s.empty())
      std::memcpy(b_.data() + pos_, s.data(), s.size());
    pos_ += s.size();
  }
  void zeros(std::size_t n) {
    if (!need(n))
      return;
    std::memset(b_.data() + pos_, 0, n);
    pos_ += n;
  }
  std::size_t position() const { return pos_; }
  bool failed() const { return failed_; }
  bool nonFinite() const { return nonfinite_; }

 private:
  void le(std::uint64_t v, std::size_t n) {
    if (!need(n))
      return;
    for (std::size_t i = 0; i < n; ++i)
      b_[pos_ + i] = static_cast<std::uint8_t>(v >> (8 * i));
    pos_ += n;
  }
  bool need(std::size_t n) {
    if (failed_ || b_.size() - pos_ < n) {
      failed_ = true;
      return false;
    }
    return true;
  }
  std::span<std::uint8_t> b_;
  std::size_t pos_ = 0;
  bool failed_ = false;
  bool nonfinite_ = false;
};

}  // namespace hapticd::proto
