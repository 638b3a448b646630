#pragma once
// One filled-in example of every message (values chosen so that no field is at its default),
// for round-trip tests and the fuzzers' seed corpus; random upload bytes.
#include <random>
#include <tuple>
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

/// n bytes drawn from a seeded RNG (scene uploads of any size).
inline std::vector<std::uint8_t> randomBytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v)
    b = static_cast<std::uint8_t>(rng());
  return v;
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

inline Welcome sampleWelcome() {
  return {.session_id = 0x0123456789abcdefull,
          .capabilities = kCapUdp | kCapShm,
          .flags = kWelcomeKeyRequired | kWelcomeAuthenticated,
          .max_datagram_bytes = 16384,
          .max_chunk_bytes = 8192,
          .max_scene_bytes = 64ull << 20,
          .max_state_rate_hz = 1000,
          .tick_rate_hz = 1000,
          .max_state_contacts = 32,
          .max_state_bodies = 64,
          .max_update_entries = 64,
          .session_timeout_ns = 10'000'000'000ull};
}

inline SceneBegin sampleBegin() {
  std::array<std::uint8_t, 32> hash{};
  for (std::size_t i = 0; i < 32; ++i)
    hash[i] = static_cast<std::uint8_t>(255 - i);
  return {.upload_id = 7,
          .chunk_bytes = 1200,
          .total_bytes = 5'000'000,
          .sha256 = hash,
          .name = "gears.glb"};
}

/// A State with every field set: 3 contacts, 4 bodies, the minor-1 fields.
inline State sampleState() {
  return {
      .tick = 123456789,
      .sim_time_ns = 123456789000ull,
      .X_WD = samplePose(5),
      .X_WP = samplePose(6),
      .force_n = {1.0, -2.0, 3.5},
      .torque_nm = {0.01, 0.02, -0.03},
      .force_scale = 0.75,
      .last_command_sequence = 99,
      .tick_misses = 2,
      .tick_p50_ns = 21000,
      .tick_p99_ns = 43000,
      .tick_max_ns = 99000,
      .fault_bits = kFaultForceClamped,
      .state_flags = kStateArmed | kStateStreaming,
      .contact_count = 40,
      .contacts = {{{0.0, 0.2, 0.3}, {0.0, 1.0, 0.0}, 0.0},
                   {{0.1, 0.2, 0.3}, {0.0, 1.0, 0.0}, 1e-4},
                   {{0.2, 0.2, 0.3}, {0.0, 1.0, 0.0}, 2e-4}},
      .bodies = {{0, samplePose(0)}, {2, samplePose(1)}, {4, samplePose(2)}, {6, samplePose(3)}},
      .pairs_tested = 17,  // minor 1
      .pairs_skipped = 3,
      .max_penetration_m = 2.5e-4,
      .tick_ns = 18500};
}

/// A StatusReply with every field set, the minor-1 tail included.
inline StatusReply sampleStatus() {
  StatusReply r;
  std::tie(r.uptime_ns, r.ticks, r.tick_misses) = std::tuple(5'000'000'000ull, 5000u, 1u);
  std::tie(r.tick_rate_hz, r.measured_tick_hz) = std::tuple(1000.0, 999.5);
  std::tie(r.tick_p50_ns, r.tick_p99_ns, r.tick_max_ns) = std::tuple(20000u, 40000u, 80000u);
  std::tie(r.fault_bits, r.state_flags) = std::tuple(kFaultStreamLost, kStateArmed);
  std::tie(r.sessions, r.subscribers, r.state_rate_hz) = std::tuple(3u, 2u, 1500u);
  std::tie(r.packets_received, r.packets_sent) = std::tuple(100000u, 90000u);
  std::tie(r.commands_accepted, r.commands_dropped) = std::tuple(5000u, 12u);
  r.refused.assign(kErrcCount, 0);
  r.refused[static_cast<std::size_t>(Errc::kBadMac)] = 5;
  r.device = "sim";
  r.scene = "peg_in_hole.glb";
  r.plan = "contact forces: on\ndynamics: off\ngravity: off";
  // minor 1
  std::tie(r.shm_commands, r.shm_commands_refused) = std::tuple(77u, 2u);
  std::tie(r.edit_batches_applied, r.edit_batches_dropped) = std::tuple(9u, 1u);
  std::tie(r.edits_applied, r.edits_refused) = std::tuple(30u, 4u);
  r.shm_flags = kShmServing | kShmClientAttached;
  r.shm_name = "/hapticd";
  return r;
}

/// One sample of every message type, in MsgType order.
inline std::vector<Message> sampleMessages() {
  SceneChunk chunk{.upload_id = 7, .offset = 1200 * 5, .data = sampleChunkBytes()};
  SceneStatus status{.upload_id = 7,
                     .status = SceneStatusCode::kIncomplete,
                     .received_bytes = 4'000'000,
                     .total_bytes = 5'000'000,
                     .missing = {{0, 1200}, {48000, 2400}, {4'998'800, 1200}},
                     .text = "3 ranges missing"};
  SceneUpdate update{.poses = {{3, samplePose(1)}, {9, samplePose(2)}},
                     .added = {{12, samplePose(3)}},
                     .removed = {4, 5, 6}};
  PoseCommand pose{
      .X_WT = samplePose(4), .v_W = {0.1, -0.2, 0.3}, .w_W = {1.5, 0.0, -3.25}, .buttons = 0b101};
  return {Hello{kCapUdp | kCapMac, "viewer-1 ü"},
          sampleWelcome(),
          sampleBegin(),
          chunk,
          SceneChunkAck{7, 1200, 6000, 7200, 5'000'000},
          SceneCommit{7},
          status,
          update,
          pose,
          Subscribe{1000, kSubscribeBodies | kSubscribeContacts},
          sampleState(),
          Arm{},
          Disarm{},
          Heartbeat{987654321},
          ErrorMsg{42, static_cast<std::uint16_t>(MsgType::kPoseCommand), Errc::kNotFinite,
                   "pose_command: NaN or Inf"},
          StatusRequest{},
          sampleStatus(),
          Ack{77, static_cast<std::uint16_t>(MsgType::kArm)},
          Bye{}};
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
