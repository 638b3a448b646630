#pragma once
/// \file
/// The shared-memory transport for clients on the same host: one POSIX shm segment
/// (shm_open("/hapticd"), mode 0600) holding a versioned header, a seqlock state block written by
/// the daemon every tick, a single-producer single-consumer command ring written by one client
/// (the commander), and a heartbeat in each direction; any number of read-only readers of the
/// state block beside the commander. After PipeWire spa/node/io.h, every field names its unit
/// and clock. No allocation, no locks and no system calls after create/attach: publish() and
/// popCommand() are servo-thread safe.
///
/// Segment layout (offsets in bytes; all integers little-endian as the host, all atomics
/// lock-free 64-bit, so the layout is the same in every process of this host):
///
/// | off | what |
/// |---|---|
/// | 0 | ShmHeader (256 bytes) |
/// | 256 | ShmStateBlock: seqlock word, then ShmState as 64-bit words |
/// | ring_offset | ShmRing: head, tail (own cache lines), then ring_slots × ShmCommand |

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

#include "core/common/result.h"
#include "protocol/messages.h"
#include "protocol/seqlock.h"
#include "protocol/spsc_ring.h"

namespace hapticd::proto {

// Shared-memory layout version; its own changelog:
//   1.0  2026-12-01  header, seqlock state (ShmState 1.0), command ring of ShmCommand 1.0.
//   1.1  2026-12-01  ShmState appends pairs_tested, pairs_skipped, max_penetration_m, tick_ns
//                    (the State minor-1 fields of the UDP protocol).
// A minor version may only append fields to ShmState or ShmCommand (sizes in the header tell a
// reader how much is there); anything else is a new major, refused by attach().
inline constexpr std::uint32_t kShmMagic = 0x4d535048u;  // "HPSM"
inline constexpr std::uint16_t kShmMajor = 1;
inline constexpr std::uint16_t kShmMinor = 1;
inline constexpr const char* kDefaultShmName = "/hapticd";
inline constexpr std::uint32_t kShmRingSlots = 256;  ///< power of two
inline constexpr std::size_t kShmBodies = 16;        ///< body poses in the state block

/// The segment header. Written once by create() except the heartbeat and attach fields.
struct ShmHeader {
  std::uint32_t magic;          ///< kShmMagic
  std::uint16_t major;          ///< kShmMajor
  std::uint16_t minor;          ///< kShmMinor
  std::uint64_t segment_bytes;  ///< total mapped size
  std::uint64_t state_offset;   ///< byte offset of ShmStateBlock
  std::uint64_t state_bytes;    ///< sizeof(ShmState) of the writer
  std::uint64_t ring_offset;    ///< byte offset of ShmRing
  std::uint32_t ring_slots;     ///< slots in the ring (power of two)
  std::uint32_t slot_bytes;     ///< sizeof(ShmCommand) of the writer
  std::uint64_t session_base;   ///< random; the gate's session id is session_base + generation
  std::atomic<std::uint64_t> server_heartbeat_ns;  ///< daemon's CLOCK_MONOTONIC at its last beat
  std::atomic<std::uint64_t> client_heartbeat_ns;  ///< client's CLOCK_MONOTONIC at its last beat
  std::atomic<std::uint64_t> server_pid;           ///< daemon process id
  std::atomic<std::uint64_t> client_pid;           ///< attached client's pid, 0 when none
  std::atomic<std::uint64_t> client_generation;    ///< +1 per attach
  std::atomic<std::uint64_t> commands_refused;     ///< slots the consumer dropped (non-finite, bad)
  std::uint8_t reserved[256 - 104];
};
static_assert(sizeof(ShmHeader) == 256);
static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

/// One tick's state as the daemon publishes it. Every field is 8 bytes (the seqlock copies
/// 64-bit words). Poses: translation metres then quaternion x, y, z, w, scene frame.
struct ShmState {
  std::uint64_t tick;                   ///< servo tick counter since start
  std::uint64_t sim_time_ns;            ///< servo clock (CLOCK_MONOTONIC or the virtual clock), ns
  std::uint64_t publish_ns;             ///< CLOCK_MONOTONIC when written, ns
  double X_WD[7];                       ///< device (probe) pose
  double X_WP[7];                       ///< proxy pose
  double force_n[3];                    ///< force on the held body, N, scene frame
  double torque_nm[3];                  ///< torque about the held body's origin, N·m, scene frame
  double force_scale;                   ///< command gate ramp, 0..1
  std::uint64_t last_command_sequence;  ///< newest accepted command (UDP or shm)
  std::uint64_t tick_misses;            ///< ticks over deadline since start
  std::uint64_t tick_p50_ns;            ///< tick compute time percentiles, ns
  std::uint64_t tick_p99_ns;
  std::uint64_t tick_max_ns;
  std::uint64_t fault_bits;     ///< kFault* bits
  std::uint64_t state_flags;    ///< kState* bits
  std::uint64_t contact_count;  ///< contacts this tick
  std::uint64_t body_count;     ///< entries used in bodies (≤ kShmBodies)
  struct Body {
    std::uint64_t index;  ///< body index in the scene
    double X_WB[7];       ///< body pose
  } bodies[kShmBodies];
  // --- layout minor 1 ---
  std::uint64_t pairs_tested;   ///< narrow-phase pair tests this tick
  std::uint64_t pairs_skipped;  ///< close pairs the scheduler left untested this tick
  double max_penetration_m;     ///< deepest penetration of the held set this tick, m, ≥ 0
  std::uint64_t tick_ns;        ///< compute time of this tick, ns
};
static_assert(sizeof(ShmState) % 8 == 0);
inline constexpr std::size_t kShmStateWords = sizeof(ShmState) / 8;

/// A command slot. kind: 1 pose, 2 arm, 3 disarm.
struct ShmCommand {
  std::uint64_t kind;
  std::uint64_t sequence;      ///< client's, strictly increasing per attach
  std::uint64_t generation;    ///< the attach generation that wrote it
  std::uint64_t timestamp_ns;  ///< client's CLOCK_MONOTONIC when written
  double X_WT[7];              ///< target pose (pose kind)
  double v_W[3];               ///< m/s
  double w_W[3];               ///< rad/s
  std::uint64_t buttons;
};
static_assert(sizeof(ShmCommand) == std::size_t{18} * 8);

/// The state block: the seqlock word (odd while the writer is inside), then ShmState as 64-bit
/// words (protocol/seqlock.h, the same seqlock the daemon uses in process).
using ShmStateBlock = SeqlockBlock<ShmState>;
static_assert(ShmStateBlock::kWords == kShmStateWords);
static_assert(std::is_standard_layout_v<ShmStateBlock>);

/// The command ring (protocol/spsc_ring.h, the same ring the daemon uses in process): head
/// written by the client, tail by the daemon, then the slots.
struct ShmRing {
  SpscIndices indices;
  alignas(64) ShmCommand slots[kShmRingSlots];
};
static_assert(offsetof(ShmRing, slots) == 128);

/// A command taken from the ring, checked (finite, unit quaternion) and in the gate's terms.
struct ShmCommandEvent {
  enum class Kind : std::uint8_t { kPose = 1, kArm = 2, kDisarm = 3 };
  Kind kind = Kind::kPose;
  std::uint64_t session_id = 0;  ///< session_base + generation
  std::uint64_t sequence = 0;
  std::uint64_t timestamp_ns = 0;
  PoseCommand pose;
};

/// Converts a published ShmState into the UDP State message (no contacts list: ShmState has
/// none; body poses: the first body_count ≤ kShmBodies; the minor-1 fields, counts saturated at
/// 2^32 − 1, a negative or non-finite depth as 0). Any thread.
void toState(const ShmState& in, State& out);

/// What is at a segment's name before a server creates it. Any thread; no state changed.
struct ShmExisting {
  enum class Kind : std::uint8_t {
    kNone,     ///< nothing at the name
    kHapticd,  ///< a hapticd segment of this user (its magic, at least a header): server_* set
    kForeign,  ///< anything else (not this user's, too small, another magic, not openable)
  };
  Kind kind = Kind::kNone;
  std::string path;  ///< the file that holds it, "/dev/shm/NAME" (Linux's shm_open)
  std::string what;  ///< kForeign: what was found, e.g. "12 bytes, smaller than a segment header"
  std::uint64_t server_pid = 0;           ///< kHapticd: the header's server pid
  std::uint64_t server_heartbeat_ns = 0;  ///< kHapticd: its last beat, CLOCK_MONOTONIC ns (0 none)
};
/// Looks at `name` (a valid shm name) without changing it.
ShmExisting inspectShm(const std::string& name);

/// The daemon's side: creates and owns the segment; unlinks it on destruction. publish(),
/// popCommand(), beat() and clientAlive() are servo-thread safe.
class ShmServer {
 public:
  /// A hapticd segment already at `name` (inspectShm: kHapticd) is replaced: the caller has
  /// decided it is stale. Anything else there is never removed: error "PATH is not a hapticd
  /// segment (WHAT)"; so are a bad name and shm_open / ftruncate / mmap failures.
  static Result<ShmServer> create(const std::string& name = kDefaultShmName);
  ~ShmServer();
  ShmServer(ShmServer&& o) noexcept;
  ShmServer& operator=(ShmServer&&) = delete;
  ShmServer(const ShmServer&) = delete;

