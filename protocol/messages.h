#pragma once
/// \file
/// Every message of the hapticd protocol as a plain struct, and the codec: encode writes the
/// header and payload byte by byte, decode checks the header, the payload length per type (exact
/// for fixed messages, bounded for variable ones), finiteness of every float and the range of
/// every count. Byte layouts: protocol/README.md. Units: metres, seconds, newtons, N·m, radians;
/// poses in scene coordinates, quaternions in glTF order (x, y, z, w).
/// Any thread; decoding and encoding allocate only for the vectors and strings of a message.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "protocol/wire.h"

namespace hapticd::proto {

/// A vector on the wire: x, y, z (unit and frame named by each field), plain doubles in the
/// codec's order; not geom::Vec3, the geometry type the daemon converts it to where it enters.
using WireVec3 = std::array<double, 3>;

/// A pose on the wire (56 bytes): translation p (metres, scene frame), unit quaternion q
/// (x, y, z, w). Decoders refuse a quaternion whose norm differs from 1 by more than
/// kQuatNormTolerance (Errc::kBadValue).
struct WirePose {
  WireVec3 p{0.0, 0.0, 0.0};
  std::array<double, 4> q{0.0, 0.0, 0.0, 1.0};
  bool operator==(const WirePose&) const = default;
};
inline constexpr std::size_t kPoseSize = 56;
inline constexpr double kQuatNormTolerance = 1e-3;

// Bounds of the variable parts (wire limits; a server may configure smaller ones).
inline constexpr std::size_t kMaxNameBytes = 64;        ///< Hello client name
inline constexpr std::size_t kMaxSceneNameBytes = 128;  ///< SceneBegin name
inline constexpr std::size_t kMaxTextBytes = 1024;      ///< Error and SceneStatus text
inline constexpr std::size_t kMaxMissingRanges = 64;    ///< SceneStatus missing ranges
inline constexpr std::size_t kMaxChunkBytes = 60000;    ///< SceneChunk data
inline constexpr std::size_t kMaxUpdateEntries = 64;    ///< SceneUpdate poses, adds, removes each
inline constexpr std::size_t kMaxStateContacts = 32;    ///< State contacts listed
inline constexpr std::size_t kMaxStateBodies = 64;      ///< State body poses listed
inline constexpr std::uint32_t kMaxStateRateHz = 1000;  ///< Subscribe rate
inline constexpr std::size_t kMaxRefusalCounters = 64;  ///< StatusReply counters
inline constexpr std::size_t kMaxDeviceBytes = 128;     ///< StatusReply device text
inline constexpr std::size_t kMaxPlanBytes = 4096;      ///< StatusReply plan text
inline constexpr std::size_t kMaxShmNameBytes = 255;    ///< StatusReply shm segment name (NAME_MAX)

/// Capability bits (Hello::capabilities, Welcome::capabilities).
inline constexpr std::uint32_t kCapUdp = 1u << 0;  ///< the UDP protocol (always set)
inline constexpr std::uint32_t kCapShm = 1u << 1;  ///< the shared-memory segment (same host)
inline constexpr std::uint32_t kCapMac = 1u << 2;  ///< tagged datagrams (a pre-shared key)

/// Client → server, first message, session_id 0. Fixed 8 bytes + name.
struct Hello {
  static constexpr MsgType kType = MsgType::kHello;
  static constexpr std::size_t kFixedSize = 8;
  std::uint32_t capabilities = kCapUdp;
  std::string client_name;  ///< UTF-8, ≤ kMaxNameBytes, for the status listing
  bool operator==(const Hello&) const = default;
};

/// Welcome::flags bits.
inline constexpr std::uint32_t kWelcomeKeyRequired = 1u << 0;    ///< the server has a key set
inline constexpr std::uint32_t kWelcomeAuthenticated = 1u << 1;  ///< this session's hello verified

/// Server → client, answer to Hello. Fixed 56 bytes.
struct Welcome {
  static constexpr MsgType kType = MsgType::kWelcome;
  static constexpr std::size_t kFixedSize = 56;
  std::uint64_t session_id = 0;  ///< put this in every later header
  std::uint32_t capabilities = kCapUdp;
  std::uint32_t flags = 0;               ///< kWelcome* bits
  std::uint32_t max_datagram_bytes = 0;  ///< the server refuses larger datagrams
  std::uint32_t max_chunk_bytes = 0;     ///< largest SceneChunk data accepted
  std::uint64_t max_scene_bytes = 0;     ///< largest SceneBegin::total_bytes accepted
  std::uint32_t max_state_rate_hz = 0;
  std::uint32_t tick_rate_hz = 0;  ///< the servo rate
  std::uint16_t max_state_contacts = 0;
  std::uint16_t max_state_bodies = 0;
  std::uint16_t max_update_entries = 0;
  std::uint64_t session_timeout_ns = 0;  ///< a session silent this long is dropped
  bool operator==(const Welcome&) const = default;
};

/// Client → server: starts (or restarts) upload `upload_id` of a scene. Fixed 52 + name.
struct SceneBegin {
  static constexpr MsgType kType = MsgType::kSceneBegin;
  static constexpr std::size_t kFixedSize = 52;
  std::uint32_t upload_id = 0;            ///< chosen by the client, nonzero
  std::uint32_t chunk_bytes = 0;          ///< the client's usual chunk size (information only)
  std::uint64_t total_bytes = 0;          ///< size of the whole .glb, ≥ 1
  std::array<std::uint8_t, 32> sha256{};  ///< SHA-256 of the whole
  std::string name;                       ///< scene name for status, ≤ kMaxSceneNameBytes
  bool operator==(const SceneBegin&) const = default;
};

/// Client → server: bytes [offset, offset + data.size()) of an upload. Fixed 16 + data.
/// `data` views the datagram it was decoded from (valid while that buffer is).
struct SceneChunk {
  static constexpr MsgType kType = MsgType::kSceneChunk;
  static constexpr std::size_t kFixedSize = 16;
  std::uint32_t upload_id = 0;
  std::uint64_t offset = 0;
  std::span<const std::uint8_t> data;  ///< 1 ≤ size ≤ kMaxChunkBytes
};

/// Server → client: the chunk at `offset` of `length` bytes was stored. Fixed 32 bytes.
struct SceneChunkAck {
  static constexpr MsgType kType = MsgType::kSceneChunkAck;
  static constexpr std::size_t kFixedSize = 32;
  std::uint32_t upload_id = 0;
  std::uint32_t length = 0;
  std::uint64_t offset = 0;
  std::uint64_t received_bytes = 0;  ///< distinct bytes held so far
  std::uint64_t total_bytes = 0;
  bool operator==(const SceneChunkAck&) const = default;
};

/// Client → server: the client has sent every chunk; commit when complete and hashed.
/// Idempotent: repeat it until SceneStatus says accepted or refused. Fixed 8 bytes.
struct SceneCommit {
  static constexpr MsgType kType = MsgType::kSceneCommit;
  static constexpr std::size_t kFixedSize = 8;
  std::uint32_t upload_id = 0;
  bool operator==(const SceneCommit&) const = default;
};

/// SceneStatus::status values.
enum class SceneStatusCode : std::uint16_t {
  kAccepted = 0,       ///< loaded and swapped in
  kRefused = 1,        ///< text holds the first error; the old scene stays
  kIncomplete = 2,     ///< missing lists byte ranges still to send, then commit again
  kValidating = 3,     ///< complete and hashed; the daemon is loading it: commit again later
  kUnknownUpload = 4,  ///< no such upload (never begun, timed out, or already finished)
};

/// Server → client: answer to SceneCommit (and to a refused SceneBegin or chunk).
/// Fixed 32 + 16 per range + text.
struct SceneStatus {
  static constexpr MsgType kType = MsgType::kSceneStatus;
  static constexpr std::size_t kFixedSize = 32;
  struct Range {
    std::uint64_t offset = 0;
    std::uint64_t length = 0;
    bool operator==(const Range&) const = default;
  };
  std::uint32_t upload_id = 0;
  SceneStatusCode status = SceneStatusCode::kIncomplete;
  std::uint64_t received_bytes = 0;
  std::uint64_t total_bytes = 0;
  std::vector<Range> missing;  ///< ≤ kMaxMissingRanges, the first gaps in offset order
  std::string text;            ///< ≤ kMaxTextBytes
  bool operator==(const SceneStatus&) const = default;
};

/// Client → server: changes to the running scene, applied at one tick boundary.
/// Fixed 8 + 64 per pose + 64 per add + 4 per remove.
struct SceneUpdate {
  static constexpr MsgType kType = MsgType::kSceneUpdate;
  static constexpr std::size_t kFixedSize = 8;
  struct BodyPose {
    std::uint32_t body_index = 0;  ///< index of the body in the loaded scene
    WirePose X_WB;                 ///< pose of the body in the scene frame
    bool operator==(const BodyPose&) const = default;
  };
  std::vector<BodyPose> poses;  ///< new poses of kinematic bodies, ≤ kMaxUpdateEntries
  std::vector<BodyPose> added;  ///< inactive bodies made active at a pose, ≤ kMaxUpdateEntries
  std::vector<std::uint32_t> removed;  ///< bodies made inactive, ≤ kMaxUpdateEntries
  bool operator==(const SceneUpdate&) const = default;
};

/// Client → server: a target for the commanded (sim) device. The header's sequence number
/// orders commands: newest wins (CommandGate). Fixed 112 bytes.
struct PoseCommand {
  static constexpr MsgType kType = MsgType::kPoseCommand;
  static constexpr std::size_t kFixedSize = 112;
  WirePose X_WT;                ///< target pose of the held body's origin, scene frame
  WireVec3 v_W{0.0, 0.0, 0.0};  ///< linear velocity, m/s, scene frame
  WireVec3 w_W{0.0, 0.0, 0.0};  ///< angular velocity, rad/s, scene frame
  std::uint32_t buttons = 0;    ///< bit mask
  bool operator==(const PoseCommand&) const = default;
};

/// Subscribe::flags bits.
inline constexpr std::uint32_t kSubscribeBodies = 1u << 0;    ///< list the non-static bodies' poses
inline constexpr std::uint32_t kSubscribeContacts = 1u << 1;  ///< list the contact points
/// (1.1) Each state of a tick not sent before, as soon as the server sees it, at most rate_hz:
/// no duplicates when the rate is at or above the tick rate (a 1.0 server ignores the bit).
inline constexpr std::uint32_t kSubscribeEachTick = 1u << 2;

/// Client → server: send State at `rate_hz` (0 stops). Fixed 8 bytes.
struct Subscribe {
  static constexpr MsgType kType = MsgType::kSubscribe;
  static constexpr std::size_t kFixedSize = 8;
  std::uint32_t rate_hz = 0;  ///< 0..kMaxStateRateHz
  std::uint32_t flags = 0;    ///< kSubscribe* bits
  bool operator==(const Subscribe&) const = default;
};

/// State::fault_bits (bit 0 is the command gate's; the others the daemon's).
inline constexpr std::uint32_t kFaultStreamLost = 1u << 0;    ///< pose stream stopped > 200 ms
inline constexpr std::uint32_t kFaultDevice = 1u << 1;        ///< device I/O failed
inline constexpr std::uint32_t kFaultForceClamped = 1u << 2;  ///< a force was clamped to limits
inline constexpr std::uint32_t kFaultNotFinite = 1u << 3;     ///< a non-finite value was refused
inline constexpr std::uint32_t kFaultTickOverrun = 1u << 4;   ///< a tick missed its deadline

/// State::state_flags bits.
inline constexpr std::uint32_t kStateArmed = 1u << 0;      ///< forces enabled
inline constexpr std::uint32_t kStateStreaming = 1u << 1;  ///< a fresh pose stream drives
inline constexpr std::uint32_t kStateRamping = 1u << 2;    ///< stream stopped, force ramping
inline constexpr std::uint32_t kStateContactsTruncated = 1u << 3;  ///< more contacts than listed
inline constexpr std::uint32_t kStateBodiesTruncated = 1u << 4;    ///< more bodies than listed

/// Server → subscriber: one servo tick's state. Fixed 232 + 56 per contact + 64 per body, then
/// (minor ≥ 1) the kMinor1Size bytes of the minor-1 fields. A 1.0 State (no tail) decodes with
/// those fields 0; a newer minor's further bytes are ignored.
struct State {
  static constexpr MsgType kType = MsgType::kState;
  static constexpr std::size_t kFixedSize = 232;
  static constexpr std::size_t kMinor1Size = 24;  ///< appended by minor 1, after the lists
  struct Contact {
    WireVec3 p_W{0.0, 0.0, 0.0};  ///< contact point, scene frame, metres
    WireVec3 n_W{0.0, 0.0, 1.0};  ///< unit normal, scene frame
    double depth_m = 0.0;         ///< penetration depth ≥ 0 (negative: gap)
    bool operator==(const Contact&) const = default;
  };
  std::uint64_t tick = 0;             ///< servo tick counter (1 at the first tick)
  std::uint64_t sim_time_ns = 0;      ///< servo clock (monotonic or virtual), ns
  WirePose X_WD;                      ///< device (probe) pose, scene frame
  WirePose X_WP;                      ///< proxy pose, scene frame
  WireVec3 force_n{0.0, 0.0, 0.0};    ///< force on the held body, N, scene frame
  WireVec3 torque_nm{0.0, 0.0, 0.0};  ///< torque about the held body's origin, N·m, scene frame
  double force_scale = 1.0;           ///< 0..1, the command gate's ramp
  std::uint64_t last_command_sequence = 0;    ///< sequence of the newest accepted PoseCommand
  std::uint64_t tick_misses = 0;              ///< ticks over their deadline since start
  std::uint32_t tick_p50_ns = 0;              ///< compute time per tick, recent window, median, ns
  std::uint32_t tick_p99_ns = 0;              ///< ... 99th percentile, ns
  std::uint32_t tick_max_ns = 0;              ///< ... largest, ns
  std::uint32_t fault_bits = 0;               ///< kFault* bits, latched until arm
  std::uint32_t state_flags = 0;              ///< kState* bits
  std::uint32_t contact_count = 0;            ///< contacts this tick (may exceed contacts.size())
  std::vector<Contact> contacts;              ///< ≤ kMaxStateContacts
  std::vector<SceneUpdate::BodyPose> bodies;  ///< ≤ kMaxStateBodies, non-static bodies
  // --- minor version 1: appended after the lists (a 1.0 reader ignores them; from a 1.0
  // sender they read as 0) ---
  std::uint32_t pairs_tested = 0;   ///< narrow-phase pair tests this tick
  std::uint32_t pairs_skipped = 0;  ///< close pairs the scheduler left untested this tick
  double max_penetration_m = 0.0;   ///< deepest penetration of the held set this tick, ≥ 0 m
                                    ///< (decode refuses a negative one, kBadValue)
  std::uint32_t tick_ns = 0;        ///< compute time of this tick, ns
  bool operator==(const State&) const = default;
};

/// A message without payload: its type is all it says. Arm, Disarm, StatusRequest and Bye.
template <MsgType T>
struct EmptyMessage {
  static constexpr MsgType kType = T;
  static constexpr std::size_t kFixedSize = 0;
  bool operator==(const EmptyMessage&) const = default;
};
/// Client → server: take control and enable forces (clears a latched fault); answered with Ack.
using Arm = EmptyMessage<MsgType::kArm>;
/// Client → server: ramp the force to zero over the daemon's `[servo] stop_ramp_s` (0.2 s by
/// default); answered with Ack.
using Disarm = EmptyMessage<MsgType::kDisarm>;
/// Both ways: keeps a session alive; echoes the last timestamp seen for round-trip time.
/// Fixed 8 bytes.
struct Heartbeat {
  static constexpr MsgType kType = MsgType::kHeartbeat;
  static constexpr std::size_t kFixedSize = 8;
  std::uint64_t echo_timestamp_ns = 0;  ///< the peer's last header timestamp_ns, 0 if none
  bool operator==(const Heartbeat&) const = default;
};
/// Server → client: a request was refused. Fixed 16 + text.
struct ErrorMsg {
  static constexpr MsgType kType = MsgType::kError;
  static constexpr std::size_t kFixedSize = 16;
  std::uint64_t ref_sequence = 0;  ///< sequence of the refused datagram (0 if unknown)
  std::uint16_t ref_type = 0;      ///< its type (0 if unknown)
  Errc code = Errc::kOk;
  std::string text;  ///< ≤ kMaxTextBytes
  bool operator==(const ErrorMsg&) const = default;
};
/// Client → server: ask for a StatusReply.
using StatusRequest = EmptyMessage<MsgType::kStatusRequest>;
/// Server → client: what `hapticctl status` shows. Fixed 112 + 8 per counter + texts.
struct StatusReply {
  static constexpr MsgType kType = MsgType::kStatusReply;
  static constexpr std::size_t kFixedSize = 112;
  std::uint64_t uptime_ns = 0;          ///< since the daemon started, ns
  std::uint64_t ticks = 0;              ///< servo ticks since start
  std::uint64_t tick_misses = 0;        ///< ticks over their deadline since start
  double tick_rate_hz = 0.0;            ///< configured servo rate
  double measured_tick_hz = 0.0;        ///< recent measured servo rate
  std::uint32_t tick_p50_ns = 0;        ///< compute time per tick, recent window, median, ns
  std::uint32_t tick_p99_ns = 0;        ///< ... 99th percentile, ns
  std::uint32_t tick_max_ns = 0;        ///< ... largest, ns
  std::uint32_t fault_bits = 0;         ///< kFault* bits, as State
  std::uint32_t state_flags = 0;        ///< kState* bits, as State
  std::uint32_t sessions = 0;           ///< UDP sessions open now
  std::uint32_t subscribers = 0;        ///< sessions subscribed to states
  std::uint32_t state_rate_hz = 0;      ///< sum of the subscribers' rates
  std::uint64_t packets_received = 0;   ///< datagrams the server read
  std::uint64_t packets_sent = 0;       ///< datagrams the server sent
  std::uint64_t commands_accepted = 0;  ///< by the command gate
  std::uint64_t commands_dropped = 0;   ///< by the gate and by a full queue
  std::vector<std::uint64_t> refused;   ///< per Errc value in order, index 0 unused; ≤ 64
  std::string device;                   ///< ≤ kMaxDeviceBytes
  std::string scene;                    ///< ≤ kMaxSceneNameBytes
  std::string plan;                     ///< the simulation plan as text, ≤ kMaxPlanBytes
  // --- minor version 1: appended after the texts (kMinor1FixedSize + shm_name; a 1.0 reader
  // ignores them; from a 1.0 sender they read as 0 and "") ---
  static constexpr std::size_t kMinor1FixedSize = 56;
  std::uint64_t shm_commands = 0;          ///< commands taken from the shared-memory ring
  std::uint64_t shm_commands_refused = 0;  ///< shm slots refused (non-finite, bad kind, ...)
  std::uint64_t edit_batches_applied = 0;  ///< scene updates applied at a tick boundary
  std::uint64_t edit_batches_dropped = 0;  ///< scene updates dropped (their scene was replaced)
  std::uint64_t edits_applied = 0;         ///< entries of scene updates applied
  std::uint64_t edits_refused = 0;         ///< entries the simulation refused at the tick
  std::uint32_t shm_flags = 0;             ///< kShmServing | kShmClientAttached | kShmClientAlive
  std::string shm_name;  ///< the segment served, "" when none; ≤ kMaxShmNameBytes
  // --- minor version 2: appended after shm_name (kMinor2FixedSize + loading; a 1.1 reader
  // ignores it; from a 1.1 sender it reads as "") ---
  static constexpr std::size_t kMinor2FixedSize = 4;
  /// What a scene build (SIGHUP reload, upload) is doing ("loading scene 'part.glb': decomposing
  /// mesh 2 (...), 12 pieces, 1.4 s"); "" when none runs. ≤ kMaxTextBytes
  std::string loading;
  bool operator==(const StatusReply&) const = default;
};
/// StatusReply::shm_flags bits.
inline constexpr std::uint32_t kShmServing = 1u << 0;         ///< the daemon serves the segment
inline constexpr std::uint32_t kShmClientAttached = 1u << 1;  ///< a client has attached
inline constexpr std::uint32_t kShmClientAlive = 1u << 2;     ///< ... and beat within 500 ms

/// Server → client: a request that has no other answer (arm, disarm, subscribe, scene update)
/// was accepted. Fixed 16 bytes.
struct Ack {
  static constexpr MsgType kType = MsgType::kAck;
  static constexpr std::size_t kFixedSize = 16;
  std::uint64_t ref_sequence = 0;  ///< sequence of the request acknowledged
  std::uint16_t ref_type = 0;      ///< its type
  bool operator==(const Ack&) const = default;
};
/// Either way: the session ends.
using Bye = EmptyMessage<MsgType::kBye>;

/// Any message. The index order is not on the wire (MsgType is).
using Message = std::variant<Hello,
                             Welcome,
                             SceneBegin,
                             SceneChunk,
                             SceneChunkAck,
                             SceneCommit,
                             SceneStatus,
                             SceneUpdate,
                             PoseCommand,
                             Subscribe,
                             State,
                             Arm,
                             Disarm,
                             Heartbeat,
                             ErrorMsg,
                             StatusRequest,
                             StatusReply,
                             Ack,
                             Bye>;

/// The payload size of `m` as encoded (no header, no tag). Any thread.
std::size_t payloadSize(const Message& m);

/// Encodes header `h` (its type and payload_length are set from `m`; flags kept; no tag) and
/// the payload into `out`. Returns the bytes written, or 0 with `*error` set: kBufferTooSmall,
/// kNotFinite (a NaN or Inf in a float), kBadValue (a list or string over its bound).
/// Any thread; no allocation.
std::size_t encode(Header h, const Message& m, std::span<std::uint8_t> out, Errc* error = nullptr);

/// Decodes the payload of a message of `type` sent with minor version `minor`. The payload
/// length must match the type (as laid out in that minor: State has a 1.0 and a 1.1 layout)
/// exactly when minor ≤ kVersionMinor; a newer minor may append bytes, which are ignored.
/// Any thread. `out` views `payload` for SceneChunk.
DecodeError decodePayload(std::uint16_t type,
                          std::uint8_t minor,
                          std::span<const std::uint8_t> payload,
                          Message& out);

/// decodeHeader, then decodePayload. A tag, when flagged, is neither read nor verified here
/// (see auth.h). Any thread.
DecodeError decode(std::span<const std::uint8_t> datagram, Header& header, Message& out);

/// The MsgType of a message. Any thread.
MsgType typeOf(const Message& m);

}  // namespace hapticd::proto
