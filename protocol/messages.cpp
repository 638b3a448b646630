#include "protocol/messages.h"

#include <cmath>
#include <concepts>
#include <type_traits>

namespace hapticd::proto {
namespace {

// ---- how a layout is written ----------------------------------------------------------------
// Every message (and every list item) has ONE layout function, `layout(io, m)`, that lists its
// fields in wire order. The same function encodes (io = Put), measures (Put over a ByteCounter)
// and decodes with every check the format requires (io = Get). A field's C++ type is its wire
// type: std::uint8_t..std::uint64_t as such, double as f64, an enum as its underlying integer,
// std::array<double, N> as N f64, std::array<std::uint8_t, N> as N bytes, Pad<N> as N reserved
// zero bytes, and a struct with a layout of its own (WirePose, BodyPose, ...) as that layout.
//
// Fields with a bound: count16/count32 is the count field of a list or string, code() an enum
// field; a value over its bound is refused on both sides. body() marks the end of the fixed part,
// where the decoder checks the payload length against the fixed part plus what the counts announce
// (exact up to our minor, at least above it); list/text/data then carry the counted items in the
// order of their counts. since(1) guards what minor 1 appended.

/// N reserved bytes: zero on send, skipped on receive.
template <std::size_t N>
struct Pad {
  static constexpr std::size_t kBytes = N;
};
constexpr Pad<2> kPad2;
constexpr Pad<4> kPad4;

template <class T>
struct IsPad : std::false_type {};
template <std::size_t N>
struct IsPad<Pad<N>> : std::true_type {};

/// std::array fields: kArray, and kBytes when its elements are bytes (carried as they are).
template <class T>
struct ArrayTraits {
  static constexpr bool kArray = false;
  static constexpr bool kBytes = false;
};
template <class T, std::size_t N>
struct ArrayTraits<std::array<T, N>> {
  static constexpr bool kArray = true;
  static constexpr bool kBytes = std::is_same_v<T, std::uint8_t>;
};

/// The count field of a list or string (an integer of type N on the wire), bounded to
/// [min, max]: an encoder refuses a longer list, a decoder a larger count (kBadValue, `field`).
template <class N, class List>
struct Count {
  using Wire = N;
  List& list;
  std::size_t max;
  const char* field;
  std::size_t min = 0;
};
template <class T>
struct IsCount : std::false_type {};
template <class N, class List>
struct IsCount<Count<N, List>> : std::true_type {};
template <class List>
constexpr Count<std::uint16_t, List> count16(List& l, std::size_t max, const char* field) {
  return {l, max, field};
}
template <class List>
constexpr Count<std::uint32_t, List> count32(List& l,
                                             std::size_t max,
                                             const char* field,
                                             std::size_t min) {
  return {l, max, field, min};
}
/// An enum field (u16 on the wire) whose values stop at `max`: a decoder refuses a larger one.
template <class E>
struct Code {
  E& value;
  E max;
  const char* field;
};
template <class E>
constexpr Code<E> code(E& v, std::remove_const_t<E> max, const char* field) {
  return {v, max, field};
}
template <class T>
struct IsCode : std::false_type {};
template <class E>
struct IsCode<Code<E>> : std::true_type {};

/// M is T or const T (a layout serves the encoder, which reads a const message, and the
/// decoder, which fills one).
template <class M, class T>
concept Is = std::same_as<std::remove_const_t<M>, T>;

/// A Writer that only counts bytes: measures a message with the encoder's own layout.
struct ByteCounter {
  std::size_t n = 0;
  constexpr void u8(std::uint8_t) { n += 1; }
  constexpr void u16(std::uint16_t) { n += 2; }
  constexpr void u32(std::uint32_t) { n += 4; }
  constexpr void u64(std::uint64_t) { n += 8; }
  constexpr void f64(double) { n += 8; }
  constexpr void bytes(std::span<const std::uint8_t> s) { n += s.size(); }
  constexpr void zeros(std::size_t k) { n += k; }
};

/// The encoder over a Writer (or a ByteCounter). ok() is false when a count is over its bound.
template <class Sink>
class Put {
 public:
  constexpr explicit Put(Sink& sink) : s_(sink) {}

