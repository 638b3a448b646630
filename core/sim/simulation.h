#pragma once
/// \file
/// One servo tick of the whole haptic simulation (docs/architecture.md "One servo tick"; §3.1, §6.1
/// of Gregory et al. 2000): probe pose in, proxy, collision, response (and dynamics when the
/// scene's plan asks), virtual coupling, force and torque out. The same code runs in the daemon,
/// in headless replay, in tests and in benchmarks.
///
/// This header is the contract between the simulation and the daemon: fields and functions may
/// be added, none renamed or removed.
///
/// Threads: create() off the servo thread (allocates); step() on the servo thread only (never
/// allocates, locks, logs or throws). A Simulation is owned by one thread at a time.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "core/common/result.h"
#include "core/geometry/pose.h"
#include "core/scene/scene.h"

namespace hapticd::collision {
class PairQueryMethod;
}  // namespace hapticd::collision

namespace hapticd::sim {

using geom::Pose;
using geom::Vec3;

/// Knobs of the response (config [response]); defaults: §5 of the paper and docs/response.md.
struct ResponseOptions {
  double stiffness_n_per_m = 600.0;  ///< k_s: 0.6 N/mm (§5.1)
  double tick_s = 0.001;             ///< Δt: 1 ms (§5.2)
  // the output limits: config [device] max_force_n, max_torque_nm, max_force_step_n,
  // max_torque_step_nm and [servo] ramp_in_s (one set for the whole daemon). The simulation
  // bounds the coupling's pull on the proxy by the device limits; the rest is the output stage's
  // (response::OutputStage, run by the caller: the servo loop, or withOutputStage() offline)
  double max_force_n = 10.0;         ///< device limit
  double max_torque_nm = 1.0;        ///< device limit
  double max_force_step_n = 0.5;     ///< F_max (§5.3): largest force change between ticks
  double max_torque_step_nm = 0.05;  ///< the same for torque
  /// Longest the force takes to ramp from zero to full at start, on arm and device back (s).
  double ramp_s = 0.5;

