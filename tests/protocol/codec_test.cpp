// The wire codec: every message round-trips; the header and every payload refuse what they
// must (short, wrong magic, other major, lying lengths, NaN/Inf, out-of-range counts) with the
// specific error; a newer minor's extra trailing bytes are ignored.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include "protocol/messages.h"
#include "tests/protocol/samples.h"

namespace hapticd::proto {
namespace {

using testing::sameMessage;
using testing::sampleMessages;
using testing::sampleState;
using testing::sampleStatus;

std::vector<std::uint8_t> encodeOrDie(const Message& m, Header h = {}) {
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  Errc e = Errc::kOk;
  const std::size_t n = encode(h, m, buf, &e);
  EXPECT_NE(n, 0u) << msgTypeName(static_cast<std::uint16_t>(typeOf(m))) << ": " << errcName(e);
  buf.resize(n);
  return buf;
}

void putU32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void putU16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
void putF64(std::vector<std::uint8_t>& b, std::size_t at, double v) {
  const auto u = std::bit_cast<std::uint64_t>(v);
  for (std::size_t i = 0; i < 8; ++i)
    b[at + i] = static_cast<std::uint8_t>(u >> (8 * i));
}

// Sets the header's payload_length to the bytes that follow it, then decodes.
DecodeError redecode(std::vector<std::uint8_t>& b) {
  putU32(b, 12, static_cast<std::uint32_t>(b.size() - kHeaderSize));
  Header got;
  Message back;
  return decode(b, got, back);
}

// The message `b` decodes to, when it is an M.
template <class M>
std::optional<M> decoded(const std::vector<std::uint8_t>& b) {
  Header h;
  Message m;
  if (decode(b, h, m).code != Errc::kOk || !std::holds_alternative<M>(m))
    return std::nullopt;
  return std::get<M>(m);
}

TEST(Codec, EveryMessageRoundTrips) {
  const auto samples = sampleMessages();
  ASSERT_EQ(samples.size(), std::variant_size_v<Message>);
  for (const auto& m : samples) {
    Header h;
    h.session_id = 0xfeedface12345678ull;
    h.sequence = 1234567890123ull;
    h.timestamp_ns = 42'000'000'001ull;
    const auto bytes = encodeOrDie(m, h);
    ASSERT_EQ(bytes.size(), kHeaderSize + payloadSize(m));
    Header got;
    Message back;
    const DecodeError e = decode(bytes, got, back);
    ASSERT_EQ(e.code, Errc::kOk) << describe(e);
    EXPECT_TRUE(sameMessage(m, back)) << msgTypeName(got.type);
    EXPECT_EQ(got.type, static_cast<std::uint16_t>(typeOf(m)));
    EXPECT_EQ(got.session_id, h.session_id);
    EXPECT_EQ(got.sequence, h.sequence);
    EXPECT_EQ(got.timestamp_ns, h.timestamp_ns);
    EXPECT_EQ(got.major, kVersionMajor);
    EXPECT_EQ(got.minor, kVersionMinor);
  }
}

TEST(Codec, HeaderBytesAreLittleEndianAtDocumentedOffsets) {
  Header h;
  h.session_id = 0x0102030405060708ull;
  h.sequence = 0x1112131415161718ull;
  h.timestamp_ns = 0x2122232425262728ull;
  const auto b = encodeOrDie(Heartbeat{5}, h);
  EXPECT_EQ(b[0], 'H');
  EXPECT_EQ(b[1], 'P');
  EXPECT_EQ(b[2], 'T');
  EXPECT_EQ(b[3], 'C');
  EXPECT_EQ(b[4], kVersionMajor);
  EXPECT_EQ(b[5], kVersionMinor);
  EXPECT_EQ(b[6], static_cast<std::uint8_t>(MsgType::kHeartbeat));
  EXPECT_EQ(b[7], 0);
  EXPECT_EQ(b[12], 8);  // payload_length
  EXPECT_EQ(b[16], 0x08);
  EXPECT_EQ(b[23], 0x01);
  EXPECT_EQ(b[24], 0x18);
  EXPECT_EQ(b[32], 0x28);
  EXPECT_EQ(b[39], 0x21);
  EXPECT_EQ(b[40], 5);
}

TEST(Codec, ShortDatagramRefused) {
  auto b = encodeOrDie(Arm{});
  for (std::size_t n = 0; n < kHeaderSize; ++n) {
    Header h;
    Message m;
    const auto e = decode(std::span(b.data(), n), h, m);
    EXPECT_EQ(e.code, Errc::kTooShort) << n;
  }
}

TEST(Codec, WrongMagicRefused) {
  auto b = encodeOrDie(Arm{});
  b[0] = 'X';
  Header h;
  Message m;
  const auto e = decode(b, h, m);
  EXPECT_EQ(e.code, Errc::kBadMagic);
  EXPECT_NE(describe(e).find("not a hapticd datagram"), std::string::npos);
}

TEST(Codec, OtherMajorRefusedWithClearError) {
  for (std::uint8_t major : {std::uint8_t{0}, std::uint8_t{2}, std::uint8_t{255}}) {
    Header h;
    h.major = major;
    auto b = encodeOrDie(Heartbeat{1}, h);
    Header got;
    Message m;
    const auto e = decode(b, got, m);
    EXPECT_EQ(e.code, Errc::kBadMajor);
    EXPECT_EQ(e.got, major);
    EXPECT_NE(describe(e).find("major version " + std::to_string(major) + " is not supported"),
              std::string::npos)
        << describe(e);
  }
}

TEST(Codec, NewerMinorExtraTrailingFieldsIgnored) {
  for (const auto& m : sampleMessages()) {
    Header h;
    h.minor = kVersionMinor + 1;
    auto b = encodeOrDie(m, h);
    // a newer minor appends 24 bytes of fields we do not know
    for (int i = 0; i < 24; ++i)
      b.push_back(static_cast<std::uint8_t>(0xA0 + i));
    putU32(b, 12, static_cast<std::uint32_t>(b.size() - kHeaderSize));
    Header got;
    Message back;
    const auto e = decode(b, got, back);
    ASSERT_EQ(e.code, Errc::kOk) << msgTypeName(got.type) << ": " << describe(e);
    EXPECT_TRUE(sameMessage(m, back)) << msgTypeName(got.type);
    EXPECT_EQ(got.minor, kVersionMinor + 1);
  }
}

TEST(Codec, SameMinorExtraBytesRefused) {
  for (const auto& m : sampleMessages()) {
    auto b = encodeOrDie(m);
    b.push_back(0);
    const auto e = redecode(b);
    EXPECT_EQ(e.code, Errc::kBadPayloadLength) << describe(e);
  }
}

TEST(Codec, LyingPayloadLengthRefused) {
  for (const auto& m : sampleMessages()) {
    auto b = encodeOrDie(m);
    const auto n = static_cast<std::uint32_t>(b.size() - kHeaderSize);
    Header got;
    Message back;
    putU32(b, 12, n + 1);  // claims more than is there
    EXPECT_EQ(decode(b, got, back).code, Errc::kTooShort);
    putU32(b, 12, 0xffffffffu);
    EXPECT_EQ(decode(b, got, back).code, Errc::kTooShort);
    if (n > 0) {
      putU32(b, 12, n - 1);  // claims less: a byte left over
      EXPECT_EQ(decode(b, got, back).code, Errc::kTooLong);
    }
  }
}

TEST(Codec, TruncatedPayloadRefusedPerType) {
  // a payload one byte short of what its type (and counts) require, with an honest header
  for (const auto& m : sampleMessages()) {
    auto b = encodeOrDie(m);
    if (b.size() == kHeaderSize)
      continue;
    b.pop_back();
    const auto e = redecode(b);
    EXPECT_EQ(e.code, Errc::kBadPayloadLength) << describe(e);
  }
}

TEST(Codec, EmptyMessagesRefuseAnyPayload) {
  for (const Message& m :
       {Message{Arm{}}, Message{Disarm{}}, Message{StatusRequest{}}, Message{Bye{}}}) {
    auto b = encodeOrDie(m);
    b.push_back(1);
    putU32(b, 12, 1);
    Header got;
    Message back;
    EXPECT_EQ(decode(b, got, back).code, Errc::kBadPayloadLength);
  }
}

TEST(Codec, UnknownTypeAndFlagsRefused) {
  auto b = encodeOrDie(Arm{});
  putU16(b, 6, 999);
  Header got;
  Message back;
  EXPECT_EQ(decode(b, got, back).code, Errc::kUnknownType);
  putU16(b, 6, 0);
  EXPECT_EQ(decode(b, got, back).code, Errc::kUnknownType);
  b = encodeOrDie(Arm{});
  putU16(b, 8, 0x8000);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadFlags);
}

// NaN and Inf in each float field of the messages that carry floats.
TEST(Codec, NanAndInfRefusedInEveryFloatField) {
  const auto samples = sampleMessages();
  auto find = [&](MsgType t) {
    for (const auto& m : samples)
      if (typeOf(m) == t)
        return m;
    return Message{};
  };
  const Message state_msg = find(MsgType::kState);
  const State& st = std::get<State>(state_msg);
  std::vector<std::pair<Message, std::vector<std::size_t>>> cases;
  {
    std::vector<std::size_t> offs;
    for (std::size_t i = 0; i < 13; ++i)
      offs.push_back(8 * i);  // pose, v, w
    cases.push_back({find(MsgType::kPoseCommand), offs});
  }
  {
    std::vector<std::size_t> offs;
    for (std::size_t i = 0; i < 21; ++i)
      offs.push_back(16 + 8 * i);  // poses, force, torque, scale
    std::size_t at = State::kFixedSize;
    for (std::size_t c = 0; c < st.contacts.size(); ++c, at += 56)
      for (std::size_t i = 0; i < 7; ++i)
        offs.push_back(at + 8 * i);
    for (std::size_t k = 0; k < st.bodies.size(); ++k, at += 64)
      for (std::size_t i = 0; i < 7; ++i)
        offs.push_back(at + 8 + 8 * i);
    offs.push_back(at + 8);  // minor 1: max_penetration_m
    cases.push_back({find(MsgType::kState), offs});
  }
  {
    std::vector<std::size_t> offs;
    std::size_t at = SceneUpdate::kFixedSize;
    for (std::size_t k = 0; k < 3; ++k, at += 64)  // 2 poses + 1 added
      for (std::size_t i = 0; i < 7; ++i)
        offs.push_back(at + 8 + 8 * i);
    cases.push_back({find(MsgType::kSceneUpdate), offs});
  }
  const std::vector<std::size_t> status_offs{24, 32};  // tick_rate_hz, measured_tick_hz
  cases.emplace_back(find(MsgType::kStatusReply), status_offs);

  const double bad[] = {
      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::signaling_NaN(),
      std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  std::size_t checked = 0;
  for (const auto& [m, offs] : cases) {
    const auto good = encodeOrDie(m);
    for (std::size_t off : offs) {
      for (double v : bad) {
        auto b = good;
        putF64(b, kHeaderSize + off, v);
        Header got;
        Message back;
        const auto e = decode(b, got, back);
        EXPECT_EQ(e.code, Errc::kNotFinite) << msgTypeName(got.type) << " offset " << off;
        EXPECT_EQ(e.got, off);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 4u * (13 + 21 + 3 * 7 + 4 * 7 + 1 + 3 * 7 + 2));
}

TEST(Codec, EncodeRefusesNonFinite) {
  PoseCommand p;
  p.v_W[1] = std::nan("");
  std::vector<std::uint8_t> buf(1024);
  Errc e = Errc::kOk;
  EXPECT_EQ(encode({}, p, buf, &e), 0u);
  EXPECT_EQ(e, Errc::kNotFinite);
  State s;
  s.force_n[2] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(encode({}, s, buf, &e), 0u);
  EXPECT_EQ(e, Errc::kNotFinite);
}

TEST(Codec, EncodeRefusesOverBoundsAndSmallBuffers) {
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  Errc e = Errc::kOk;
  State s;
  s.contacts.resize(kMaxStateContacts + 1);
  EXPECT_EQ(encode({}, s, buf, &e), 0u);
  EXPECT_EQ(e, Errc::kBadValue);
  Hello h;
  h.client_name.assign(kMaxNameBytes + 1, 'x');
  EXPECT_EQ(encode({}, h, buf, &e), 0u);
  EXPECT_EQ(e, Errc::kBadValue);
  std::vector<std::uint8_t> small(kHeaderSize + PoseCommand::kFixedSize - 1);
  EXPECT_EQ(encode({}, PoseCommand{}, small, &e), 0u);
  EXPECT_EQ(e, Errc::kBufferTooSmall);
}

TEST(Codec, NonUnitQuaternionRefused) {
  PoseCommand p;
  p.X_WT.q = {0.0, 0.0, 0.0, 1.01};
  auto b = encodeOrDie(p);
  Header got;
  Message back;
  auto e = decode(b, got, back);
  EXPECT_EQ(e.code, Errc::kBadValue);
  EXPECT_NE(describe(e).find("q (norm)"), std::string::npos) << describe(e);
  p.X_WT.q = {0.0, 0.0, 0.0, 0.0};
  b = encodeOrDie(p);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadValue);
  p.X_WT.q = {0.0, 0.0, 0.0, 1.0 + 0.5 * kQuatNormTolerance};  // within tolerance
  b = encodeOrDie(p);
  EXPECT_EQ(decode(b, got, back).code, Errc::kOk);
}

TEST(Codec, CountsOverBoundsRefusedBeforeReading) {
  // State claiming 33 contacts (bound 32) and a matching length
  State s;
  auto b = encodeOrDie(s);
  putU16(b, kHeaderSize + 224, static_cast<std::uint16_t>(kMaxStateContacts + 1));
  b.resize(b.size() + 56 * (kMaxStateContacts + 1), 0);
  putU32(b, 12, static_cast<std::uint32_t>(b.size() - kHeaderSize));
  Header got;
  Message back;
  auto e = decode(b, got, back);
  EXPECT_EQ(e.code, Errc::kBadValue);
  EXPECT_STREQ(e.field, "listed_contacts");
  // a SceneChunk with data_length 0, and one over the bound
  SceneChunk c;
  c.upload_id = 1;
  c.data = testing::sampleChunkBytes();
  b = encodeOrDie(c);
  putU32(b, kHeaderSize + 4, 0);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadValue);
  putU32(b, kHeaderSize + 4, static_cast<std::uint32_t>(kMaxChunkBytes + 1));
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadValue);
  // data_length that disagrees with payload_length
  putU32(b, kHeaderSize + 4, 1199);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadPayloadLength);
  // subscribe over 1 kHz
  b = encodeOrDie(Subscribe{1000, 0});
  putU32(b, kHeaderSize, 1001);
  e = decode(b, got, back);
  EXPECT_EQ(e.code, Errc::kBadValue);
  EXPECT_STREQ(e.field, "rate_hz");
  // scene begin with total 0 and id 0
  SceneBegin sb;
  sb.upload_id = 0;
  sb.total_bytes = 10;
  b = encodeOrDie(sb);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadValue);
  sb.upload_id = 1;
  sb.total_bytes = 0;
  b = encodeOrDie(sb);
  EXPECT_EQ(decode(b, got, back).code, Errc::kBadValue);
}

