#pragma once
/// \file
/// The servo loop (docs/architecture.md "One servo tick"): each period it reads the device, maps
/// the pose into the scene, steps the simulation, passes its raw wrench through the one output
/// stage (response::OutputStage: finite, device frame, clamp, ramp-in x fade x gate, step limit)
/// and writes the result to the device, publishes state and hands a record row on. It is paced by a
/// Clock (real monotonic, virtual, scripted), measures each tick's wake-up lateness and compute
/// time into fixed histograms, skips missed periods instead of queueing them, and after
/// `miss_fault_count` consecutive overruns fades the force to zero and latches a fault until
/// re-armed.
///
/// Threads (docs/architecture.md rule 6): run() is the servo thread. It meets the other threads
/// only at
///  - a command ring (single producer: the owner thread; sendCommand()),
///  - a ring of scene edit batches (single producer; sendEdits()), applied whole at one tick
///    boundary before step(),
///  - an optional shared-memory segment (proto::ShmServer, attachShm()): its command ring is
///    drained into the same command gate as the network's commands, and a proto::ShmState is
///    published after every tick,
///  - a scene pointer exchange (offerScene() / reclaimScenes() on the owner thread),
///  - a seqlock state block (state(), any thread) and a second one with the tick's lists (body
///    poses and contact points; lists(), any thread),
///  - lock-free rings of log events and record rows (popLog(), popRecord(), popBody(): one
///    consumer thread each),
///  - the atomic stop flag (requestStop(), any thread) and relaxed-atomic histograms.
/// run() never allocates, locks, logs, throws or does I/O other than the device and its sleep
/// (one exception: with `wait_for_record_space`, meant for virtual clocks, a full record ring
/// makes it wait for the writer instead of dropping rows).

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "core/response/output_stage.h"
#include "core/sim/simulation.h"
#include "daemon/clock.h"
#include "daemon/device/device.h"
#include "daemon/handoff/scene_exchange.h"
#include "daemon/histogram.h"
#include "daemon/workspace.h"
#include "protocol/command_gate.h"
#include "protocol/messages.h"
#include "protocol/seqlock.h"
#include "protocol/shm.h"
#include "protocol/spsc_ring.h"

