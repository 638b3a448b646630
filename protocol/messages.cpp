#include "protocol/messages.h"

#include <cmath>
#include <type_traits>

namespace hapticd::proto {
namespace {

// ---- shared pieces ------------------------------------------------------------------------

void putPose(Writer& w, const WirePose& x) {
  for (double v : x.p)
    w.f64(v);
  for (double v : x.q)
    w.f64(v);
}
void putVec(Writer& w, const WireVec3& v) {
  for (double c : v)
    w.f64(c);
}
WirePose getPose(Reader& r) {
  WirePose x;
  for (double& v : x.p)
    v = r.f64();
  for (double& v : x.q)
    v = r.f64();
  return x;
}
WireVec3 getVec(Reader& r) {
  WireVec3 v;
  for (double& c : v)
    c = r.f64();
  return v;
}
bool unitQuat(const WirePose& x) {
  const double n = std::sqrt(x.q[0] * x.q[0] + x.q[1] * x.q[1] + x.q[2] * x.q[2] + x.q[3] * x.q[3]);
  return std::fabs(n - 1.0) <= kQuatNormTolerance;
}
void putText(Writer& w, const std::string& s) {
  w.bytes({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()});
}
std::string getText(Reader& r, std::size_t n) {
  auto b = r.bytes(n);
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

DecodeError err(Errc c, MsgType t, std::uint64_t got, std::uint64_t expected, const char* field) {
  return {c, static_cast<std::uint16_t>(t), got, expected, field};
}

// The length rule: exact for our minor and older, at least for a newer minor.
DecodeError checkLength(MsgType t, std::size_t got, std::size_t expected, bool exact) {
  if (exact ? got != expected : got < expected)
    return err(Errc::kBadPayloadLength, t, got, expected, exact ? "payload" : "payload (at least)");
  return {};
}

// ---- per-message size, encode, decode -------------------------------------------------------
// Each message has size(m), put(w, m) and get(r, m, exact) -> DecodeError. get() is called with a
// Reader over the whole payload.

std::size_t size(const Hello& m) {
  return Hello::kFixedSize + m.client_name.size();
}
bool fits(const Hello& m) {
  return m.client_name.size() <= kMaxNameBytes;
}
void put(Writer& w, const Hello& m) {
  w.u32(m.capabilities);
  w.u16(static_cast<std::uint16_t>(m.client_name.size()));
  w.u16(0);
  putText(w, m.client_name);
}
DecodeError get(Reader& r, Hello& m, bool exact) {
  const std::size_t total = r.remaining();
  if (total < Hello::kFixedSize)
    return checkLength(Hello::kType, total, Hello::kFixedSize, false);
  m.capabilities = r.u32();
  const std::size_t n = r.u16();
  r.u16();
  if (n > kMaxNameBytes)
    return err(Errc::kBadValue, Hello::kType, n, kMaxNameBytes, "name_length");
  if (auto e = checkLength(Hello::kType, total, Hello::kFixedSize + n, exact); e.code != Errc::kOk)
    return e;
  m.client_name = getText(r, n);
  return {};
}

std::size_t size(const Welcome&) {
  return Welcome::kFixedSize;
}
bool fits(const Welcome&) {
  return true;
}
void put(Writer& w, const Welcome& m) {
  w.u64(m.session_id);
  w.u32(m.capabilities);
  w.u32(m.flags);
  w.u32(m.max_datagram_bytes);
  w.u32(m.max_chunk_bytes);
  w.u64(m.max_scene_bytes);
  w.u32(m.max_state_rate_hz);
  w.u32(m.tick_rate_hz);
  w.u16(m.max_state_contacts);
  w.u16(m.max_state_bodies);
  w.u16(m.max_update_entries);
  w.u16(0);
  w.u64(m.session_timeout_ns);
}
DecodeError get(Reader& r, Welcome& m, bool exact) {
  if (auto e = checkLength(Welcome::kType, r.remaining(), Welcome::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.session_id = r.u64();
  m.capabilities = r.u32();
  m.flags = r.u32();
  m.max_datagram_bytes = r.u32();
  m.max_chunk_bytes = r.u32();
  m.max_scene_bytes = r.u64();
  m.max_state_rate_hz = r.u32();
  m.tick_rate_hz = r.u32();
  m.max_state_contacts = r.u16();
  m.max_state_bodies = r.u16();
  m.max_update_entries = r.u16();
  r.u16();
  m.session_timeout_ns = r.u64();
  return {};
}

std::size_t size(const SceneBegin& m) {
  return SceneBegin::kFixedSize + m.name.size();
}
bool fits(const SceneBegin& m) {
  return m.name.size() <= kMaxSceneNameBytes;
}
void put(Writer& w, const SceneBegin& m) {
  w.u32(m.upload_id);
  w.u32(m.chunk_bytes);
  w.u64(m.total_bytes);
  w.bytes(m.sha256);
  w.u16(static_cast<std::uint16_t>(m.name.size()));
  w.u16(0);
  putText(w, m.name);
}
DecodeError get(Reader& r, SceneBegin& m, bool exact) {
  const std::size_t total = r.remaining();
  if (total < SceneBegin::kFixedSize)
    return checkLength(SceneBegin::kType, total, SceneBegin::kFixedSize, false);
  m.upload_id = r.u32();
  m.chunk_bytes = r.u32();
  m.total_bytes = r.u64();
  auto h = r.bytes(32);
  std::memcpy(m.sha256.data(), h.data(), 32);
  const std::size_t n = r.u16();
  r.u16();
  if (n > kMaxSceneNameBytes)
    return err(Errc::kBadValue, SceneBegin::kType, n, kMaxSceneNameBytes, "name_length");
  if (auto e = checkLength(SceneBegin::kType, total, SceneBegin::kFixedSize + n, exact);
      e.code != Errc::kOk)
    return e;
  m.name = getText(r, n);
  if (m.upload_id == 0)
    return err(Errc::kBadValue, SceneBegin::kType, 0, 1, "upload_id");
  if (m.total_bytes == 0)
    return err(Errc::kBadValue, SceneBegin::kType, 0, 1, "total_bytes");
  return {};
}

std::size_t size(const SceneChunk& m) {
  return SceneChunk::kFixedSize + m.data.size();
}
bool fits(const SceneChunk& m) {
  return !m.data.empty() && m.data.size() <= kMaxChunkBytes;
}
void put(Writer& w, const SceneChunk& m) {
  w.u32(m.upload_id);
  w.u32(static_cast<std::uint32_t>(m.data.size()));
  w.u64(m.offset);
  w.bytes(m.data);
}
DecodeError get(Reader& r, SceneChunk& m, bool exact) {
  const std::size_t total = r.remaining();
  if (total < SceneChunk::kFixedSize)
    return checkLength(SceneChunk::kType, total, SceneChunk::kFixedSize, false);
  m.upload_id = r.u32();
  const std::size_t n = r.u32();
  m.offset = r.u64();
  if (n == 0 || n > kMaxChunkBytes)
    return err(Errc::kBadValue, SceneChunk::kType, n, kMaxChunkBytes, "data_length");
  if (auto e = checkLength(SceneChunk::kType, total, SceneChunk::kFixedSize + n, exact);
      e.code != Errc::kOk)
    return e;
  m.data = r.bytes(n);
  if (m.offset > UINT64_MAX - n)
    return err(Errc::kBadValue, SceneChunk::kType, m.offset, UINT64_MAX - n, "offset");
  return {};
}

std::size_t size(const SceneChunkAck&) {
  return SceneChunkAck::kFixedSize;
}
bool fits(const SceneChunkAck&) {
  return true;
}
void put(Writer& w, const SceneChunkAck& m) {
  w.u32(m.upload_id);
  w.u32(m.length);
  w.u64(m.offset);
  w.u64(m.received_bytes);
  w.u64(m.total_bytes);
}
DecodeError get(Reader& r, SceneChunkAck& m, bool exact) {
  if (auto e = checkLength(SceneChunkAck::kType, r.remaining(), SceneChunkAck::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.upload_id = r.u32();
  m.length = r.u32();
  m.offset = r.u64();
  m.received_bytes = r.u64();
  m.total_bytes = r.u64();
  return {};
}

std::size_t size(const SceneCommit&) {
  return SceneCommit::kFixedSize;
}
bool fits(const SceneCommit&) {
  return true;
}
void put(Writer& w, const SceneCommit& m) {
  w.u32(m.upload_id);
  w.u32(0);
}
DecodeError get(Reader& r, SceneCommit& m, bool exact) {
  if (auto e = checkLength(SceneCommit::kType, r.remaining(), SceneCommit::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.upload_id = r.u32();
  r.u32();
  return {};
}

std::size_t size(const SceneStatus& m) {
  return SceneStatus::kFixedSize + 16 * m.missing.size() + m.text.size();
}
bool fits(const SceneStatus& m) {
  return m.missing.size() <= kMaxMissingRanges && m.text.size() <= kMaxTextBytes;
}
void put(Writer& w, const SceneStatus& m) {
  w.u32(m.upload_id);
  w.u16(static_cast<std::uint16_t>(m.status));
  w.u16(static_cast<std::uint16_t>(m.missing.size()));
  w.u64(m.received_bytes);
  w.u64(m.total_bytes);
  w.u16(static_cast<std::uint16_t>(m.text.size()));
  w.u16(0);
  w.u32(0);
  for (const auto& g : m.missing) {
    w.u64(g.offset);
    w.u64(g.length);
  }
  putText(w, m.text);
}
DecodeError get(Reader& r, SceneStatus& m, bool exact) {
  const std::size_t total = r.remaining();
  constexpr auto t = SceneStatus::kType;
  if (total < SceneStatus::kFixedSize)
    return checkLength(t, total, SceneStatus::kFixedSize, false);
  m.upload_id = r.u32();
  const std::uint16_t status = r.u16();
  const std::size_t ranges = r.u16();
  m.received_bytes = r.u64();
  m.total_bytes = r.u64();
  const std::size_t text = r.u16();
  r.u16();
  r.u32();
  if (status > static_cast<std::uint16_t>(SceneStatusCode::kUnknownUpload))
    return err(Errc::kBadValue, t, status, 4, "status");
  if (ranges > kMaxMissingRanges)
    return err(Errc::kBadValue, t, ranges, kMaxMissingRanges, "missing_count");
  if (text > kMaxTextBytes)
    return err(Errc::kBadValue, t, text, kMaxTextBytes, "text_length");
  if (auto e = checkLength(t, total, SceneStatus::kFixedSize + 16 * ranges + text, exact);
      e.code != Errc::kOk)
    return e;
  m.status = static_cast<SceneStatusCode>(status);
  m.missing.resize(ranges);
  for (auto& g : m.missing) {
    g.offset = r.u64();
    g.length = r.u64();
  }
  m.text = getText(r, text);
  return {};
}

void putBodyPose(Writer& w, const SceneUpdate::BodyPose& b) {
  w.u32(b.body_index);
  w.u32(0);
  putPose(w, b.X_WB);
}
SceneUpdate::BodyPose getBodyPose(Reader& r) {
  SceneUpdate::BodyPose b;
  b.body_index = r.u32();
  r.u32();
  b.X_WB = getPose(r);
  return b;
}
constexpr std::size_t kBodyPoseSize = 8 + kPoseSize;

std::size_t size(const SceneUpdate& m) {
  return SceneUpdate::kFixedSize + kBodyPoseSize * (m.poses.size() + m.added.size()) +
         4 * m.removed.size();
}
bool fits(const SceneUpdate& m) {
  return m.poses.size() <= kMaxUpdateEntries && m.added.size() <= kMaxUpdateEntries &&
         m.removed.size() <= kMaxUpdateEntries;
}
void put(Writer& w, const SceneUpdate& m) {
  w.u16(static_cast<std::uint16_t>(m.poses.size()));
  w.u16(static_cast<std::uint16_t>(m.added.size()));
  w.u16(static_cast<std::uint16_t>(m.removed.size()));
  w.u16(0);
  for (const auto& b : m.poses)
    putBodyPose(w, b);
  for (const auto& b : m.added)
    putBodyPose(w, b);
  for (auto i : m.removed)
    w.u32(i);
}
DecodeError get(Reader& r, SceneUpdate& m, bool exact) {
  const std::size_t total = r.remaining();
  constexpr auto t = SceneUpdate::kType;
  if (total < SceneUpdate::kFixedSize)
    return checkLength(t, total, SceneUpdate::kFixedSize, false);
  const std::size_t np = r.u16(), na = r.u16(), nr = r.u16();
  r.u16();
  if (np > kMaxUpdateEntries)
    return err(Errc::kBadValue, t, np, kMaxUpdateEntries, "pose_count");
  if (na > kMaxUpdateEntries)
    return err(Errc::kBadValue, t, na, kMaxUpdateEntries, "add_count");
  if (nr > kMaxUpdateEntries)
    return err(Errc::kBadValue, t, nr, kMaxUpdateEntries, "remove_count");
  if (auto e = checkLength(t, total, SceneUpdate::kFixedSize + kBodyPoseSize * (np + na) + 4 * nr,
                           exact);
      e.code != Errc::kOk)
    return e;
  m.poses.resize(np);
  for (auto& b : m.poses)
    b = getBodyPose(r);
  m.added.resize(na);
  for (auto& b : m.added)
    b = getBodyPose(r);
  m.removed.resize(nr);
  for (auto& i : m.removed)
    i = r.u32();
  if (r.nonFinite())
    return {};  // reported by the caller with its offset
  for (const auto& b : m.poses)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, t, b.body_index, 0, "poses[].q (norm)");
  for (const auto& b : m.added)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, t, b.body_index, 0, "added[].q (norm)");
  return {};
}

std::size_t size(const PoseCommand&) {
  return PoseCommand::kFixedSize;
}
bool fits(const PoseCommand&) {
  return true;
}
void put(Writer& w, const PoseCommand& m) {
  putPose(w, m.X_WT);
  putVec(w, m.v_W);
  putVec(w, m.w_W);
  w.u32(m.buttons);
  w.u32(0);
}
DecodeError get(Reader& r, PoseCommand& m, bool exact) {
  if (auto e = checkLength(PoseCommand::kType, r.remaining(), PoseCommand::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.X_WT = getPose(r);
  m.v_W = getVec(r);
  m.w_W = getVec(r);
  m.buttons = r.u32();
  r.u32();
  if (!r.nonFinite() && !unitQuat(m.X_WT))
    return err(Errc::kBadValue, PoseCommand::kType, 0, 0, "target q (norm)");
  return {};
}

std::size_t size(const Subscribe&) {
  return Subscribe::kFixedSize;
}
bool fits(const Subscribe& m) {
  return m.rate_hz <= kMaxStateRateHz;
}
void put(Writer& w, const Subscribe& m) {
  w.u32(m.rate_hz);
  w.u32(m.flags);
}
DecodeError get(Reader& r, Subscribe& m, bool exact) {
  if (auto e = checkLength(Subscribe::kType, r.remaining(), Subscribe::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.rate_hz = r.u32();
  m.flags = r.u32();
  if (m.rate_hz > kMaxStateRateHz)
    return err(Errc::kBadValue, Subscribe::kType, m.rate_hz, kMaxStateRateHz, "rate_hz");
  return {};
}

constexpr std::size_t kContactSize = 56;
std::size_t size(const State& m) {
  return State::kFixedSize + kContactSize * m.contacts.size() + kBodyPoseSize * m.bodies.size() +
         State::kMinor1Size;
}
bool fits(const State& m) {
  return m.contacts.size() <= kMaxStateContacts && m.bodies.size() <= kMaxStateBodies;
}
void put(Writer& w, const State& m) {
  w.u64(m.tick);
  w.u64(m.sim_time_ns);
  putPose(w, m.X_WD);
  putPose(w, m.X_WP);
  putVec(w, m.force_n);
  putVec(w, m.torque_nm);
  w.f64(m.force_scale);
  w.u64(m.last_command_sequence);
  w.u64(m.tick_misses);
  w.u32(m.tick_p50_ns);
  w.u32(m.tick_p99_ns);
  w.u32(m.tick_max_ns);
  w.u32(m.fault_bits);
  w.u32(m.state_flags);
  w.u32(m.contact_count);
  w.u16(static_cast<std::uint16_t>(m.contacts.size()));
  w.u16(static_cast<std::uint16_t>(m.bodies.size()));
  w.u32(0);
  for (const auto& c : m.contacts) {
    putVec(w, c.p_W);
    putVec(w, c.n_W);
    w.f64(c.depth_m);
  }
  for (const auto& b : m.bodies)
    putBodyPose(w, b);
  // minor 1
  w.u32(m.pairs_tested);
  w.u32(m.pairs_skipped);
  w.f64(m.max_penetration_m);
  w.u32(m.tick_ns);
  w.u32(0);
}
// State is the one message whose length depends on the sender's minor: 1.0 has no tail, 1.1
// appends kMinor1Size bytes; the length is exact up to our minor and "at least" above it.
DecodeError get(Reader& r, State& m, std::uint8_t minor) {
  const bool exact = minor <= kVersionMinor;
  const std::size_t total = r.remaining();
  constexpr auto t = State::kType;
  if (total < State::kFixedSize)
    return checkLength(t, total, State::kFixedSize, false);
  m.tick = r.u64();
  m.sim_time_ns = r.u64();
  m.X_WD = getPose(r);
  m.X_WP = getPose(r);
  m.force_n = getVec(r);
  m.torque_nm = getVec(r);
  m.force_scale = r.f64();
  m.last_command_sequence = r.u64();
  m.tick_misses = r.u64();
  m.tick_p50_ns = r.u32();
  m.tick_p99_ns = r.u32();
  m.tick_max_ns = r.u32();
  m.fault_bits = r.u32();
  m.state_flags = r.u32();
  m.contact_count = r.u32();
  const std::size_t nc = r.u16(), nb = r.u16();
  r.u32();
  if (nc > kMaxStateContacts)
    return err(Errc::kBadValue, t, nc, kMaxStateContacts, "listed_contacts");
  if (nb > kMaxStateBodies)
    return err(Errc::kBadValue, t, nb, kMaxStateBodies, "listed_bodies");
  const std::size_t tail = minor >= 1 ? State::kMinor1Size : 0;
  if (auto e = checkLength(
          t, total, State::kFixedSize + kContactSize * nc + kBodyPoseSize * nb + tail, exact);
      e.code != Errc::kOk)
    return e;
  m.contacts.resize(nc);
  for (auto& c : m.contacts) {
    c.p_W = getVec(r);
    c.n_W = getVec(r);
    c.depth_m = r.f64();
  }
  m.bodies.resize(nb);
  for (auto& b : m.bodies)
    b = getBodyPose(r);
  if (minor >= 1) {
    m.pairs_tested = r.u32();
    m.pairs_skipped = r.u32();
    m.max_penetration_m = r.f64();
    m.tick_ns = r.u32();
    r.u32();
  }  // else: a 1.0 sender, the minor-1 fields stay 0
  if (r.nonFinite())
    return {};  // reported by the caller with its offset
  if (!(m.max_penetration_m >= 0.0))
    return err(Errc::kBadValue, t, 0, 0, "max_penetration_m (>= 0)");
  if (!(m.force_scale >= 0.0 && m.force_scale <= 1.0))
    return err(Errc::kBadValue, t, 0, 1, "force_scale (0..1)");
  if (!unitQuat(m.X_WD))
    return err(Errc::kBadValue, t, 0, 0, "device q (norm)");
  if (!unitQuat(m.X_WP))
    return err(Errc::kBadValue, t, 0, 0, "proxy q (norm)");
  for (const auto& b : m.bodies)
    if (!unitQuat(b.X_WB))
      return err(Errc::kBadValue, t, b.body_index, 0, "bodies[].q (norm)");
  return {};
}

template <class Empty>
std::size_t sizeEmpty(const Empty&) {
  return 0;
}
std::size_t size(const Arm& m) {
  return sizeEmpty(m);
}
std::size_t size(const Disarm& m) {
  return sizeEmpty(m);
}
std::size_t size(const StatusRequest& m) {
  return sizeEmpty(m);
}
std::size_t size(const Bye& m) {
  return sizeEmpty(m);
}
bool fits(const Arm&) {
  return true;
}
bool fits(const Disarm&) {
  return true;
}
bool fits(const StatusRequest&) {
  return true;
}
bool fits(const Bye&) {
  return true;
}
void put(Writer&, const Arm&) {}
void put(Writer&, const Disarm&) {}
void put(Writer&, const StatusRequest&) {}
void put(Writer&, const Bye&) {}
template <class Empty>
DecodeError getEmpty(Reader& r, bool exact) {
  return checkLength(Empty::kType, r.remaining(), 0, exact);
}
DecodeError get(Reader& r, Arm&, bool exact) {
  return getEmpty<Arm>(r, exact);
}
DecodeError get(Reader& r, Disarm&, bool exact) {
  return getEmpty<Disarm>(r, exact);
}
DecodeError get(Reader& r, StatusRequest&, bool exact) {
  return getEmpty<StatusRequest>(r, exact);
}
DecodeError get(Reader& r, Bye&, bool exact) {
  return getEmpty<Bye>(r, exact);
}

std::size_t size(const Heartbeat&) {
  return Heartbeat::kFixedSize;
}
bool fits(const Heartbeat&) {
  return true;
}
void put(Writer& w, const Heartbeat& m) {
  w.u64(m.echo_timestamp_ns);
}
DecodeError get(Reader& r, Heartbeat& m, bool exact) {
  if (auto e = checkLength(Heartbeat::kType, r.remaining(), Heartbeat::kFixedSize, exact);
      e.code != Errc::kOk)
    return e;
  m.echo_timestamp_ns = r.u64();
  return {};
}

std::size_t size(const ErrorMsg& m) {
  return ErrorMsg::kFixedSize + m.text.size();
}
bool fits(const ErrorMsg& m) {
  return m.text.size() <= kMaxTextBytes;
}
void put(Writer& w, const ErrorMsg& m) {
  w.u64(m.ref_sequence);
  w.u16(m.ref_type);
  w.u16(static_cast<std::uint16_t>(m.code));
  w.u16(static_cast<std::uint16_t>(m.text.size()));
  w.u16(0);
  putText(w, m.text);
}
DecodeError get(Reader& r, ErrorMsg& m, bool exact) {
  const std::size_t total = r.remaining();
  constexpr auto t = ErrorMsg::kType;
  if (total < ErrorMsg::kFixedSize)
    return checkLength(t, total, ErrorMsg::kFixedSize, false);
  m.ref_sequence = r.u64();
  m.ref_type = r.u16();
  const std::uint16_t code = r.u16();
  const std::size_t n = r.u16();
  r.u16();
  if (n > kMaxTextBytes)
    return err(Errc::kBadValue, t, n, kMaxTextBytes, "text_length");
  if (auto e = checkLength(t, total, ErrorMsg::kFixedSize + n, exact); e.code != Errc::kOk)
    return e;
  // a newer peer's unknown code is kept as is: errcName() says "unknown"
  m.code = static_cast<Errc>(code);
  m.text = getText(r, n);
  return {};
}

std::size_t size(const StatusReply& m) {
  return StatusReply::kFixedSize + 8 * m.refused.size() + m.device.size() + m.scene.size() +
         m.plan.size() + StatusReply::kMinor1FixedSize + m.shm_name.size();
}
bool fits(const StatusReply& m) {
  return m.refused.size() <= kMaxRefusalCounters && m.device.size() <= kMaxDeviceBytes &&
         m.scene.size() <= kMaxSceneNameBytes && m.plan.size() <= kMaxPlanBytes &&
         m.shm_name.size() <= kMaxShmNameBytes;
}
void put(Writer& w, const StatusReply& m) {
  w.u64(m.uptime_ns);
  w.u64(m.ticks);
  w.u64(m.tick_misses);
  w.f64(m.tick_rate_hz);
  w.f64(m.measured_tick_hz);
  w.u32(m.tick_p50_ns);
  w.u32(m.tick_p99_ns);
  w.u32(m.tick_max_ns);
  w.u32(m.fault_bits);
  w.u32(m.state_flags);
  w.u32(m.sessions);
  w.u32(m.subscribers);
  w.u32(m.state_rate_hz);
  w.u64(m.packets_received);
  w.u64(m.packets_sent);
  w.u64(m.commands_accepted);
  w.u64(m.commands_dropped);
  w.u16(static_cast<std::uint16_t>(m.refused.size()));
  w.u16(static_cast<std::uint16_t>(m.device.size()));
  w.u16(static_cast<std::uint16_t>(m.scene.size()));
  w.u16(static_cast<std::uint16_t>(m.plan.size()));
  for (auto c : m.refused)
    w.u64(c);
  putText(w, m.device);
  putText(w, m.scene);
  putText(w, m.plan);
  // minor 1
  w.u64(m.shm_commands);
  w.u64(m.shm_commands_refused);
  w.u64(m.edit_batches_applied);
  w.u64(m.edit_batches_dropped);
  w.u64(m.edits_applied);
  w.u64(m.edits_refused);
  w.u32(m.shm_flags);
  w.u16(static_cast<std::uint16_t>(m.shm_name.size()));
  w.u16(0);
  putText(w, m.shm_name);
}
// Like State, StatusReply gained a tail in minor 1 (after its texts): one exact length per
// minor up to ours, "at least" above it.
DecodeError get(Reader& r, StatusReply& m, std::uint8_t minor) {
  const bool exact = minor <= kVersionMinor;
  const std::size_t total = r.remaining();
  constexpr auto t = StatusReply::kType;
  if (total < StatusReply::kFixedSize)
    return checkLength(t, total, StatusReply::kFixedSize, false);
  m.uptime_ns = r.u64();
  m.ticks = r.u64();
  m.tick_misses = r.u64();
  m.tick_rate_hz = r.f64();
  m.measured_tick_hz = r.f64();
  m.tick_p50_ns = r.u32();
  m.tick_p99_ns = r.u32();
  m.tick_max_ns = r.u32();
  m.fault_bits = r.u32();
  m.state_flags = r.u32();
  m.sessions = r.u32();
  m.subscribers = r.u32();
  m.state_rate_hz = r.u32();
  m.packets_received = r.u64();
  m.packets_sent = r.u64();
  m.commands_accepted = r.u64();
  m.commands_dropped = r.u64();
  const std::size_t nc = r.u16(), nd = r.u16(), ns = r.u16(), np = r.u16();
  if (nc > kMaxRefusalCounters)
    return err(Errc::kBadValue, t, nc, kMaxRefusalCounters, "refused_count");
  if (nd > kMaxDeviceBytes)
    return err(Errc::kBadValue, t, nd, kMaxDeviceBytes, "device_length");
  if (ns > kMaxSceneNameBytes)
    return err(Errc::kBadValue, t, ns, kMaxSceneNameBytes, "scene_length");
  if (np > kMaxPlanBytes)
    return err(Errc::kBadValue, t, np, kMaxPlanBytes, "plan_length");
  const std::size_t head = StatusReply::kFixedSize + 8 * nc + nd + ns + np;
  if (minor == 0) {
    if (auto e = checkLength(t, total, head, exact); e.code != Errc::kOk)
      return e;
  } else if (total < head + StatusReply::kMinor1FixedSize) {
    return checkLength(t, total, head + StatusReply::kMinor1FixedSize, false);
  }
  m.refused.resize(nc);
  for (auto& c : m.refused)
    c = r.u64();
  m.device = getText(r, nd);
  m.scene = getText(r, ns);
  m.plan = getText(r, np);
  if (minor >= 1) {
    m.shm_commands = r.u64();
    m.shm_commands_refused = r.u64();
    m.edit_batches_applied = r.u64();
    m.edit_batches_dropped = r.u64();
    m.edits_applied = r.u64();
    m.edits_refused = r.u64();
    m.shm_flags = r.u32();
    const std::size_t nn = r.u16();
    r.u16();
    if (nn > kMaxShmNameBytes)
      return err(Errc::kBadValue, t, nn, kMaxShmNameBytes, "shm_name_length");
    if (auto e = checkLength(t, total, head + StatusReply::kMinor1FixedSize + nn, exact);
        e.code != Errc::kOk)
      return e;
    m.shm_name = getText(r, nn);
  }  // else: a 1.0 sender, the minor-1 fields stay 0 and ""
  return {};
}

std::size_t size(const Ack&) {
  return Ack::kFixedSize;
}
bool fits(const Ack&) {
  return true;
}
void put(Writer& w, const Ack& m) {
  w.u64(m.ref_sequence);
  w.u16(m.ref_type);
  w.u16(0);
  w.u32(0);
}
DecodeError get(Reader& r, Ack& m, bool exact) {
  if (auto e = checkLength(Ack::kType, r.remaining(), Ack::kFixedSize, exact); e.code != Errc::kOk)
    return e;
  m.ref_sequence = r.u64();
  m.ref_type = r.u16();
  r.u16();
  r.u32();
  return {};
}

// Layout checks: fixed sizes as the README documents them.
static_assert(kHeaderSize == 4 + 1 + 1 + 2 + 2 + 2 + 4 + 8 + 8 + 8);
static_assert(kPoseSize == 7 * 8);
static_assert(Welcome::kFixedSize == 8 + 4 * 4 + 8 + 4 * 2 + 2 * 4 + 8);
static_assert(SceneBegin::kFixedSize == 4 + 4 + 8 + 32 + 2 + 2);
static_assert(SceneChunk::kFixedSize == 4 + 4 + 8);
static_assert(SceneChunkAck::kFixedSize == 4 + 4 + 8 * 3);
static_assert(SceneStatus::kFixedSize == 4 + 2 + 2 + 8 + 8 + 2 + 2 + 4);
static_assert(PoseCommand::kFixedSize == kPoseSize + 3 * 8 + 3 * 8 + 4 + 4);
static_assert(State::kFixedSize == 8 + 8 + 2 * kPoseSize + 6 * 8 + 8 + 8 + 8 + 6 * 4 + 2 + 2 + 4);
static_assert(State::kMinor1Size == 4 + 4 + 8 + 4 + 4);
static_assert(StatusReply::kFixedSize == 3 * 8 + 2 * 8 + 8 * 4 + 4 * 8 + 4 * 2);
static_assert(StatusReply::kMinor1FixedSize == 6 * 8 + 4 + 2 + 2);
static_assert(ErrorMsg::kFixedSize == 8 + 2 + 2 + 2 + 2);
static_assert(Ack::kFixedSize == 16);
static_assert(kErrcCount <= kMaxRefusalCounters);
// the largest messages fit the largest datagram
static_assert(kHeaderSize + State::kFixedSize + kMaxStateContacts * kContactSize +
                  kMaxStateBodies * kBodyPoseSize + State::kMinor1Size + kMacSize <=
              8192);
static_assert(kHeaderSize + SceneChunk::kFixedSize + kMaxChunkBytes + kMacSize <=
              kMaxDatagramLimit);

// Every message but State has one layout per major: exact length up to our minor.
template <class M>
DecodeError getAt(Reader& r, M& m, std::uint8_t minor) {
  return get(r, m, minor <= kVersionMinor);
}
template <>
DecodeError getAt(Reader& r, State& m, std::uint8_t minor) {
  return get(r, m, minor);
}
DecodeError getAt(Reader& r, StatusReply& m, std::uint8_t minor) {
  return get(r, m, minor);
}

template <class M>
DecodeError decodeAs(std::span<const std::uint8_t> payload, std::uint8_t minor, Message& out) {
  M m{};
  Reader r(payload);
  DecodeError e = getAt(r, m, minor);
  if (e.code != Errc::kOk)
    return e;
  if (r.nonFinite())
    return err(Errc::kNotFinite, M::kType, r.nonFiniteAt(), 0, "a float field (NaN or Inf)");
  out = std::move(m);
  return {};
}

}  // namespace

MsgType typeOf(const Message& m) {
  return std::visit([](const auto& x) { return std::decay_t<decltype(x)>::kType; }, m);
}

std::size_t payloadSize(const Message& m) {
  return std::visit([](const auto& x) { return size(x); }, m);
}

std::size_t encode(Header h, const Message& m, std::span<std::uint8_t> out, Errc* error) {
  auto fail = [&](Errc c) {
    if (error)
      *error = c;
    return std::size_t{0};
  };
  const bool ok = std::visit([](const auto& x) { return fits(x); }, m);
  if (!ok)
    return fail(Errc::kBadValue);
  const std::size_t n = payloadSize(m);
  if (out.size() < kHeaderSize + n)
    return fail(Errc::kBufferTooSmall);
  h.type = static_cast<std::uint16_t>(typeOf(m));
  h.payload_length = static_cast<std::uint32_t>(n);
  encodeHeader(h, out);
  Writer w(out.subspan(kHeaderSize, n));
  std::visit([&](const auto& x) { put(w, x); }, m);
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