// ---- State minor 1: pairs_tested, pairs_skipped, max_penetration_m, tick_ns after the lists ----

// Re-labels an encoded datagram as sent with `minor` and sets its payload length.
void relabel(std::vector<std::uint8_t>& b, std::uint8_t minor) {
  b[5] = minor;
  putU32(b, 12, static_cast<std::uint32_t>(b.size() - kHeaderSize));
}

TEST(CodecStateMinor1, FieldsRoundTripAtTheDocumentedOffsets) {
  State s = sampleState();
  s.pairs_tested = 0xA1B2C3D4u;
  s.pairs_skipped = 0x01020304u;
  s.max_penetration_m = 0.375;
  s.tick_ns = 0x0F0E0D0Cu;
  const auto b = encodeOrDie(s);
  const std::size_t lists = State::kFixedSize + 56 * s.contacts.size() + 64 * s.bodies.size();
  ASSERT_EQ(b.size(), kHeaderSize + lists + State::kMinor1Size);
  EXPECT_EQ(b[5], kVersionMinor);  // our minor on the wire (1 when these fields came)
  const std::size_t at = kHeaderSize + lists;
  EXPECT_EQ(b[at + 0], 0xD4);
  EXPECT_EQ(b[at + 3], 0xA1);
  EXPECT_EQ(b[at + 4], 0x04);
  EXPECT_EQ(b[at + 7], 0x01);
  std::uint64_t pen = 0;
  for (std::size_t i = 0; i < 8; ++i)
    pen |= static_cast<std::uint64_t>(b[at + 8 + i]) << (8 * i);
  EXPECT_EQ(std::bit_cast<double>(pen), 0.375);
  EXPECT_EQ(b[at + 16], 0x0C);
  EXPECT_EQ(b[at + 19], 0x0F);
  for (std::size_t i = 20; i < 24; ++i)
    EXPECT_EQ(b[at + i], 0u) << "reserved byte " << i;
  EXPECT_EQ(decoded<State>(b), s);
}