  template <class... F>
  constexpr void fields(const F&... f) {
    (one(f), ...);
  }
  constexpr void body(std::size_t = 0, bool = false, std::uint8_t = 1) {}
  constexpr bool since(std::uint8_t) const { return true; }  // the encoder writes our newest layout
  template <class T>
  constexpr void list(const std::vector<T>& items) {
    for (const T& x : items)
      one(x);
  }
  constexpr void text(const std::string& t) {
    s_.bytes({reinterpret_cast<const std::uint8_t*>(t.data()), t.size()});
  }
  constexpr void data(std::span<const std::uint8_t> d) { s_.bytes(d); }
  constexpr bool ok() const { return ok_; }

 private:
  template <class T>
  constexpr void one(const T& v) {
    if constexpr (std::is_enum_v<T>)
      one(static_cast<std::underlying_type_t<T>>(v));
    else if constexpr (std::is_same_v<T, std::uint8_t>)
      s_.u8(v);
    else if constexpr (std::is_same_v<T, std::uint16_t>)
      s_.u16(v);
    else if constexpr (std::is_same_v<T, std::uint32_t>)
      s_.u32(v);
    else if constexpr (std::is_same_v<T, std::uint64_t>)
      s_.u64(v);
    else if constexpr (std::is_same_v<T, double>)
      s_.f64(v);
    else if constexpr (IsPad<T>::value)
      s_.zeros(T::kBytes);
    else if constexpr (IsCode<T>::value)
      one(v.value);
    else if constexpr (IsCount<T>::value) {
      if (v.list.size() < v.min || v.list.size() > v.max)
        ok_ = false;
      one(static_cast<typename T::Wire>(v.list.size()));
    } else if constexpr (ArrayTraits<T>::kBytes)
      s_.bytes(v);
    else if constexpr (ArrayTraits<T>::kArray) {
      for (const auto& x : v)
        one(x);
    } else {
      layout(*this, v);
    }
  }
  Sink& s_;
  bool ok_ = true;
};

/// The decoder over a Reader of the whole payload: reads the fields, refuses a count or code
/// over its bound at once, and checks the payload length at body(). The first refusal stops it.
class Get {
 public:
  Get(Reader& r, MsgType type, std::size_t fixed_size, std::uint8_t minor)
      : r_(r),
        type_(type),
        total_(r.remaining()),
        expected_(fixed_size),
        minor_(minor),
        exact_(minor <= kVersionMinor) {}

  template <class... F>
  void fields(F&&... f) {
    (one(f), ...);
  }
  /// The end of the fixed part: the payload must hold the fixed part and what the counts
  /// announce, plus `tail` bytes from a sender of minor `tail_minor` or newer. `tail_counted`:
  /// that tail has counts of its own (checked by a later body()), so for now "at least".
  void body(std::size_t tail = 0, bool tail_counted = false, std::uint8_t tail_minor = 1) {
    if (failed())
      return;
    if (minor_ >= tail_minor)
      expected_ += tail;
    const bool exact = exact_ && !(tail_counted && minor_ >= tail_minor);
    if (exact ? total_ != expected_ : total_ < expected_)
      refuse(Errc::kBadPayloadLength, total_, expected_, exact ? "payload" : "payload (at least)");
  }
  bool since(std::uint8_t minor) const { return !failed() && minor_ >= minor; }
  template <class T>
  void list(std::vector<T>& items) {
    items.resize(take());
    for (T& x : items)
      one(x);
  }
  void text(std::string& t) {
    const auto b = r_.bytes(take());
    t.assign(reinterpret_cast<const char*>(b.data()), b.size());
  }
  void data(std::span<const std::uint8_t>& d) { d = r_.bytes(take()); }

  bool failed() const { return error_.code != Errc::kOk; }
  const DecodeError& error() const { return error_; }