  /// Writes one state under the seqlock. Single writer.
  void publish(const ShmState& s) noexcept;
  /// Takes the next command; false when the ring is empty. A slot that fails the checks is
  /// counted (header commands_refused) and skipped.
  bool popCommand(ShmCommandEvent& out) noexcept;
  /// Heartbeat: now_ns on CLOCK_MONOTONIC.
  void beat(std::uint64_t now_ns) noexcept;
  /// True when a client is attached and beat within timeout_ns of now_ns.
  bool clientAlive(std::uint64_t now_ns, std::uint64_t timeout_ns) const noexcept;
  /// True when a client has attached (its pid is in the header), beating or not.
  bool clientAttached() const noexcept;
  const std::string& name() const { return name_; }
  std::uint64_t commandsRefused() const noexcept;

 private:
  ShmServer() = default;
  std::string name_;
  void* base_ = nullptr;
  std::size_t size_ = 0;
};

/// A client's side: attaches to an existing segment (checks magic, version and sizes). Two
/// kinds: one commander at a time (attach(): the command ring, the client heartbeat and pid,
/// a gate session of its own), and any number of read-only state readers beside it
/// (attachReader(): the segment mapped read-only, nothing in it written, invisible to the
/// daemon; readState() and serverAlive() only).
class ShmClient {
 public:
  /// The commander. Errors: no segment (daemon not running or shm off), wrong version, a live
  /// commander already attached (its heartbeat is younger than `takeover_after_ns`).
  static Result<ShmClient> attach(const std::string& name = kDefaultShmName,
                                  std::uint64_t takeover_after_ns = 500'000'000);
  /// A read-only state reader, beside the commander and any other reader. Errors: no segment,
  /// wrong version or sizes.
  static Result<ShmClient> attachReader(const std::string& name = kDefaultShmName);
  ~ShmClient();
  ShmClient(ShmClient&& o) noexcept;
  ShmClient& operator=(ShmClient&&) = delete;
  ShmClient(const ShmClient&) = delete;