namespace hapticd::daemon {

// the project's one ring and one seqlock (protocol/spsc_ring.h, protocol/seqlock.h)
using proto::Seqlock;
using proto::SpscRing;

/// The marker of functions that run on the servo thread (a hook for a real-time sanitizer).
#define HAPTICD_SERVO_THREAD

/// One scene's pipeline, built off the servo thread and handed over whole.
struct ServoScene {
  std::unique_ptr<sim::Simulation> sim;
  std::uint64_t generation = 0;  ///< set by the owner: 1 for the first scene, +1 per reload
  /// The held body's start pose, device frame, handed to Device::setHome() when the scene is
  /// taken; none when [device] sim_home_from_scene is off or the scene has no probe.
  std::optional<geom::Pose> X_D_home;
};

/// Loop settings (config [servo] and [device]).
struct ServoOptions {
  double rate_hz = 1000.0;              ///< tick rate; the period is rounded to whole ns
  std::uint32_t miss_fault_count = 10;  ///< consecutive overrunning ticks that latch a fault
  double fault_fade_s = 0.05;           ///< the force fades to zero over this after a fault (s)
  double stop_ramp_s = 0.2;             ///< SIGTERM / disarm: the force ramps to zero over this (s)
  double ramp_in_s = 0.5;  ///< the force ramps in over this at start, on arm and device back (s)
  WorkspaceMapping workspace;
  device::DeviceLimits limits;         ///< clamp of the force written to the device (device frame)
  double max_force_step_n = 0.5;       ///< largest change of the written force per tick (N)
  double max_torque_step_nm = 0.05;    ///< largest change of the written torque per tick (N m)
  bool armed_at_start = true;          ///< false: forces stay zero until an arm command
  std::uint64_t max_ticks = 0;         ///< run() returns after this many ticks; 0: no limit
  bool record = false;                 ///< push a RecordRow per tick
  bool record_bodies = false;          ///< push a BodyRow per non-static body per tick
  bool wait_for_record_space = false;  ///< full record ring: wait (virtual clock) or drop (real)
  std::size_t command_capacity = 256;
  std::size_t edit_capacity = 16;  ///< scene edit batches waiting for the servo thread
  std::size_t log_capacity = 1024;
  std::size_t record_capacity = 1 << 14;
  std::size_t body_capacity = 1 << 16;
};

/// What the owner asks of the servo thread.
enum class CommandKind : std::uint8_t {
  kPose,    ///< a client's pose command (scene frame): handed to the device
  kArm,     ///< clear latched faults, ramp forces in again
  kDisarm,  ///< ramp forces to zero and hold them there
};

struct ServoCommand {
  CommandKind kind = CommandKind::kPose;
  std::uint64_t sequence = 0;  ///< echoed in ServoState::last_command_sequence
  device::PoseCommand pose;    ///< kPose: target pose and velocities in the scene frame
  /// true: a network client's command, passed through the protocol's CommandGate (newest wins
  /// per session, stream-stop hold, ramp and fault); false: applied directly (tests, replay).
  bool gated = false;
  std::uint64_t session_id = 0;  ///< gated: the client session (the gate's controller)
};

/// Latched faults (ServoState::faults); cleared by kArm. The protocol's numbering (State and
/// StatusReply fault_bits), so that a fault has one number wherever a number is shown (the wire,
/// the status file's faults.bits); the log, the status line and the summary name them
/// (faultNames()).
enum FaultBits : std::uint32_t {
  kFaultStreamLost = proto::kFaultStreamLost,  ///< "stream_lost": a client's pose stream stopped
  kFaultNonFinite = proto::kFaultNotFinite,    ///< "not_finite": a non-finite force or torque
  kFaultMisses = proto::kFaultTickOverrun,     ///< "tick_overrun": miss_fault_count overruns
  kFaultDevice = proto::kFaultDevice,          ///< "device": the device reported an error (kFault)
};

/// The state block, published once per tick through the seqlock. Scene frame, SI units.
struct ServoState {
  std::uint64_t tick = 0;          ///< ticks run so far
  std::uint64_t period_index = 0;  ///< periods elapsed (ticks + skipped periods)
  double t_s = 0.0;                ///< loop time of the last tick
  geom::Pose X_W_device;           ///< device pose after the workspace mapping
  geom::Pose X_W_proxy;
  geom::Vec3 force_W_n{0.0};  ///< force written (after the output stage)
  geom::Vec3 torque_W_nm{0.0};
  /// The held set's contact points: penalty rows and contacts with dynamic bodies
  /// (sim::TickOutput::contacts + held_dynamic_contacts).
  std::uint32_t contacts = 0;
  std::uint32_t pairs_tested = 0;
  std::uint32_t pairs_skipped = 0;
  std::uint32_t tick_flags = 0;  ///< sim::TickFlags of the last tick, the output stage's included
  double max_penetration_m = 0.0;
  std::uint32_t faults = 0;         ///< FaultBits latched now
  std::uint32_t faults_seen = 0;    ///< FaultBits latched at some time since start
  std::uint64_t fault_latches = 0;  ///< faults latched since start (each a "fault latched" line)
  std::uint32_t consecutive_misses = 0;
  std::uint64_t overruns = 0;         ///< ticks whose end passed the next deadline
  std::uint64_t skipped_periods = 0;  ///< periods skipped after overruns
  std::uint64_t device_lost_count = 0;
  std::uint64_t scene_generation = 0;
  std::uint64_t last_command_sequence = 0;
  std::uint64_t records_dropped = 0;
  std::uint64_t log_dropped = 0;
  std::int64_t last_tick_ns = 0;    ///< compute time of the last tick
  double output_gain = 1.0;         ///< 1 normally, fading to 0 on fault, disarm and stop
  std::uint64_t ramp_restarts = 0;  ///< times the output stage's ramp-in started again
  double peak_force_n = 0.0;        ///< largest |force| written so far
  double peak_penetration_m = 0.0;  ///< largest max_penetration so far
  std::uint64_t contact_ticks = 0;  ///< ticks with at least one contact
  std::uint8_t gate_mode = 0;       ///< proto::GateMode of the CommandGate
  double gate_scale = 1.0;          ///< the gate's force scale applied this tick (1 when unused)
  std::uint64_t commands_accepted = 0;     ///< gated pose commands accepted (newest)
  std::uint64_t commands_dropped = 0;      ///< gated pose commands dropped (older, duplicate, ...)
  std::uint64_t edit_batches_applied = 0;  ///< edit batches applied (at their tick boundary)
  std::uint64_t edit_batches_dropped = 0;  ///< batches for a scene generation no longer current
  std::uint64_t edits_applied = 0;         ///< edit entries the simulation accepted
  std::uint64_t edits_refused = 0;         ///< edit entries it refused (sim::EditStatus != kOk)
  std::uint64_t shm_commands = 0;          ///< commands taken from the shared-memory ring
  bool shm_client_alive = false;           ///< a shm client beat within kShmAliveTimeoutNs
  bool device_connected = false;
  bool armed = false;
  bool stopping = false;
  bool running = false;  ///< the loop is inside run()
};

/// Capacity of each list of an edit batch: one protocol SceneUpdate.
inline constexpr std::size_t kMaxEditEntries = proto::kMaxUpdateEntries;

/// One entry of an edit batch: a scene body index and a pose (scene frame; ignored for removes).
struct EditEntry {
  std::uint32_t body = 0;
  geom::Pose X_WB;
};

/// One client scene update (a proto::SceneUpdate), validated by the owner against the scene of
/// `generation` and applied whole by the servo thread at one tick boundary, before step(), in
/// the order removes, adds, poses (so that an update may add a body and move it, or take a body
/// out and put it back at a pose). A batch for a generation other than the running scene's is
/// dropped and counted (ServoState::edit_batches_dropped). Trivially copyable.
struct EditBatch {
  std::uint64_t generation = 0;  ///< ServoScene::generation it was validated against
  std::uint64_t id = 0;          ///< the owner's number for it (events name it)
  std::uint32_t pose_count = 0;
  std::uint32_t add_count = 0;
  std::uint32_t remove_count = 0;
  std::array<EditEntry, kMaxEditEntries> poses{};        ///< setKinematicPose
  std::array<EditEntry, kMaxEditEntries> added{};        ///< setBodyActive(body, true, X_WB)
  std::array<std::uint32_t, kMaxEditEntries> removed{};  ///< setBodyActive(body, false)
};

/// Capacities of the lists block (the protocol's State lists).
inline constexpr std::size_t kListBodies = proto::kMaxStateBodies;
inline constexpr std::size_t kListContacts = proto::kMaxStateContacts;

/// The tick's lists, published once per tick through a second seqlock (only the used entries
/// are copied). Scene frame. Read with ServoLoop::lists().
struct ServoLists {
  std::uint64_t tick = 0;              ///< ServoState::tick of the tick these are from
  std::uint64_t scene_generation = 0;  ///< the scene the body indices refer to
  std::uint32_t body_count = 0;        ///< entries used in bodies
  std::uint32_t bodies_total = 0;      ///< active non-static bodies (may be more than listed)
  std::uint32_t contact_count = 0;     ///< entries used in contacts
  std::uint32_t contacts_total = 0;    ///< contact points the simulation reported (may be more)
  /// Simulation::bodyPoses() of the active bodies (Simulation::bodyActive), in index order
  std::array<sim::BodyPose, kListBodies> bodies{};
  std::array<sim::ContactPoint, kListContacts> contacts{};  ///< Simulation::contactPoints()
};

/// A shm client counts as alive while its heartbeat is younger than this (CLOCK_MONOTONIC).
inline constexpr std::uint64_t kShmAliveTimeoutNs = 500'000'000;
/// The tick percentiles in the shm state are refreshed this often (ticks): a percentile scans
/// the histogram, too much work for every tick.
inline constexpr std::uint64_t kShmPercentileEveryTicks = 100;

/// A client's command (UDP or shared memory) for the servo's command gate: gated, from session
/// `session_id`, ordered by `sequence`; the pose (scene frame) only for kPose. The one place a
/// wire pose becomes the daemon's: the gate and the device work on the result. Any thread.
ServoCommand gatedCommand(CommandKind kind,
                          std::uint64_t session_id,
                          std::uint64_t sequence,
                          const proto::PoseCommand& pose) noexcept;

/// ServoState as the protocol's State::state_flags (armed, streaming, ramping). Any thread.
std::uint32_t wireStateFlags(const ServoState& st) noexcept;

/// One --record row (docs/architecture.md, records): scene frame, N, N m, m.
struct RecordRow {
  std::uint64_t tick = 0;
  double t_s = 0.0;
  geom::Pose X_W_device;
  geom::Pose X_W_proxy;
  geom::Vec3 force_n{0.0};
  geom::Vec3 torque_nm{0.0};
  std::uint32_t contacts = 0;
  std::uint32_t pairs_tested = 0;
  std::uint32_t pairs_skipped = 0;
  double max_penetration_m = 0.0;
  std::int64_t tick_ns = 0;
};

/// One --record-bodies row.
struct BodyRow {
  std::uint64_t tick = 0;
  double t_s = 0.0;
  std::uint64_t generation = 0;  ///< the scene (ServoScene::generation) the index refers to
  std::uint32_t body = 0;        ///< index into that scene's bodies
  geom::Pose X_WB;
};

/// Events the servo thread reports; formatted and logged by a normal thread.
enum class ServoEventKind : std::uint8_t {
  kDeviceLost,
  kDeviceBack,
  kMissFault,  ///< a = consecutive misses
  kNonFiniteForce,
  kStreamLost,  ///< the command gate latched stream_lost
  kArmed,
  kDisarmed,
  kSceneSwapped,  ///< a = generation
  kStopRampDone,
  kEndOfStream,
  kRecordDropped,  ///< first dropped row (later drops only count)
  kDeviceWriteFailed,
  kEditRefused,       ///< a = body, b = sim::EditStatus, c = list (0 poses, 1 added, 2 removed)
  kEditBatchDropped,  ///< a = the batch's generation, b = the running generation, c = batch id
  kDeviceFault,       ///< the device reported an error or came back (DeviceStatus::kFault)
};

struct ServoEvent {
  ServoEventKind kind = ServoEventKind::kDeviceLost;
  std::uint64_t tick = 0;
  std::int64_t a = 0;
  std::int64_t b = 0;
  std::int64_t c = 0;
};

/// Why run() returned.
enum class ServoExit : std::uint8_t { kStopped, kEndOfStream, kMaxTicks };

class ServoLoop {
 public:
  /// Allocates every ring. Off the servo thread. `clock` and `device` outlive the loop.
  ServoLoop(const ServoOptions& options,
            Clock& clock,
            device::Device& device,
            std::unique_ptr<ServoScene> initial_scene);
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  /// Servo thread, once, before run(): takes a scene already offered and calls its
  /// sim::Simulation::prepareThread() (the real simulation needs nothing per thread: its narrow
  /// phase's scratch belongs to its collision world). May allocate: it is the last step of the
  /// start, like the stack pre-faulting.
  void prepareServoThread();