 private:
  template <class T>
  void one(T& v) {
    using U = std::remove_const_t<T>;
    if constexpr (std::is_enum_v<U>)
      v = static_cast<U>(r_.u16());
    else if constexpr (std::is_same_v<U, std::uint8_t>)
      v = r_.u8();
    else if constexpr (std::is_same_v<U, std::uint16_t>)
      v = r_.u16();
    else if constexpr (std::is_same_v<U, std::uint32_t>)
      v = r_.u32();
    else if constexpr (std::is_same_v<U, std::uint64_t>)
      v = r_.u64();
    else if constexpr (std::is_same_v<U, double>)
      v = r_.f64();
    else if constexpr (IsPad<U>::value)
      r_.bytes(U::kBytes);
    else if constexpr (IsCode<U>::value) {
      const std::uint16_t raw = r_.u16();
      if (raw > static_cast<std::uint16_t>(v.max))
        refuse(Errc::kBadValue, raw, static_cast<std::uint16_t>(v.max), v.field);
      v.value = static_cast<std::remove_reference_t<decltype(v.value)>>(raw);
    } else if constexpr (IsCount<U>::value)
      counted(read<typename U::Wire>(), v.list, v.min, v.max, v.field);
    else if constexpr (ArrayTraits<U>::kBytes) {
      const auto b = r_.bytes(v.size());
      if (b.size() == v.size())
        std::memcpy(v.data(), b.data(), b.size());
    } else if constexpr (ArrayTraits<U>::kArray) {
      for (auto& x : v)
        one(x);
    } else {
      layout(*this, v);
    }
  }
  template <class N>
  std::size_t read() {
    if constexpr (std::is_same_v<N, std::uint16_t>)
      return r_.u16();
    else
      return r_.u32();
  }
  // a count: bounded at once; its items are read later, in the order of the counts
  template <class List>
  void counted(std::size_t n, const List&, std::size_t min, std::size_t max, const char* field) {
    if (failed())
      return;
    if (n < min || n > max)
      return refuse(Errc::kBadValue, n, max, field);
    expected_ += n * itemBytes<List>();
    pending_[pushed_++ % pending_.size()] = n;
  }
  std::size_t take() { return failed() ? 0 : pending_[taken_++ % pending_.size()]; }
  void refuse(Errc c, std::uint64_t got, std::uint64_t expected, const char* field) {
    if (!failed())
      error_ = {c, static_cast<std::uint16_t>(type_), got, expected, field};
  }
  template <class List>
  static constexpr std::size_t itemBytes();