  /// Reads the newest state without tearing; false when none was published yet or the writer
  /// kept it busy for max_tries attempts (never blocks).
  bool readState(ShmState& out, int max_tries = 10000) const noexcept;
  /// True for a reader (attachReader()): the push calls return false, beat() does nothing.
  bool readOnly() const noexcept { return read_only_; }
  /// Queues a pose command (sequence assigned here, returned in *sequence); false when full or
  /// read-only.
  bool pushPose(const PoseCommand& cmd,
                std::uint64_t now_ns,
                std::uint64_t* sequence = nullptr) noexcept;
  bool pushArm(std::uint64_t now_ns) noexcept;
  bool pushDisarm(std::uint64_t now_ns) noexcept;
  void beat(std::uint64_t now_ns) noexcept;
  /// True when the daemon beat within timeout_ns of now_ns.
  bool serverAlive(std::uint64_t now_ns, std::uint64_t timeout_ns) const noexcept;
  std::uint64_t sessionId() const noexcept;

 private:
  ShmClient() = default;
  // maps the segment and checks its header (both kinds)
  static Result<ShmClient> map(const std::string& name, bool read_only);
  bool push(ShmCommand c) noexcept;
  bool pushControl(std::uint64_t kind, std::uint64_t now_ns) noexcept;  // arm or disarm
  void* base_ = nullptr;
  std::size_t size_ = 0;
  std::uint64_t generation_ = 0;
  std::uint64_t sequence_ = 0;
  bool read_only_ = false;
};

}  // namespace hapticd::proto