  /// The loop, until stopped (after its ramp), the end of a replay stream, or max_ticks.
  /// Servo thread. A scene swapped in during the run is prepared at its tick boundary, which
  /// allocates only when it holds a larger polytope than any this thread has seen.
  /// With a device that owns the clock (device::Device::ownsClock(), openhaptics) each tick runs
  /// inside the device's scheduler callback (the device's thread is then the servo thread), with
  /// the same tick, guards and figures; the Clock given to the loop should then not sleep
  /// (DeviceClock).
  HAPTICD_SERVO_THREAD ServoExit run() noexcept;

  /// Any thread: ramp the force to zero, then leave run().
  void requestStop() noexcept { stop_requested_.store(true, std::memory_order_release); }

  /// Owner thread (the one producer). False when the ring is full (the command is dropped).
  bool sendCommand(const ServoCommand& command) noexcept { return commands_.push(command); }
  /// The edit ring's one producer thread. False when the ring is full (nothing queued).
  bool sendEdits(const EditBatch& batch) noexcept { return edits_.push(batch); }
  /// Edit batches waiting now (any thread, a snapshot) and the ring's capacity.
  std::size_t editsPending() const noexcept { return edits_.size(); }
  std::size_t editCapacity() const noexcept { return edits_.capacity(); }
  /// Serves shared memory: the servo thread drains `shm`'s command ring every tick into the
  /// command gate (gated, session from the segment), publishes a ShmState after every tick and
  /// beats. Only before run(); `shm` outlives the loop's run. nullptr: no shared memory.
  void attachShm(proto::ShmServer* shm) noexcept { shm_ = shm; }
  /// Owner thread: hands a new scene over; the servo thread takes it at the next tick boundary.
  void offerScene(std::unique_ptr<ServoScene> scene) { scenes_.offer(std::move(scene)); }
  /// Owner thread: frees the scene the servo thread replaced (call regularly).
  void reclaimScenes() { scenes_.reclaim(); }
  /// Owner thread: an offered scene has not been taken yet.
  bool sceneOfferPending() const { return scenes_.pending(); }