  Reader& r_;
  MsgType type_;
  std::size_t total_;
  std::size_t expected_;
  std::uint8_t minor_;
  bool exact_;
  std::array<std::size_t, 4> pending_{};  // counts whose items are still to read (≤ 4 per message)
  std::size_t pushed_ = 0;
  std::size_t taken_ = 0;
  DecodeError error_;
};

// ---- the layouts, in wire order (protocol/README.md has them as tables) ---------------------

template <class Io, Is<WirePose> M>
constexpr void layout(Io& io, M& x) {
  io.fields(x.p, x.q);
}
template <class Io, Is<SceneStatus::Range> M>
constexpr void layout(Io& io, M& g) {
  io.fields(g.offset, g.length);
}
template <class Io, Is<SceneUpdate::BodyPose> M>
constexpr void layout(Io& io, M& b) {
  io.fields(b.body_index, kPad4, b.X_WB);
}
template <class Io, Is<State::Contact> M>
constexpr void layout(Io& io, M& c) {
  io.fields(c.p_W, c.n_W, c.depth_m);
}

template <class Io, Is<Hello> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.capabilities, count16(m.client_name, kMaxNameBytes, "name_length"), kPad2);
  io.body();
  io.text(m.client_name);
}
template <class Io, Is<Welcome> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.session_id, m.capabilities, m.flags, m.max_datagram_bytes, m.max_chunk_bytes,
            m.max_scene_bytes, m.max_state_rate_hz, m.tick_rate_hz, m.max_state_contacts,
            m.max_state_bodies, m.max_update_entries, kPad2, m.session_timeout_ns);
  io.body();
}
template <class Io, Is<SceneBegin> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.upload_id, m.chunk_bytes, m.total_bytes, m.sha256,
            count16(m.name, kMaxSceneNameBytes, "name_length"), kPad2);
  io.body();
  io.text(m.name);
}
template <class Io, Is<SceneChunk> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.upload_id, count32(m.data, kMaxChunkBytes, "data_length", 1), m.offset);
  io.body();
  io.data(m.data);
}
template <class Io, Is<SceneChunkAck> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.upload_id, m.length, m.offset, m.received_bytes, m.total_bytes);
  io.body();
}
template <class Io, Is<SceneCommit> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.upload_id, kPad4);
  io.body();
}
template <class Io, Is<SceneStatus> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.upload_id, code(m.status, SceneStatusCode::kUnknownUpload, "status"),
            count16(m.missing, kMaxMissingRanges, "missing_count"), m.received_bytes, m.total_bytes,
            count16(m.text, kMaxTextBytes, "text_length"), kPad2, kPad4);
  io.body();
  io.list(m.missing);
  io.text(m.text);
}
template <class Io, Is<SceneUpdate> M>
constexpr void layout(Io& io, M& m) {
  io.fields(count16(m.poses, kMaxUpdateEntries, "pose_count"),
            count16(m.added, kMaxUpdateEntries, "add_count"),
            count16(m.removed, kMaxUpdateEntries, "remove_count"), kPad2);
  io.body();
  io.list(m.poses);
  io.list(m.added);
  io.list(m.removed);
}
template <class Io, Is<PoseCommand> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.X_WT, m.v_W, m.w_W, m.buttons, kPad4);
  io.body();
}
template <class Io, Is<Subscribe> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.rate_hz, m.flags);
  io.body();
}
// State gained a tail in minor 1, after its lists: one exact length per minor up to ours.
template <class Io, Is<State> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.tick, m.sim_time_ns, m.X_WD, m.X_WP, m.force_n, m.torque_nm, m.force_scale,
            m.last_command_sequence, m.tick_misses, m.tick_p50_ns, m.tick_p99_ns, m.tick_max_ns,
            m.fault_bits, m.state_flags, m.contact_count,
            count16(m.contacts, kMaxStateContacts, "listed_contacts"),
            count16(m.bodies, kMaxStateBodies, "listed_bodies"), kPad4);
  io.body(State::kMinor1Size);
  io.list(m.contacts);
  io.list(m.bodies);
  if (io.since(1))  // from a 1.0 sender these stay 0
    io.fields(m.pairs_tested, m.pairs_skipped, m.max_penetration_m, m.tick_ns, kPad4);
}
template <class Io, Is<Heartbeat> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.echo_timestamp_ns);
  io.body();
}
// a newer peer's unknown code is kept as is: errcName() says "unknown"
template <class Io, Is<ErrorMsg> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.ref_sequence, m.ref_type, m.code, count16(m.text, kMaxTextBytes, "text_length"),
            kPad2);
  io.body();
  io.text(m.text);
}
// Like State, StatusReply gained a tail in minor 1 (after its texts), with a count of its own,
// and another in minor 2 (after the first).
template <class Io, Is<StatusReply> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.uptime_ns, m.ticks, m.tick_misses, m.tick_rate_hz, m.measured_tick_hz, m.tick_p50_ns,
            m.tick_p99_ns, m.tick_max_ns, m.fault_bits, m.state_flags, m.sessions, m.subscribers,
            m.state_rate_hz, m.packets_received, m.packets_sent, m.commands_accepted,
            m.commands_dropped, count16(m.refused, kMaxRefusalCounters, "refused_count"),
            count16(m.device, kMaxDeviceBytes, "device_length"),
            count16(m.scene, kMaxSceneNameBytes, "scene_length"),
            count16(m.plan, kMaxPlanBytes, "plan_length"));
  io.body(StatusReply::kMinor1FixedSize, /*tail_counted=*/true);
  io.list(m.refused);
  io.text(m.device);
  io.text(m.scene);
  io.text(m.plan);
  if (!io.since(1))
    return;  // a 1.0 sender: the minor-1 fields stay 0 and ""
  io.fields(m.shm_commands, m.shm_commands_refused, m.edit_batches_applied, m.edit_batches_dropped,
            m.edits_applied, m.edits_refused, m.shm_flags,
            count16(m.shm_name, kMaxShmNameBytes, "shm_name_length"), kPad2);
  io.body(StatusReply::kMinor2FixedSize, /*tail_counted=*/true, /*tail_minor=*/2);
  io.text(m.shm_name);
  if (!io.since(2))
    return;  // a 1.1 sender: loading stays ""
  io.fields(count16(m.loading, kMaxTextBytes, "loading_length"), kPad2);
  io.body();
  io.text(m.loading);
}
template <class Io, Is<Ack> M>
constexpr void layout(Io& io, M& m) {
  io.fields(m.ref_sequence, m.ref_type, kPad2, kPad4);
  io.body();
}
// Arm, Disarm, StatusRequest, Bye: the messages without payload
template <class Io, class M>
requires(std::remove_const_t<M>::kFixedSize == 0) constexpr void layout(Io& io, M&) {
  io.body();
}