  // --- added by the response (docs/response.md lists every knob) ---
  /// The safe distance s (§5.2): no point of the held set moves farther than s in one proxy
  /// sub-step, and the broad phase looks twice that far, so that the proxy never passes a
  /// surface it has not seen. s = safe_distance_fraction * the probe body's radius: relative to
  /// the held body's size, the same in mm, m and km. The proxy takes as many sub-steps of at
  /// most s as it needs to reach its equilibrium with the device in one tick (at most
  /// max_substeps): in free space it follows the device within the tick whatever its speed, and
  /// the bound only limits travel toward contact (docs/response.md "The proxy").
  double safe_distance_fraction = 0.02;
  std::uint32_t max_substeps = 64;
  /// Deprecated (kept for configurations that set it): > 0 makes the safe distance absolute,
  /// max_speed_m_per_s * tick_s scene units per sub-step (before 2026-12-03: per tick, which made
  /// it a bound on the proxy's speed). 0: from safe_distance_fraction.
  double max_speed_m_per_s = 0.0;
  /// The predictive distance of §5.2 is delta = v_c * tick_s, v_c the current bound on the speed
  /// of the held body's points (from the device's motion, decaying with this time constant, s),
  /// clamped to [min_predictive_fraction * radius of the held body, the safe distance].
  double speed_decay_s = 0.02;
  double min_predictive_fraction = 1e-3;
  /// false: no predictive distance (δ = 0): force only on penetration, F = k_s D_p (§5.1). For the
  /// accuracy study; the default keeps §5.2's δ.
  bool predictive = true;
  /// The proxy's contact stiffness is this many times k_s; the coupling stiffness is then chosen
  /// so that the two in series give exactly k_s at the device (docs/response.md).
  double proxy_stiffness_ratio = 50.0;
  /// Coupling damping B = factor * K * tick_s (linear and rotational); B >= K tick_s / 2 is the
  /// sampled-spring passivity bound, so 1 keeps a factor 2 of margin.
  double coupling_damping_factor = 1.0;
  /// Rotational coupling stiffness (N m/rad); 0: k_c * r^2 with r the held body's radius.
  double rot_stiffness_nm_per_rad = 0.0;
  /// A proxy step that would leave the proxy deeper than this (scene units) is bisected back.
  /// 0: derived from the device and the stiffness, 1.5 times the proxy's penetration at the force
  /// limit, 1.5 max_force_n / (proxy_stiffness_ratio * stiffness_n_per_m) (0.5 mm at the
  /// defaults; it scales with the scene as the stiffness's units do).
  double penetration_allowance_m = 0.0;
  /// With dynamics: the held set's contacts with a dynamic body are the dynamics' (impulses,
  /// spread, felt through TickOutput::impact_force_W_n); its penalty rows act only once the held
  /// set is deeper than this fraction of penetration_allowance_m into the body (a body the
  /// dynamics cannot push away, wedged against something fixed): a backstop. 0: penalty rows
  /// from the surface, as for a fixed body (and the dynamics' impulses on top).
  double dynamic_backstop_fraction = 0.5;
  /// Force shading (§5.3): edges whose faces bend by less than this are smoothed; 0: off.
  double crease_angle_deg = 40.0;
  /// Buttons that attach the probe to the body it touches (§6.2) while held down.
  std::uint32_t attach_button_mask = 1u;
  /// The probe attaches to a body no farther than attach_distance_fraction of the probe body's
  /// radius (and never less than two safe distances: the proxy rests up to a safe distance from
  /// what it presses). attach_distance_m > 0 (deprecated, for configurations that set it): that
  /// absolute distance instead (scene units).
  double attach_distance_fraction = 0.1;
  double attach_distance_m = 0.0;
  /// How the probe attaches to a body on a hinge (§6.2): kAuto picks kCentre when the probe is
  /// within centre_radius_fraction of the body's radius from the axis, else kRim.
  enum class HingeAttach : std::uint8_t { kAuto, kRim, kCentre };
  HingeAttach hinge_attach = HingeAttach::kAuto;
  double centre_radius_fraction = 0.3;
  // --- added by the scene edits (docs/dynamics.md "A grabbed dynamic body's weight and inertia")
  /// With dynamics, a dynamic body grabbed rigidly (attach mode 1) is felt with its weight: m g
  /// (the scene's gravity times its gravity factor) at its centre of mass shifts the proxy's
  /// target by F / k_c (and the torque of the weight about the handle by T / k_r), so that in
  /// free space the hand carries m g and, set down on a table, the table does. false: not felt.
  bool grab_weight = true;
  /// ... and with its inertia: -m a and -(I α + ω × I ω) of the body rigidly at the device's
  /// pose, a and α the device's accelerations (second differences of its pose, low-passed with
  /// grab_inertia_filter_s), added to the hand's wrench before the output stage. false: off.
  bool grab_inertia = true;
  /// Time constant (s) of the one-pole low-pass on the device's accelerations; 0: unfiltered.
  double grab_inertia_filter_s = 0.010;
};

/// Everything the simulation needs besides the scene.
struct SimOptions {
  ResponseOptions response;
  /// Narrow-phase tests per tick (0: no limit). Pairs only, never a time budget: runs must be
  /// bitwise identical.
  std::uint32_t max_pairs_per_tick = 0;
  /// Radius (m) of the probe sphere used when the scene marks no probe body.
  double probe_sphere_radius_m = 0.01;
  /// With dynamics: the window (s) over which each impulse on the held body is spread as a
  /// force on the hand (DynamicsOptions::impulse_window_s; docs/dynamics.md has what it does to
  /// the force record). 0: one tick of force J / dt.
  double dynamics_impulse_window_s = 0.020;
  /// With dynamics: the whole-scene sleep (DynamicsOptions::sleep_time_s): still this long (s),
  /// with the held body touching no dynamic body, the dynamics skip their solve. 0: never.
  double dynamics_sleep_time_s = 0.5;
  /// With dynamics: sequential-impulse iterations per solve (DynamicsOptions::velocity_iterations;
  /// a solve may stop earlier once converged). More: stiffer stacks and contacts, more time per
  /// tick (docs/accuracy.md measures both). 1..1000.
  std::uint32_t dynamics_velocity_iterations = 12;
  /// With dynamics: split-impulse iterations of the drift correction per tick
  /// (DynamicsOptions::position_iterations). 0..1000; 0 turns the correction off.
  std::uint32_t dynamics_position_iterations = 6;
  /// With dynamics: a solve not converged after dynamics_velocity_iterations goes on while its
  /// error falls and still matters at the size of the smallest body of its island, up to this
  /// many iterations
  /// (DynamicsOptions::velocity_iterations_max: settling towers). 0..1000; at most
  /// dynamics_velocity_iterations: never beyond it.
  std::uint32_t dynamics_velocity_iterations_max = 100;
  /// With dynamics: the split impulses go on beyond dynamics_position_iterations while a resting
  /// frictionless contact's levelling still converges, up to this many
  /// (DynamicsOptions::position_iterations_max). 0..1000; at most dynamics_position_iterations:
  /// never beyond it.
  std::uint32_t dynamics_position_iterations_max = 30;
  /// Not null: another method answers every pair query (collision::WorldOptions::query_method):
  /// hapticstudy's methods inside the closed loop. Never set by the daemon. Not owned.
  collision::PairQueryMethod* query_method = nullptr;
};

/// One tick's input, in scene coordinates (after the device-to-scene workspace mapping).
struct TickInput {
  double t_s = 0.0;  ///< simulated time of this tick
  Pose X_W_device;   ///< target pose of the held body's origin
  std::uint32_t buttons = 0;
  bool device_ok = true;  ///< false: the device is lost or faulted: the wrench is zero
};

/// Status bits of a tick (TickOutput::flags). kTickRamping, kTickForceClamped, kTickStepLimited
/// and kTickNonFinite are the output stage's (response::OutputStage, outputFlags()): step() never
/// sets them; the servo loop and withOutputStage() add them.
enum TickFlags : std::uint32_t {
  kTickRamping = 1u << 0,       ///< force still ramping in
  kTickForceClamped = 1u << 1,  ///< the force hit a device limit
  kTickStepLimited = 1u << 2,   ///< the force step was limited by F_max
  kTickPairsSkipped = 1u << 3,  ///< the scheduler left close pairs untested
  kTickCapacityFull = 1u << 4,  ///< some fixed capacity was full: work was dropped, visibly
  kTickNonFinite = 1u << 5,     ///< the coupling gave NaN or Inf: zero was sent, the ramp restarted
  kTickBackedOff = 1u << 6,     ///< the proxy's step went too deep and was bisected back
  kTickDynamics = 1u << 7,      ///< the dynamics stepped this tick (never for a scene without them)
};

/// One tick's output, in scene coordinates.
struct TickOutput {
  /// The raw wrench on the hand (device): the coupling's, the dynamics' feedback and a grabbed
  /// body's inertia, not yet shaped. The caller passes it through the one output stage
  /// (response::OutputStage: clamp, ramps and fades, step limit) before a device sees it. N, N m.
  Vec3 force_W_n{0.0};
  Vec3 torque_W_nm{0.0};
  Pose X_W_proxy;  ///< the proxy's pose
  /// The held set's penalty rows within delta this tick (the contact points the response used;
  /// Simulation::contactPoints() lists them). Its contacts with bodies the dynamics move are
  /// held_dynamic_contacts.
  std::uint32_t contacts = 0;
  double max_penetration_m = 0.0;  ///< >= 0
  std::uint32_t pairs_tested = 0;
  std::uint32_t pairs_skipped = 0;
  /// The penetration depths of this tick's pair tests (collision::StepStats, docs/narrow-phase.md
  /// "In the collision world"): proven from the pair's depth tracker; its certificate failed
  /// (the full method ran); the tracker had no state yet (full method); penetrating pairs
  /// without a tracker (full or EPA method).
  std::uint32_t depth_certified = 0;
  std::uint32_t depth_fallbacks = 0;
  std::uint32_t depth_cold = 0;
  std::uint32_t depth_untracked = 0;
  std::uint32_t flags = 0;  ///< TickFlags
  /// TickInput::device_ok and a finite device pose: false when the device is lost or its pose is
  /// NaN or Inf (the proxy then holds and the wrench is zero); the output stage then cuts to zero
  /// at once and restarts its ramp (response::OutputInputs::device_ok).
  bool device_ok = true;
  // --- added by the response ---
  /// The penalty wrench of §5.1–5.2 on the proxy (about the held body's centre of mass): what
  /// the coupling balances at rest. World frame, N and N m.
  Vec3 contact_force_W_n{0.0};
  Vec3 contact_torque_W_nm{0.0};
  /// 0: free; 1: a body grabbed rigidly; 2: attached at a rim point; 3: attached at the centre.
  std::uint8_t attach_mode = 0;
  std::int32_t attached_body = -1;  ///< scene body index, -1: none
  /// The proxy did not reach its equilibrium with the device this tick: its last sub-step was
  /// still cut by the safe distance (max_substeps sub-steps taken, or one bisected back).
  bool travel_limited = false;
  std::uint32_t proxy_substeps = 0;  ///< proxy sub-steps taken this tick (>= 1)
  /// Friction at the probe (docs/response.md "Friction at the probe"), the last sub-step: the
  /// proxy stuck inside the friction cone, or slid on its edge.
  bool proxy_stuck = false;
  bool proxy_sliding = false;
  double delta_m = 0.0;  ///< this tick's predictive distance delta (scene units)
  // --- added by the dynamics integration (docs/dynamics.md "In the Simulation") ---
  /// The dynamics' feedback on the held set this tick: its contact and joint impulses with the
  /// bodies the dynamics move, spread over DynamicsOptions::impulse_window_s, added to the
  /// coupling's wrench before the output stage (torque about the handle point). N, N m, world.
  Vec3 impact_force_W_n{0.0};
  Vec3 impact_torque_W_nm{0.0};
  /// Contact points the dynamics took in this tick (0 without dynamics): all of the scene's.
  std::uint32_t dynamics_contact_points = 0;
  /// The held set's contact points with bodies the dynamics move (within delta at the proxy's
  /// pose this tick, before the dynamics step), which the dynamics' impulses answer rather than
  /// penalty rows; those deeper than the backstop, whose rows act, are in `contacts` instead. The
  /// daemon's contact count (the record's `contacts` column, the status) is the sum of the two.
  std::uint32_t held_dynamic_contacts = 0;
  // --- added by the scene edits: a grabbed dynamic body (ResponseOptions::grab_weight, _inertia)
  /// Its weight m g (N, world): what shifted the proxy's target this tick (felt through the
  /// coupling, so a surface the held set rests on carries it). Zero when nothing is grabbed.
  Vec3 grab_weight_W_n{0.0};
  /// Its inertial wrench (N, N m about the handle point, world), added to the hand's wrench.
  Vec3 grab_inertia_force_W_n{0.0};
  Vec3 grab_inertia_torque_W_nm{0.0};
};

/// The dynamics stage's state (Simulation::dynamicsStatus), for status and tests.
struct DynamicsStatus {
  bool active = false;              ///< the scene's plan has dynamics (a dynamic body exists)
  std::uint64_t ticks = 0;          ///< ticks the dynamics did work
  std::uint64_t ticks_asleep = 0;   ///< ticks skipped because the scene was at rest
  double kinetic_energy_j = 0.0;    ///< of the dynamic bodies (J)
  double potential_energy_j = 0.0;  ///< in the scene's gravity (J, zero at the origin)
};

/// The pose of one non-static body (for --record-bodies and the state stream).
struct BodyPose {
  std::uint32_t body = 0;  ///< index into SceneModel::bodies
  Pose X_WB;
};

/// One contact point of the held set after the last step (for the state stream).
struct ContactPoint {
  Vec3 p_W{0.0};            ///< contact point, scene frame
  Vec3 n_W{0.0, 0.0, 1.0};  ///< unit normal pushing the held set out
  double depth_m = 0.0;     ///< penetration depth (> 0 penetrating, < 0 a gap inside delta)
  std::int32_t body = -1;   ///< scene index of the other body, -1 if unknown
};

/// The answer of a scene edit (Simulation::setKinematicPose, setBodyActive).
enum class EditStatus : std::uint8_t {
  kOk,
  kUnsupported,   ///< this implementation does not edit scenes
  kNoSuchBody,    ///< index out of range
  kNotKinematic,  ///< a pose for a body that is not kinematic
  kStaticBody,    ///< static bodies are never added, removed or moved
  kHeldBody,      ///< the probe (held) body cannot be moved, added or removed by a client
  kInactive,      ///< a pose for a body that is not active (add it first)
  kNotFinite,     ///< a pose with NaN or Inf, or a quaternion that is not unit
};

/// A name for an EditStatus ("not a kinematic body"). Any thread; inline, so that code which
/// does not link the simulation (the servo loop with test fakes) names it the same way.
inline const char* toString(EditStatus s) {
  switch (s) {
    case EditStatus::kOk:
      return "ok";
    case EditStatus::kUnsupported:
      return "scene edits not supported";
    case EditStatus::kNoSuchBody:
      return "no such body";
    case EditStatus::kNotKinematic:
      return "not a kinematic body";
    case EditStatus::kStaticBody:
      return "a static body";
    case EditStatus::kHeldBody:
      return "the held (probe) body";
    case EditStatus::kInactive:
      return "not active (add it first)";
    case EditStatus::kNotFinite:
      return "not a finite pose with a unit quaternion";
  }
  return "unknown";
}

/// What a scene swap's prewarm did (Simulation::prewarm, sim::prewarmState).
struct PrewarmReport {
  std::uint32_t collision_steps = 0;  ///< collision steps run off the servo thread
  std::uint32_t dynamics_steps = 0;   ///< dynamics steps run off the servo thread
  bool at_rest = false;  ///< the dynamics were still: the scene sleeps from its first tick
};

/// Cold work done so far: what a new scene's first ticks do once and later ticks should not
/// (collision::CollisionWorld::coldCounters). A scene swap's prewarm does it off the servo
/// thread; the swap test (tests/daemon/scene_swap_test.cpp) reads these before and after.
struct ColdWork {
  std::uint64_t cold_queries = 0;       ///< pair queries with no cache yet (a pair's first)
  std::uint64_t full_sorts = 0;         ///< boxes sorted into the broad phase's lists
  std::uint64_t position_rebuilds = 0;  ///< whole passes rebuilding the broad phase's positions
};

struct SimModel;
struct SceneState;

/// The façade the daemon drives: a compiled model (core/sim/model.h) and its per-tick state
/// (core/sim/scene_state.h), stepped by sim::step (the functions underneath, for tests and tools
/// that copy or compare states).
class Simulation {
 public:
  /// Builds the per-scene pipeline (only the stages the scene's plan asks for) and every capacity
  /// step() needs, so that step() never allocates. Off the servo thread.
  static Result<std::unique_ptr<Simulation>> create(std::shared_ptr<const scene::SceneModel> scene,
                                                    const SimOptions& options);
  virtual ~Simulation() = default;