TEST(CodecStateMinor1, AOneZeroStateWithoutTheFieldsDecodesWithZeros) {
  const State s = sampleState();
  ASSERT_NE(s.pairs_tested, 0u);
  auto b = encodeOrDie(s);
  b.resize(b.size() - State::kMinor1Size);  // what a 1.0 sender writes
  relabel(b, 0);
  Header h;
  Message back;
  const auto e = decode(b, h, back);
  ASSERT_EQ(e.code, Errc::kOk) << describe(e);
  const State& got = std::get<State>(back);
  EXPECT_EQ(got.pairs_tested, 0u);
  EXPECT_EQ(got.pairs_skipped, 0u);
  EXPECT_EQ(got.max_penetration_m, 0.0);
  EXPECT_EQ(got.tick_ns, 0u);
  State expect = s;
  expect.pairs_tested = expect.pairs_skipped = expect.tick_ns = 0;
  expect.max_penetration_m = 0.0;
  EXPECT_EQ(got, expect);
  // an empty State from 1.0 too
  auto e0 = encodeOrDie(State{});
  e0.resize(e0.size() - State::kMinor1Size);
  relabel(e0, 0);
  EXPECT_EQ(decode(e0, h, back).code, Errc::kOk);
}

TEST(CodecStateMinor1, AOneZeroStateMustStillBeExact) {
  // 1.0 had no tail: a 1.0 State with the 24 bytes (or one byte more) is refused
  auto b = encodeOrDie(sampleState());
  relabel(b, 0);
  Header h;
  Message back;
  auto e = decode(b, h, back);
  EXPECT_EQ(e.code, Errc::kBadPayloadLength) << describe(e);
  b.resize(b.size() - State::kMinor1Size + 1);
  relabel(b, 0);
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
}