  /// Any thread.
  ServoState state() const noexcept { return state_.read(); }
  ServoLists lists() const noexcept { return lists_.read(); }
  const DurationHistogram& lateness() const noexcept { return lateness_; }
  const DurationHistogram& compute() const noexcept { return compute_; }
  std::int64_t periodNs() const noexcept { return period_ns_; }

  /// One consumer thread each.
  bool popEvent(ServoEvent& out) noexcept { return events_.pop(out); }
  bool popRecord(RecordRow& out) noexcept { return records_.pop(out); }
  bool popBody(BodyRow& out) noexcept { return bodies_.pop(out); }

  /// Changes ServoOptions::max_ticks (the total tick count at which run() returns). Only while
  /// run() is not running.
  void setMaxTicks(std::uint64_t ticks) { options_.max_ticks = ticks; }

  /// The scene the loop runs now. Only while run() is not running (before or after it).
  const ServoScene* currentScene() const { return current_; }

 private:
  // one period of run(): wait for the deadline, tick, count overruns; false when run() ends
  HAPTICD_SERVO_THREAD bool runPeriod() noexcept;
  HAPTICD_SERVO_THREAD static bool clockedTick(void* self) noexcept;
  // one tick, in order: takeInputs, readDevice, step, writeOutput, updateState, publish,
  // pushRecords
  HAPTICD_SERVO_THREAD void tick(std::uint64_t period_index, std::int64_t& tick_ns) noexcept;
  // commands, shm commands, the gate, the stop flag, a scene swap, edits: at the tick boundary
  HAPTICD_SERVO_THREAD void takeInputs(std::uint64_t now_ns) noexcept;
  // the device's pose (scene frame, into s_), lost / back
  HAPTICD_SERVO_THREAD device::DeviceStatus readDevice(double t_s,
                                                       device::DeviceSample& sample) noexcept;
  // the stream ended: zero force, no step, no record row
  HAPTICD_SERVO_THREAD void endStream(std::int64_t t0, std::int64_t& tick_ns) noexcept;
  // tells the device when the output is live (before the write) and when it is held at zero
  // (after the write of a zero force)
  HAPTICD_SERVO_THREAD void syncDeviceHold(bool after_write) noexcept;
  // the simulation's raw wrench through the one output stage (in the device frame) to the device
  HAPTICD_SERVO_THREAD void writeOutput(const sim::TickOutput& out, bool connected) noexcept;
  HAPTICD_SERVO_THREAD void updateState(const sim::TickOutput& out,
                                        double t_s,
                                        std::uint64_t period_index) noexcept;
  HAPTICD_SERVO_THREAD void pushRecords(double t_s, std::int64_t tick_ns) noexcept;
  // pushes a record row, waiting (virtual clock) or dropping and counting (real clock) when full
  template <class Row>
  HAPTICD_SERVO_THREAD bool pushRow(SpscRing<Row>& ring, const Row& row) noexcept;
  HAPTICD_SERVO_THREAD void drainCommands(std::uint64_t now_ns) noexcept;
  HAPTICD_SERVO_THREAD void applyCommand(const ServoCommand& cmd, std::uint64_t now_ns) noexcept;
  HAPTICD_SERVO_THREAD void drainShm(std::uint64_t now_ns) noexcept;
  HAPTICD_SERVO_THREAD void applyEdits() noexcept;
  HAPTICD_SERVO_THREAD void publishLists() noexcept;
  HAPTICD_SERVO_THREAD void publishShm(std::int64_t now_real_ns) noexcept;
  HAPTICD_SERVO_THREAD void applyGate(std::uint64_t now_ns) noexcept;
  // a pose command (scene frame) through the workspace mapping to the device
  HAPTICD_SERVO_THREAD void commandDevice(const device::PoseCommand& c_W) noexcept;
  HAPTICD_SERVO_THREAD void emit(ServoEventKind kind,
                                 std::int64_t a = 0,
                                 std::int64_t b = 0,
                                 std::int64_t c = 0) noexcept;
  // latches `fault` (FaultBits); true when it was not latched before (the caller logs it)
  HAPTICD_SERVO_THREAD bool latch(std::uint32_t fault) noexcept;