/// Bytes of one item of a counted list (a string's item is a byte), from its layout.
template <class T>
constexpr std::size_t wireSize() {
  ByteCounter n;
  Put<ByteCounter> p(n);
  const T item{};
  p.fields(item);
  return n.n;
}
template <class List>
constexpr std::size_t Get::itemBytes() {
  if constexpr (std::is_same_v<List, std::string> ||
                std::is_same_v<List, std::span<const std::uint8_t>>)
    return 1;
  else
    return wireSize<typename List::value_type>();
}

// ---- what a layout cannot say: value checks after decoding, and what an encoder refuses -----

bool unitQuat(const WirePose& x) {
  const double n = std::sqrt(x.q[0] * x.q[0] + x.q[1] * x.q[1] + x.q[2] * x.q[2] + x.q[3] * x.q[3]);
  return std::fabs(n - 1.0) <= kQuatNormTolerance;
}

DecodeError err(Errc c, MsgType t, std::uint64_t got, std::uint64_t expected, const char* field) {
  return {c, static_cast<std::uint16_t>(t), got, expected, field};
}

/// Ranges a decoded message must respect beyond its counts (finite floats are checked first).
template <class M>
DecodeError checkValues(const M&) {
  return {};
}
DecodeError checkValues(const SceneBegin& m) {
  if (m.upload_id == 0)
    return err(Errc::kBadValue, SceneBegin::kType, 0, 1, "upload_id");
  if (m.total_bytes == 0)
    return err(Errc::kBadValue, SceneBegin::kType, 0, 1, "total_bytes");
  return {};
}
DecodeError checkValues(const SceneChunk& m) {
  if (m.offset > UINT64_MAX - m.data.size())
    return err(Errc::kBadValue, SceneChunk::kType, m.offset, UINT64_MAX - m.data.size(), "offset");
  return {};
}
DecodeError checkValues(const SceneUpdate& m) {
  for (const auto& b : m.poses)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, SceneUpdate::kType, b.body_index, 0, "poses[].q (norm)");
  for (const auto& b : m.added)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, SceneUpdate::kType, b.body_index, 0, "added[].q (norm)");
  return {};
}
DecodeError checkValues(const PoseCommand& m) {
  if (!unitQuat(m.X_WT))
    return err(Errc::kBadValue, PoseCommand::kType, 0, 0, "target q (norm)");
  return {};
}
DecodeError checkValues(const Subscribe& m) {
  if (m.rate_hz > kMaxStateRateHz)
    return err(Errc::kBadValue, Subscribe::kType, m.rate_hz, kMaxStateRateHz, "rate_hz");
  return {};
}
DecodeError checkValues(const State& m) {
  constexpr auto kT = State::kType;
  if (!(m.max_penetration_m >= 0.0))
    return err(Errc::kBadValue, kT, 0, 0, "max_penetration_m (>= 0)");
  if (!(m.force_scale >= 0.0 && m.force_scale <= 1.0))
    return err(Errc::kBadValue, kT, 0, 1, "force_scale (0..1)");
  if (!unitQuat(m.X_WD))
    return err(Errc::kBadValue, kT, 0, 0, "device q (norm)");
  if (!unitQuat(m.X_WP))
    return err(Errc::kBadValue, kT, 0, 0, "proxy q (norm)");
  for (const auto& b : m.bodies)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, kT, b.body_index, 0, "bodies[].q (norm)");
  return {};
}