TEST(CodecStateMinor1, ANewerMinorsTrailingBytesAreIgnored) {
  const State s = sampleState();
  auto b = encodeOrDie(s);
  for (int i = 0; i < 40; ++i)  // a newer minor's field list we do not know
    b.push_back(static_cast<std::uint8_t>(0x80 + i));
  relabel(b, kVersionMinor + 1);
  Header h;
  Message back;
  const auto e = decode(b, h, back);
  ASSERT_EQ(e.code, Errc::kOk) << describe(e);
  EXPECT_EQ(std::get<State>(back), s);  // the 1.1 fields are read, the rest ignored
  EXPECT_EQ(h.minor, kVersionMinor + 1);
}

TEST(CodecStateMinor1, OneByteShortIsRefusedAtMinorOneAndAbove) {
  for (std::uint8_t minor : {std::uint8_t{1}, std::uint8_t{2}}) {
    auto b = encodeOrDie(sampleState());
    b.pop_back();
    relabel(b, minor);
    Header h;
    Message back;
    const auto e = decode(b, h, back);
    EXPECT_EQ(e.code, Errc::kBadPayloadLength) << int(minor) << ": " << describe(e);
    EXPECT_EQ(e.expected, e.got + 1) << describe(e);
  }
  // and the 1.0 prefix alone, labelled 1.1, is short by the whole tail
  auto b = encodeOrDie(sampleState());
  b.resize(b.size() - State::kMinor1Size);
  relabel(b, 1);
  Header h;
  Message back;
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
}

