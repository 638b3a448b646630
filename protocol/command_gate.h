#pragma once
/// \file
/// The command gate: the safety state machine between pose commands and the commanded device.
/// Pure and deterministic on the caller's clock (simulated or monotonic), no allocation, no
/// locks: the daemon's servo thread owns one and calls it every tick (docs/architecture.md rule
/// 8, libfranka's "every command checked before it reaches the robot").
///
/// Rules (issue 8, Safety):
///  - one controlling session: the one that armed last; commands of other sessions are dropped;
///  - newest command wins: per session, a sequence number not above the largest seen is dropped
///    (older or duplicate), counted by reason;
///  - a stream that stops: for hold_ns after the newest command the target is held at full force
///    (kStreaming); then the force scale falls linearly to 0 at zero_ns (kRamping); at zero_ns a
///    fault (kFaultStreamLost) is latched (kFaulted, scale 0) until the next arm();
///  - disarm() forgets the target and reports kDisarmed with scale 0. Taking the force away is
///    the owner's: hapticd does not apply the gate's 0 at once but ramps its own output to zero
///    over [servo] stop_ramp_s (a sudden release of a large force makes the hand lurch).
///
/// The gate works on the caller's own command type (BasicCommandGate<Target>): the daemon gates
/// its device::PoseCommand (the wire pose converted once, where it enters), tests and tools the
/// wire's PoseCommand (CommandGate). A Target is copyable and has a zeroVelocities(Target&)
/// found by argument-dependent lookup (a ramping target is held still).
///
/// Times are ns on one clock, the servo's: pass the tick time when a command is drained from the
/// queue, and the tick time to update().

#include <array>
#include <cstdint>

#include "protocol/messages.h"

namespace hapticd::proto {

/// Timing of the gate. Defaults are the issue's: hold 20 ms, zero force and fault at 200 ms.
struct CommandGateConfig {
  std::uint64_t hold_ns = 20'000'000;   ///< newest command held at full force this long
  std::uint64_t zero_ns = 200'000'000;  ///< force scale reaches 0 and the fault latches here
};

/// What the gate is doing.
enum class GateMode : std::uint8_t {
  kDisarmed,   ///< no force (initial state, and after disarm)
  kArmedIdle,  ///< armed, no command since: full force, no commanded target
  kStreaming,  ///< newest command at most hold_ns old: full force, target = that command
  kRamping,    ///< command older than hold_ns: target held, force scale falling to 0
  kFaulted,    ///< stream lost: scale 0, kFaultStreamLost latched until arm
};
const char* gateModeName(GateMode m);

/// Why a command was dropped.
enum class DropReason : std::uint8_t {
  kOlder,          ///< sequence below the largest seen from its session
  kDuplicate,      ///< sequence equal to the largest seen
  kNotArmed,       ///< the gate is disarmed
  kFaulted,        ///< the gate is faulted (re-arm first)
  kNotController,  ///< from a session other than the one that armed
  kCount
};

/// The gate's answer for one tick, but the target.
struct GateStatus {
  GateMode mode = GateMode::kDisarmed;
  bool has_target = false;           ///< false: no command since arm (the device keeps its pose)
  double force_scale = 0.0;          ///< multiply the device force and torque by this, 0..1
  std::uint32_t fault_bits = 0;      ///< kFaultStreamLost while latched
  std::uint64_t last_sequence = 0;   ///< sequence of the newest accepted command (State echo)
  std::uint64_t command_age_ns = 0;  ///< now minus the newest command's arrival, 0 without one
};

/// The gate's answer for one tick.
template <class Target>
struct BasicGateOutput : GateStatus {
  Target target{};  ///< the newest accepted command (velocities zero when ramping)
};

/// The gate's state machine without the target: sessions, sequence numbers, mode, scale and
/// fault. BasicCommandGate adds the target; use that.
class CommandGateCore {
 public:
  /// Sessions whose sequence numbers are tracked; the least recently used is forgotten first.
  static constexpr std::size_t kSessions = 16;

  explicit CommandGateCore(CommandGateConfig config = {}) noexcept : config_(config) {}

  void arm(std::uint64_t session_id, std::uint64_t now_ns) noexcept;
  void disarm(std::uint64_t now_ns) noexcept;
  /// True when the command is accepted (the newest): the caller keeps it as the target.
  bool submit(std::uint64_t session_id, std::uint64_t sequence, std::uint64_t now_ns) noexcept;
  /// Advances to now_ns (never backwards): everything of the answer but the target.
  GateStatus update(std::uint64_t now_ns) noexcept;