/// Besides the counts: what an encoder refuses to send (kBadValue).
template <class M>
bool encodable(const M&) {
  return true;
}
bool encodable(const Subscribe& m) {
  return m.rate_hz <= kMaxStateRateHz;
}

/// Messages with counted parts: a payload shorter than their fixed part is "at least" short.
template <class M>
constexpr bool kCounted =
    std::is_same_v<M, Hello> || std::is_same_v<M, SceneBegin> || std::is_same_v<M, SceneChunk> ||
    std::is_same_v<M, SceneStatus> || std::is_same_v<M, SceneUpdate> || std::is_same_v<M, State> ||
    std::is_same_v<M, ErrorMsg> || std::is_same_v<M, StatusReply>;

template <class M>
DecodeError decodeAs(std::span<const std::uint8_t> payload, std::uint8_t minor, Message& out) {
  if (payload.size() < M::kFixedSize) {
    const bool exact = !kCounted<M> && minor <= kVersionMinor;
    return err(Errc::kBadPayloadLength, M::kType, payload.size(), M::kFixedSize,
               exact ? "payload" : "payload (at least)");
  }
  M m{};
  Reader r(payload);
  Get get(r, M::kType, M::kFixedSize, minor);
  layout(get, m);
  if (get.failed())
    return get.error();
  if (r.nonFinite())
    return err(Errc::kNotFinite, M::kType, r.nonFiniteAt(), 0, "a float field (NaN or Inf)");
  if (DecodeError e = checkValues(m); e.code != Errc::kOk)
    return e;
  out = std::move(m);
  return {};
}

// Layout checks: the fixed sizes the README documents are what the layouts write.
static_assert(kHeaderSize == 4 + 1 + 1 + 2 + 2 + 2 + 4 + 8 + 8 + 8);
static_assert(wireSize<WirePose>() == kPoseSize);
static_assert(wireSize<Welcome>() == Welcome::kFixedSize);
static_assert(wireSize<SceneChunkAck>() == SceneChunkAck::kFixedSize);
static_assert(wireSize<SceneCommit>() == SceneCommit::kFixedSize);
static_assert(wireSize<PoseCommand>() == PoseCommand::kFixedSize);
static_assert(wireSize<Subscribe>() == Subscribe::kFixedSize);
static_assert(wireSize<Heartbeat>() == Heartbeat::kFixedSize);
static_assert(wireSize<Ack>() == Ack::kFixedSize);
static_assert(wireSize<Arm>() == 0 && wireSize<Bye>() == 0);
constexpr std::size_t kContactSize = wireSize<State::Contact>();
constexpr std::size_t kBodyPoseSize = wireSize<SceneUpdate::BodyPose>();
static_assert(kContactSize == 56 && kBodyPoseSize == 8 + kPoseSize);
static_assert(wireSize<SceneStatus::Range>() == 16);
static_assert(State::kMinor1Size == 4 + 4 + 8 + 4 + 4);
static_assert(kErrcCount <= kMaxRefusalCounters);
// the largest messages fit the largest datagram
static_assert(kHeaderSize + State::kFixedSize + kMaxStateContacts * kContactSize +
                  kMaxStateBodies * kBodyPoseSize + State::kMinor1Size + kMacSize <=
              8192);
static_assert(kHeaderSize + SceneChunk::kFixedSize + kMaxChunkBytes + kMacSize <=
              kMaxDatagramLimit);

}  // namespace