  /// One tick. Servo thread only; no allocation, no lock, no log, no throw.
  virtual TickOutput step(const TickInput& input) = 0;

  /// Poses of every non-static body after the last step (ordered by body index).
  virtual std::span<const BodyPose> bodyPoses() const = 0;

  /// Forces fade to zero and ramp in again from there. The ramp is the output stage's now
  /// (response::OutputStage, run after step() by the caller): the simulation has none, so the
  /// default does nothing; withOutputStage()'s restarts its stage's. Servo thread.
  virtual void restartRamp() {}

  virtual const scene::SceneModel& scene() const = 0;

  /// The dynamics stage's counters and energy (all zero for a scene without dynamics). Servo
  /// thread, or the owner thread between steps. Not pure, so that other implementations (test
  /// fakes) need not define it: the default reports no dynamics.
  virtual DynamicsStatus dynamicsStatus() const { return {}; }

  /// Prepares the calling thread for step(). The simulation needs nothing per thread any more
  /// (the narrow phase's scratch belongs to the state's collision world, sized at create():
  /// core/collision/penetration.h), so step() allocates nothing from its first tick; the servo
  /// loop still calls it once on its thread before the first step(), which costs nothing and
  /// keeps other implementations free to need it. May allocate.
  virtual void prepareThread() = 0;