TEST(CodecStateMinor1, NegativePenetrationRefusedNanRefusedAtItsOffset) {
  State s = sampleState();
  s.max_penetration_m = -1e-6;
  auto b = encodeOrDie(s);
  Header h;
  Message back;
  auto e = decode(b, h, back);
  EXPECT_EQ(e.code, Errc::kBadValue);
  EXPECT_STREQ(e.field, "max_penetration_m (>= 0)");
  s.max_penetration_m = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::uint8_t> buf(8192);
  Errc ec = Errc::kOk;
  EXPECT_EQ(encode({}, s, buf, &ec), 0u);
  EXPECT_EQ(ec, Errc::kNotFinite);
}

TEST(Codec, DescribeNamesWhatAndWhere) {
  auto b = encodeOrDie(PoseCommand{});
  b.resize(b.size() - 12);
  putU32(b, 12, static_cast<std::uint32_t>(b.size() - kHeaderSize));
  Header got;
  Message back;
  const auto e = decode(b, got, back);
  EXPECT_EQ(describe(e), "pose_command: payload length 100 bytes, expected 112");
}

// ---- StatusReply minor 1: shm and scene-edit counters after the texts ----
// the minor-1 and minor-2 tails
std::size_t statusTail(const StatusReply& r) {
  return StatusReply::kMinor1FixedSize + r.shm_name.size() + StatusReply::kMinor2FixedSize +
         r.loading.size();
}