  ServoOptions options_;
  Clock& clock_;
  device::Device& device_;
  std::int64_t period_ns_;
  double period_s_;

  SpscRing<ServoCommand> commands_;
  SpscRing<EditBatch> edits_;
  SpscRing<ServoEvent> events_;
  SpscRing<RecordRow> records_;
  SpscRing<BodyRow> bodies_;
  PointerExchange<ServoScene> scenes_;
  Seqlock<ServoState> state_;
  Seqlock<ServoLists> lists_;
  DurationHistogram lateness_;
  DurationHistogram compute_;
  std::atomic<bool> stop_requested_{false};

  // servo-thread state
  // the gate on the daemon's own command (scene frame; the wire pose converted once, where it
  // enters: gatedCommand())
  proto::BasicCommandGate<device::PoseCommand> gate_;
  bool gate_used_ = false;  // a gated command arrived (the gate's scale then applies)
  ServoScene* current_ = nullptr;
  ServoState s_;
  ServoLists l_;  // the lists being built (a member: too big for the servo stack per tick)
  proto::ShmServer* shm_ = nullptr;
  proto::ShmState shm_state_{};
  std::uint64_t shm_p50_ns_ = 0, shm_p99_ns_ = 0;
  // the one output stage: every wrench for the device, its ramps and fades, its last output
  response::OutputStage output_;
  response::OutputFrame output_frame_;  // the workspace mapping's scene-to-device frame
  std::uint64_t run_period_index_ = 0;  // run()'s state (runPeriod())
  std::int64_t run_deadline_ = 0;
  ServoExit run_exit_ = ServoExit::kStopped;
  int device_held_ = -1;  // what the device was last told (setOutputHeld); -1: nothing yet
  bool end_of_stream_ = false;
  bool stop_done_ = false;
  bool record_drop_reported_ = false;
};

/// A one-line description of an event ("device lost at tick 1200"). Any thread; allocates.
std::string describe(const ServoEvent& event);

/// FaultBits by name, in bit order: "none", or e.g. "stream_lost,tick_overrun" (the names
/// hapticctl shows). Any thread; allocates.
std::string faultNames(std::uint32_t faults);

}  // namespace hapticd::daemon