  // --- scene edits (protocol SceneUpdate; issue 6 "kinematic bodies moved by clients") ---
  // All servo thread, between steps; no allocation, lock or log. An edit takes effect in the
  // next step(). The defaults (test fakes) refuse with kUnsupported.

  /// Moves kinematic body `body` (scene index) to X_WB by the end of the next step: the collision
  /// world sees it there, and the dynamics move it with the velocity that takes it there in one
  /// tick (so that it pushes dynamic bodies and the proxy instead of teleporting through them).
  virtual EditStatus setKinematicPose(std::uint32_t body, const Pose& X_WB) {
    (void)body;
    (void)X_WB;
    return EditStatus::kUnsupported;
  }
  /// Makes body `body` (scene index, kinematic or dynamic, not the probe) active at X_WB (its
  /// velocity zero), or inactive (`active` false; X_WB ignored): an inactive body neither
  /// collides nor moves nor appears in bodyPoses()' contacts. Adding an active body moves it.
  /// bodyPoses() keeps listing an inactive body at its last pose (bodyActive() tells which);
  /// what rested on a removed body falls (docs/dynamics.md "Scene edits").
  virtual EditStatus setBodyActive(std::uint32_t body, bool active, const Pose& X_WB) {
    (void)body;
    (void)active;
    (void)X_WB;
    return EditStatus::kUnsupported;
  }
  /// Whether body `body` (scene index) is active now.
  virtual bool bodyActive(std::uint32_t body) const {
    (void)body;
    return true;
  }
  /// The held set's contact points after the last step (at most a fixed capacity, in the order
  /// the response used them). Servo thread or the owner between steps.
  virtual std::span<const ContactPoint> contactPoints() const { return {}; }