TEST(CodecStatusMinor1, FieldsRoundTripAtTheDocumentedOffsets) {
  const StatusReply r = sampleStatus();
  ASSERT_FALSE(r.shm_name.empty());
  const auto b = encodeOrDie(r);
  const std::size_t texts = kHeaderSize + StatusReply::kFixedSize + 8 * r.refused.size() +
                            r.device.size() + r.scene.size() + r.plan.size();
  ASSERT_EQ(b.size(), texts + statusTail(r));
  EXPECT_EQ(b[texts], 77u);                                    // shm_commands, u64 little-endian
  EXPECT_EQ(b[texts + 8], 2u);                                 // shm_commands_refused
  EXPECT_EQ(b[texts + 16], 9u);                                // edit_batches_applied
  EXPECT_EQ(b[texts + 24], 1u);                                // edit_batches_dropped
  EXPECT_EQ(b[texts + 32], 30u);                               // edits_applied
  EXPECT_EQ(b[texts + 40], 4u);                                // edits_refused
  EXPECT_EQ(b[texts + 48], kShmServing | kShmClientAttached);  // shm_flags u32
  EXPECT_EQ(b[texts + 52], r.shm_name.size());                 // shm_name_length u16
  EXPECT_EQ(std::string(b.begin() + static_cast<long>(texts + 56),
                        b.begin() + static_cast<long>(texts + 56 + r.shm_name.size())),
            r.shm_name);
  EXPECT_EQ(decoded<StatusReply>(b), r);
}

TEST(CodecStatusMinor1, AOneZeroStatusWithoutTheTailDecodesWithZerosAndMustBeExact) {
  const StatusReply r = sampleStatus();
  auto b = encodeOrDie(r);
  b.resize(b.size() - statusTail(r));  // what a 1.0 sender writes
  relabel(b, 0);
  Header h;
  Message back;
  const auto e = decode(b, h, back);
  ASSERT_EQ(e.code, Errc::kOk) << describe(e);
  StatusReply expect = r;
  expect.shm_commands = expect.shm_commands_refused = 0;
  expect.edit_batches_applied = expect.edit_batches_dropped = 0;
  expect.edits_applied = expect.edits_refused = 0;
  expect.shm_flags = 0;
  expect.shm_name.clear();
  EXPECT_EQ(std::get<StatusReply>(back), expect);
  // 1.0 had no tail: a 1.0 StatusReply carrying it is refused
  auto full = encodeOrDie(r);
  relabel(full, 0);
  EXPECT_EQ(decode(full, h, back).code, Errc::kBadPayloadLength);
}