MsgType typeOf(const Message& m) {
  return std::visit([](const auto& x) { return std::decay_t<decltype(x)>::kType; }, m);
}

std::size_t payloadSize(const Message& m) {
  return std::visit(
      [](const auto& x) {
        ByteCounter n;
        Put<ByteCounter> p(n);
        layout(p, x);
        return n.n;
      },
      m);
}

std::size_t encode(Header h, const Message& m, std::span<std::uint8_t> out, Errc* error) {
  auto fail = [&](Errc c) {
    if (error)
      *error = c;
    return std::size_t{0};
  };
  ByteCounter size;
  const bool ok = std::visit(
      [&](const auto& x) {
        Put<ByteCounter> p(size);
        layout(p, x);
        return p.ok() && encodable(x);
      },
      m);
  if (!ok)
    return fail(Errc::kBadValue);
  const std::size_t n = size.n;
  if (out.size() < kHeaderSize + n)
    return fail(Errc::kBufferTooSmall);
  h.type = static_cast<std::uint16_t>(typeOf(m));
  h.payload_length = static_cast<std::uint32_t>(n);
  encodeHeader(h, out);
  Writer w(out.subspan(kHeaderSize, n));
  std::visit(
      [&](const auto& x) {
        Put<Writer> p(w);
        layout(p, x);
      },
      m);
  if (w.nonFinite())
    return fail(Errc::kNotFinite);
  if (w.failed() || w.position() != n)
    return fail(Errc::kBufferTooSmall);
  if (error)
    *error = Errc::kOk;
  return kHeaderSize + n;
}

DecodeError decodePayload(std::uint16_t type,
                          std::uint8_t minor,
                          std::span<const std::uint8_t> payload,
                          Message& out) {
  switch (static_cast<MsgType>(type)) {
    case MsgType::kHello:
      return decodeAs<Hello>(payload, minor, out);
    case MsgType::kWelcome:
      return decodeAs<Welcome>(payload, minor, out);
    case MsgType::kSceneBegin:
      return decodeAs<SceneBegin>(payload, minor, out);
    case MsgType::kSceneChunk:
      return decodeAs<SceneChunk>(payload, minor, out);
    case MsgType::kSceneChunkAck:
      return decodeAs<SceneChunkAck>(payload, minor, out);
    case MsgType::kSceneCommit:
      return decodeAs<SceneCommit>(payload, minor, out);
    case MsgType::kSceneStatus:
      return decodeAs<SceneStatus>(payload, minor, out);
    case MsgType::kSceneUpdate:
      return decodeAs<SceneUpdate>(payload, minor, out);
    case MsgType::kPoseCommand:
      return decodeAs<PoseCommand>(payload, minor, out);
    case MsgType::kSubscribe:
      return decodeAs<Subscribe>(payload, minor, out);
    case MsgType::kState:
      return decodeAs<State>(payload, minor, out);
    case MsgType::kArm:
      return decodeAs<Arm>(payload, minor, out);
    case MsgType::kDisarm:
      return decodeAs<Disarm>(payload, minor, out);
    case MsgType::kHeartbeat:
      return decodeAs<Heartbeat>(payload, minor, out);
    case MsgType::kError:
      return decodeAs<ErrorMsg>(payload, minor, out);
    case MsgType::kStatusRequest:
      return decodeAs<StatusRequest>(payload, minor, out);
    case MsgType::kStatusReply:
      return decodeAs<StatusReply>(payload, minor, out);
    case MsgType::kAck:
      return decodeAs<Ack>(payload, minor, out);
    case MsgType::kBye:
      return decodeAs<Bye>(payload, minor, out);
  }
  return {Errc::kUnknownType, type, type, kMsgTypeEnd - 1, "type"};
}

DecodeError decode(std::span<const std::uint8_t> datagram, Header& header, Message& out) {
  DecodeError e = decodeHeader(datagram, header);
  if (e.code != Errc::kOk)
    return e;
  return decodePayload(header.type, header.minor,
                       datagram.subspan(kHeaderSize, header.payload_length), out);
}

}  // namespace hapticd::proto
