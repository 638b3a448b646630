#include "protocol/wire.h"

#include <cstdarg>
#include <cstdio>
#include <iterator>

namespace hapticd::proto {
namespace {

// in value order; 0 is no type
constexpr const char* kMsgTypeNames[] = {
    "unknown",         "hello",          "welcome",      "scene_begin",  "scene_chunk",
    "scene_chunk_ack", "scene_commit",   "scene_status", "scene_update", "pose_command",
    "subscribe",       "state",          "arm",          "disarm",       "heartbeat",
    "error",           "status_request", "status_reply", "ack",          "bye"};
static_assert(std::size(kMsgTypeNames) == kMsgTypeEnd);

constexpr const char* kErrcNames[] = {
    "ok",          "too_short",    "too_long",        "bad_magic",
    "bad_major",   "bad_flags",    "unknown_type",    "bad_payload_length",
    "not_finite",  "bad_value",    "no_mac",          "bad_mac",
    "replay",      "rate_limited", "unknown_session", "wrong_peer",
    "server_full", "upload_error", "not_expected",    "buffer_too_small"};
static_assert(std::size(kErrcNames) == kErrcCount);

// printf into a string (the sentences of describe() are short)
[[gnu::format(printf, 1, 2)]] std::string format(const char* fmt, ...) {
  char buf[256];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

}  // namespace

const char* msgTypeName(std::uint16_t type) {
  return nameOf(type, kMsgTypeNames);
}

const char* errcName(Errc e) {
  return nameOf(e, kErrcNames);
}

std::string describe(const DecodeError& e) {
  const char* what = e.type != 0 ? msgTypeName(e.type) : "datagram";
  const auto got = static_cast<unsigned long long>(e.got);
  const auto exp = static_cast<unsigned long long>(e.expected);
  const char* at_least = std::string_view(e.field) == "payload (at least)" ? "at least " : "";
  switch (e.code) {
    case Errc::kOk:
      return "ok";
    case Errc::kTooShort:
      return format("%s: %llu bytes, too short for its %s (needs %llu)", what, got, e.field, exp);
    case Errc::kTooLong:
      return format("%s: %llu bytes, more than %s allows (%llu)", what, got, e.field, exp);
    case Errc::kBadMagic:
      return format("not a hapticd datagram (magic 0x%08llx, expected 0x%08llx)", got, exp);
    case Errc::kBadMajor:
      return format(
          "protocol major version %llu is not supported: this build speaks %u.%u (upgrade the "
          "older side)",
          got, kVersionMajor, kVersionMinor);
    case Errc::kBadFlags:
      return format("%s: unknown header flags 0x%04llx", what, got);
    case Errc::kUnknownType:
      return format("unknown message type %llu (this build knows 1..%llu)", got, exp);
    case Errc::kBadPayloadLength:
      return format("%s: payload length %llu bytes, expected %s%llu", what, got, at_least, exp);
    case Errc::kNotFinite:
      return format("%s: NaN or Inf in a float field at payload offset %llu", what, got);
    case Errc::kBadValue:
      return format("%s: field %s out of range (value %llu, bound %llu)", what, e.field, got, exp);
    default:
      return format("%s: refused (%s%s%s)", what, errcName(e.code), e.field[0] ? ": " : "",
                    e.field);
  }
}

DecodeError decodeHeader(std::span<const std::uint8_t> d, Header& h) {
  if (d.size() < kHeaderSize)
    return {Errc::kTooShort, 0, d.size(), kHeaderSize, "header"};
  Reader r(d.first(kHeaderSize));
  const std::uint32_t magic = r.u32();
  if (magic != kMagic)
    return {Errc::kBadMagic, 0, magic, kMagic, "magic"};
  h.major = r.u8();
  h.minor = r.u8();
  if (h.major != kVersionMajor)
    return {Errc::kBadMajor, 0, h.major, kVersionMajor, "major"};
  h.type = r.u16();
  h.flags = r.u16();
  r.u16();  // reserved
  h.payload_length = r.u32();
  h.session_id = r.u64();
  h.sequence = r.u64();
  h.timestamp_ns = r.u64();
  if (h.flags & ~kKnownFlags)
    return {Errc::kBadFlags, h.type, h.flags, kKnownFlags, "flags"};
  const std::size_t expected =
      kHeaderSize + std::size_t{h.payload_length} + ((h.flags & kFlagMac) ? kMacSize : 0);
  if (d.size() < expected)
    return {Errc::kTooShort, h.type, d.size(), expected, "payload_length (+ tag)"};
  if (d.size() > expected)
    return {Errc::kTooLong, h.type, d.size(), expected, "payload_length (+ tag)"};
  return {};
}

void encodeHeader(const Header& h, std::span<std::uint8_t> out) {
  Writer w(out.first(kHeaderSize));
  w.u32(kMagic);
  w.u8(h.major);
  w.u8(h.minor);
  w.u16(h.type);
  w.u16(h.flags);
  w.u16(0);
  w.u32(h.payload_length);
  w.u64(h.session_id);
  w.u64(h.sequence);
  w.u64(h.timestamp_ns);
}

}  // namespace hapticd::proto