  GateMode mode() const noexcept { return mode_; }
  std::uint64_t accepted() const noexcept { return accepted_; }
  std::uint64_t dropped(DropReason r) const noexcept {
    return dropped_[static_cast<std::size_t>(r)];
  }
  std::uint64_t droppedTotal() const noexcept;
  std::uint64_t controller() const noexcept { return controller_; }
  const CommandGateConfig& config() const noexcept { return config_; }

 private:
  struct SessionSeq {
    std::uint64_t session = 0;
    std::uint64_t max_seen = 0;
    std::uint64_t last_use = 0;
  };
  void timeTo(std::uint64_t now_ns) noexcept {  // never backwards
    if (now_ns > now_ns_)
      now_ns_ = now_ns;
  }
  SessionSeq& sessionEntry(std::uint64_t session_id) noexcept;
  void drop(DropReason r) noexcept { ++dropped_[static_cast<std::size_t>(r)]; }

  CommandGateConfig config_;
  GateMode mode_ = GateMode::kDisarmed;
  std::uint64_t controller_ = 0;
  bool has_target_ = false;
  std::uint64_t last_sequence_ = 0;
  std::uint64_t last_command_ns_ = 0;
  std::uint64_t now_ns_ = 0;
  std::uint32_t fault_bits_ = 0;
  std::uint64_t use_counter_ = 0;
  std::array<SessionSeq, kSessions> sessions_{};
  std::uint64_t accepted_ = 0;
  std::array<std::uint64_t, static_cast<std::size_t>(DropReason::kCount)> dropped_{};
};

/// See the file comment. Servo thread: every member is noexcept, allocation-free and O(1)
/// (the session table has kSessions entries).
template <class Target>
class BasicCommandGate {
 public:
  static constexpr std::size_t kSessions = CommandGateCore::kSessions;

  explicit BasicCommandGate(CommandGateConfig config = {}) noexcept : core_(config) {}

  /// Arms for `session_id` (it becomes the controller) and clears a latched fault. The session's
  /// largest sequence seen is kept, so its old commands stay dropped.
  void arm(std::uint64_t session_id, std::uint64_t now_ns) noexcept {
    core_.arm(session_id, now_ns);
  }
  /// kDisarmed, scale 0; forgets the target (see the file comment for who ramps the force).
  void disarm(std::uint64_t now_ns) noexcept { core_.disarm(now_ns); }
  /// Offers a command that arrived at now_ns. Returns true when accepted (it is the newest).
  bool submit(std::uint64_t session_id,
              std::uint64_t sequence,
              const Target& cmd,
              std::uint64_t now_ns) noexcept {
    if (!core_.submit(session_id, sequence, now_ns))
      return false;
    target_ = cmd;
    return true;
  }
  /// Advances the state machine to now_ns (never backwards: an earlier time counts as now) and
  /// returns what the device should do this tick.
  BasicGateOutput<Target> update(std::uint64_t now_ns) noexcept {
    BasicGateOutput<Target> out;
    static_cast<GateStatus&>(out) = core_.update(now_ns);
    out.target = target_;
    if (out.mode == GateMode::kRamping || out.mode == GateMode::kFaulted)
      zeroVelocities(out.target);  // held still
    return out;
  }

  GateMode mode() const noexcept { return core_.mode(); }
  std::uint64_t accepted() const noexcept { return core_.accepted(); }
  std::uint64_t dropped(DropReason r) const noexcept { return core_.dropped(r); }
  std::uint64_t droppedTotal() const noexcept { return core_.droppedTotal(); }
  std::uint64_t controller() const noexcept { return core_.controller(); }
  const CommandGateConfig& config() const noexcept { return core_.config(); }

 private:
  CommandGateCore core_;
  Target target_{};
};

/// The wire's command held still (velocities zero), for BasicCommandGate<PoseCommand>.
inline void zeroVelocities(PoseCommand& c) noexcept {
  c.v_W = {0.0, 0.0, 0.0};
  c.w_W = {0.0, 0.0, 0.0};
}

/// The gate on the wire's command type (tests, tools, protocol/README.md's example).
using CommandGate = BasicCommandGate<PoseCommand>;
using GateOutput = BasicGateOutput<PoseCommand>;

}  // namespace hapticd::proto