  // --- scene swaps without a hiccup (issue 18; docs/architecture.md "Scene swaps") ---
  /// Runs what the scene's first ticks would compute cold (sim::prewarmState): its first
  /// queries at the device's pose, the broad phase's tables, and with dynamics its first steps,
  /// a scene found at rest put to sleep. X_W_device: where the device is now (scene frame, after
  /// the workspace mapping), or none (the scene's own probe pose). Off the servo thread, once,
  /// before the first step() (the daemon's builder, before handing the scene over). The
  /// default (test fakes) does nothing.
  virtual PrewarmReport prewarm(const std::optional<Pose>& X_W_device) {
    (void)X_W_device;
    return {};
  }
  /// The cold work done so far (all zero for implementations without it). The owner thread,
  /// between steps; no allocation.
  virtual ColdWork coldWork() const { return {}; }

  // --- the model apart from the state (docs/architecture.md "Model apart from state") ---
  /// The compiled model and the state after the last step (for a copy, a comparison or the
  /// hash). nullptr for implementations without them (test fakes). The owner thread, between
  /// steps.
  virtual const SimModel* model() const { return nullptr; }
  virtual const SceneState* state() const { return nullptr; }
  /// sim::stateHash(*state()): the determinism hash of the state after the last step (0 without
  /// a state). The owner thread between steps; no allocation.
  std::uint64_t stateHash() const;
};

}  // namespace hapticd::sim