TEST(CodecStatusMinor1, ShortLongAndNewerMinor) {
  const StatusReply r = sampleStatus();
  Header h;
  Message back;
  // one byte short at 1.1 (in the name) and without the whole tail
  auto b = encodeOrDie(r);
  b.pop_back();
  relabel(b, 1);
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
  b = encodeOrDie(r);
  b.resize(b.size() - statusTail(r));
  relabel(b, 1);
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
  // one byte long at our minor
  b = encodeOrDie(r);
  b.push_back(0);
  relabel(b, kVersionMinor);
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
  // a newer minor's trailing bytes are ignored
  b = encodeOrDie(r);
  for (int i = 0; i < 17; ++i)
    b.push_back(static_cast<std::uint8_t>(i));
  relabel(b, static_cast<std::uint8_t>(kVersionMinor + 1));
  ASSERT_EQ(decode(b, h, back).code, Errc::kOk);
  EXPECT_EQ(std::get<StatusReply>(back), r);
  // a name over its bound is refused on both sides
  StatusReply longer = r;
  longer.shm_name.assign(kMaxShmNameBytes + 1, 'x');
  std::vector<std::uint8_t> out(65536);
  Errc why = Errc::kOk;
  EXPECT_EQ(encode(Header{}, longer, out, &why), 0u);
  EXPECT_EQ(why, Errc::kBadValue);
}

// ---- StatusReply minor 2: what a scene build is doing, after shm_name ----
TEST(CodecStatusMinor2, LoadingRoundTripsAtTheDocumentedOffset) {
  StatusReply r = sampleStatus();
  r.loading = "loading scene 'a.glb': decomposing mesh 2 (mesh 1 'Bunny'), 12 pieces, 1.4 s";
  const auto b = encodeOrDie(r);
  ASSERT_EQ(b[5], 2u);
  const std::size_t at = b.size() - StatusReply::kMinor2FixedSize - r.loading.size();
  EXPECT_EQ(b[at] | (b[at + 1] << 8), static_cast<int>(r.loading.size()));  // loading_length
  EXPECT_EQ(b[at + 2], 0u);                                                 // reserved
  EXPECT_EQ(b[at + 3], 0u);
  EXPECT_EQ(std::string(b.begin() + static_cast<long>(at + 4), b.end()), r.loading);
  EXPECT_EQ(decoded<StatusReply>(b), r);
  // with no build running: 4 bytes, ""
  const StatusReply idle = sampleStatus();
  ASSERT_TRUE(idle.loading.empty());
  EXPECT_EQ(decoded<StatusReply>(encodeOrDie(idle)), idle);
}

TEST(CodecStatusMinor2, AOneOneStatusWithoutItReadsEmptyAndMustBeExact) {
  StatusReply r = sampleStatus();
  r.loading = "loading";
  auto b = encodeOrDie(r);
  b.resize(b.size() - StatusReply::kMinor2FixedSize - r.loading.size());  // a 1.1 sender's
  relabel(b, 1);
  Header h;
  Message back;
  const auto e = decode(b, h, back);
  ASSERT_EQ(e.code, Errc::kOk) << describe(e);
  StatusReply expect = r;
  expect.loading.clear();
  EXPECT_EQ(std::get<StatusReply>(back), expect);
  // 1.1 had no loading: a 1.1 StatusReply carrying it is refused
  auto full = encodeOrDie(r);
  relabel(full, 1);
  EXPECT_EQ(decode(full, h, back).code, Errc::kBadPayloadLength);
  // at 1.2: one byte short (in the text), and without the length field, are refused
  full = encodeOrDie(r);
  full.pop_back();
  relabel(full, 2);
  EXPECT_EQ(decode(full, h, back).code, Errc::kBadPayloadLength);
  relabel(b, 2);
  EXPECT_EQ(decode(b, h, back).code, Errc::kBadPayloadLength);
  // a text over its bound is refused on both sides
  StatusReply longer = r;
  longer.loading.assign(kMaxTextBytes + 1, 'x');
  std::vector<std::uint8_t> out(65536);
  Errc why = Errc::kOk;
  EXPECT_EQ(encode(Header{}, longer, out, &why), 0u);
  EXPECT_EQ(why, Errc::kBadValue);
}

}  // namespace
}  // namespace hapticd::proto
