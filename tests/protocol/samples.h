#pragma once
// One filled-in example of every message (values chosen so that no field is at its default),
// for round-trip tests and the fuzzers' seed corpus.
#include <vector>

#include "protocol/messages.h"

namespace hapticd::proto::testing {

inline WirePose samplePose(double k) {
  WirePose x;
  x.p = {0.125 * k, -2.5e3 * k, 1e-9 * k};
  // a unit quaternion (0.5, 0.5, 0.5, 0.5)
  x.q = {0.5, -0.5, 0.5, 0.5};
  return x;
}

/// Backing bytes of the sample SceneChunk (static storage: the chunk views it).
inline const std::vector<std::uint8_t>& sampleChunkBytes() {
  static const std::vector<std::uint8_t> b = [] {
    std::vector<std::uint8_t> v(1200);
    for (std::size_t i = 0; i < v.size(); ++i)
      v[i] = static_cast<std::uint8_t>(i * 7 + 3);
    return v;
  }();
  return b;
}

inline std::vector<Message> sampleMessages() {
  std::vector<Message> out;
  out.push_back(Hello{kCapUdp | kCapMac, "viewer-1 ü"});
  {
    Welcome w;
    w.session_id = 0x0123456789abcdefull;
    w.capabilities = kCapUdp | kCapShm;
    w.flags = kWelcomeKeyRequired | kWelcomeAuthenticated;
    w.max_datagram_bytes = 16384;
    w.max_chunk_bytes = 8192;
    w.max_scene_bytes = 64ull << 20;
    w.max_state_rate_hz = 1000;
    w.tick_rate_hz = 1000;
    w.max_state_contacts = 32;
    w.max_state_bodies = 64;
    w.max_update_entries = 64;
    w.session_timeout_ns = 10'000'000'000ull;
    out.push_back(w);
  }
  {
    SceneBegin b;
    b.upload_id = 7;
    b.chunk_bytes = 1200;
    b.total_bytes = 5'000'000;
    for (std::size_t i = 0; i < 32; ++i)
      b.sha256[i] = static_cast<std::uint8_t>(255 - i);
    b.name = "gears.glb";
    out.push_back(b);
  }
  {
    SceneChunk c;
    c.upload_id = 7;
    c.offset = 1200 * 5;
    c.data = sampleChunkBytes();
    out.push_back(c);
  }
  out.push_back(SceneChunkAck{7, 1200, 6000, 7200, 5'000'000});
  out.push_back(SceneCommit{7});
  {
    SceneStatus s;
    s.upload_id = 7;
    s.status = SceneStatusCode::kIncomplete;
    s.received_bytes = 4'000'000;
    s.total_bytes = 5'000'000;
    s.missing = {{0, 1200}, {48000, 2400}, {4'998'800, 1200}};
    s.text = "3 ranges missing";
    out.push_back(s);
  }
  {
    SceneUpdate u;
    u.poses = {{3, samplePose(1)}, {9, samplePose(2)}};
    u.added = {{12, samplePose(3)}};
    u.removed = {4, 5, 6};
    out.push_back(u);
  }
  {
    PoseCommand p;
    p.X_WT = samplePose(4);
    p.v_W = {0.1, -0.2, 0.3};
    p.w_W = {1.5, 0.0, -3.25};
    p.buttons = 0b101;
    out.push_back(p);
  }
  out.push_back(Subscribe{1000, kSubscribeBodies | kSubscribeContacts});
  {
    State s;
    s.tick = 123456789;
    s.sim_time_ns = 123456789000ull;
    s.X_WD = samplePose(5);
    s.X_WP = samplePose(6);
    s.force_n = {1.0, -2.0, 3.5};
    s.torque_nm = {0.01, 0.02, -0.03};
    s.force_scale = 0.75;
    s.last_command_sequence = 99;
    s.tick_misses = 2;
    s.tick_p50_ns = 21000;
    s.tick_p99_ns = 43000;
    s.tick_max_ns = 99000;
    s.fault_bits = kFaultForceClamped;
    s.state_flags = kStateArmed | kStateStreaming;
    s.contact_count = 40;
    for (int i = 0; i < 3; ++i)
      s.contacts.push_back({{0.1 * i, 0.2, 0.3}, {0.0, 1.0, 0.0}, 1e-4 * i});
    for (std::uint32_t i = 0; i < 4; ++i)
      s.bodies.push_back({i * 2, samplePose(i)});
    s.pairs_tested = 17;  // minor 1
    s.pairs_skipped = 3;
    s.max_penetration_m = 2.5e-4;
    s.tick_ns = 18500;
    out.push_back(s);
  }
  out.push_back(Arm{});
  out.push_back(Disarm{});
  out.push_back(Heartbeat{987654321});
  out.push_back(ErrorMsg{42, static_cast<std::uint16_t>(MsgType::kPoseCommand), Errc::kNotFinite,
                         "pose_command: NaN or Inf"});
  out.push_back(StatusRequest{});
  {
    StatusReply r;
    r.uptime_ns = 5'000'000'000ull;
    r.ticks = 5000;
    r.tick_misses = 1;
    r.tick_rate_hz = 1000.0;
    r.measured_tick_hz = 999.5;
    r.tick_p50_ns = 20000;
    r.tick_p99_ns = 40000;
    r.tick_max_ns = 80000;
    r.fault_bits = kFaultStreamLost;
    r.state_flags = kStateArmed;
    r.sessions = 3;
    r.subscribers = 2;
    r.state_rate_hz = 1500;
    r.packets_received = 100000;
    r.packets_sent = 90000;
    r.commands_accepted = 5000;
    r.commands_dropped = 12;
    r.refused.assign(kErrcCount, 0);
    r.refused[static_cast<std::size_t>(Errc::kBadMac)] = 5;
    r.device = "sim";
    r.scene = "peg_in_hole.glb";
    r.plan = "contact forces: on\ndynamics: off\ngravity: off";
    r.shm_commands = 77;  // minor 1
    r.shm_commands_refused = 2;
    r.edit_batches_applied = 9;
    r.edit_batches_dropped = 1;
    r.edits_applied = 30;
    r.edits_refused = 4;
    r.shm_flags = kShmServing | kShmClientAttached;
    r.shm_name = "/hapticd";
    out.push_back(r);
  }
  out.push_back(Ack{77, static_cast<std::uint16_t>(MsgType::kArm)});
  out.push_back(Bye{});
  return out;
}

/// Equality of two messages (SceneChunk compares its bytes, not the view).
inline bool sameMessage(const Message& a, const Message& b) {
  if (a.index() != b.index())
    return false;
  if (const auto* ca = std::get_if<SceneChunk>(&a)) {
    const auto& cb = std::get<SceneChunk>(b);
    return ca->upload_id == cb.upload_id && ca->offset == cb.offset &&
           std::equal(ca->data.begin(), ca->data.end(), cb.data.begin(), cb.data.end());
  }
  return std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, SceneChunk>) {
          return false;
        } else {
          return x == std::get<T>(b);
        }
      },
      a);
}

}  // namespace hapticd::proto::testing
