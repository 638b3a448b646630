#pragma once
/// \file
/// The per-tick state of the simulation apart from its model (docs/architecture.md "Model apart
/// from state"; MuJoCo's mjModel / mjData): everything one tick reads and writes, and the tick
/// itself as a function of the compiled model (core/sim/model.h), the state and the input:
///
///     TickOutput step(const SimModel&, SceneState&, const TickInput&)
///
/// A SceneState can be copied (off the servo thread: a copy allocates; it keeps every capacity,
/// so that stepping the copy allocates nothing either), compared (operator==) and hashed
/// (stateHash()). The hash and the comparison cover every field below that a later tick reads:
/// the collision world's poses, boxes, sweep-and-prune lists, pair states with their feature and
/// depth caches and last answers, and contacts; the dynamics' bodies, joints' warm starts, warm
/// contact points, impulse spreader, feedback, sleep and counters; the coupling's memory; the proxy
/// and its parameters; the contact rows; the held set, attach and grab state; the device's speed
/// tracking; scene edits pending. Not covered: the shapes (the model's), per-tick scratch that a
/// step rewrites before reading (the scheduler's order, the broad phase's event lists, the
/// dynamics' contact points and restitution scratch) and the hash maps that index hashed lists
/// (their layout depends on capacity, not on the run). Doubles are hashed by their bits: two states
/// are equal only if bitwise equal.
///
/// Threads: makeState() and copies off the servo thread; step() and the edits on the thread that
/// owns the state (the servo thread): no allocation, lock, log or throw.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/collision/collision_world.h"
#include "core/common/reserved_vector.h"
#include "core/common/result.h"
#include "core/dynamics/dynamics.h"
#include "core/response/coupling.h"
#include "core/response/proxy.h"
#include "core/sim/model.h"
#include "core/sim/simulation.h"

namespace hapticd {
class StateWriter;
}

namespace hapticd::sim {

/// How the probe holds what it attached to (TickOutput::attach_mode).
enum class AttachMode : std::uint8_t { kFree = 0, kGrab = 1, kRim = 2, kCentre = 3 };

/// No body (a world id).
inline constexpr std::uint32_t kNoBody = 0xffffffffu;

/// The held set: the probe body first, then the body it is attached to (§6.2).
struct HeldSet {
  std::array<std::uint32_t, 2> ids{};  ///< world ids
  std::uint32_t count = 1;
  AttachMode mode = AttachMode::kFree;
  std::uint32_t attached = kNoBody;
  geom::Transform X_probe_attached;  ///< kGrab: the attached body in the probe's frame
  geom::Transform X_attached_probe;  ///< kRim: the probe in the attached body's frame
  geom::Quat q_attached_probe{1.0, 0.0, 0.0, 0.0};  ///< kCentre: the probe's rotation in the body
  Vec3 centre_h_W{0.0};                             ///< kCentre: the fixed handle point
  Vec3 hinge_o_W{0.0}, hinge_a_W{0.0};              ///< kRim, kCentre: the hinge, world
  double radius_m = 0.0;                            ///< largest distance of a held point
  std::uint32_t last_buttons = 0;
};

/// A dynamic body grabbed rigidly (kGrab), felt with its weight and inertia
/// (ResponseOptions::grab_weight, grab_inertia). mass 0: nothing of the kind is grabbed.
struct GrabState {
  double mass = 0.0;
  Vec3 gravity_W{0.0};
  Vec3 com_B{0.0};
  geom::Mat3 inertia_B{0.0};
  Vec3 r_P{0.0};                      ///< its centre of mass from the handle point, probe frame
  std::uint32_t history = 0;          ///< device poses seen since the grab (up to 2)
  Vec3 c1{0.0}, c2{0.0};              ///< the device-side centre of mass, last two ticks
  geom::Quat q1{1.0, 0.0, 0.0, 0.0};  ///< the device's rotation, last tick
  Vec3 w1{0.0};                       ///< the device's angular velocity, last tick
  Vec3 a_f{0.0}, alpha_f{0.0};        ///< low-passed accelerations
};

/// The device's motion as the predictive distance tracks it (§5.2).
struct DeviceTrack {
  bool have_prev = false;
  Vec3 prev_h_W{0.0};
  geom::Quat prev_q{1.0, 0.0, 0.0, 0.0};
  double v_c = 0.0;  ///< current bound on the speed of the held body's points
};

/// Bodies on a hinge to the scene that the held set may turn (quasi-static coordinates).
struct DrivenHinges {
  std::array<std::uint32_t, response::ProxyProblem::kMaxDriven> ids{};
  std::uint32_t count = 0;
  std::array<geom::Pose, response::ProxyProblem::kMaxDriven> before{};  ///< this tick's start
};

/// Everything one tick reads and writes. Made by makeState(); see the file comment.
struct SceneState {
  collision::CollisionWorld world;
  /// Present exactly when the model's plan has dynamics.
  std::optional<dynamics::Dynamics> dynamics;
  response::VirtualCoupling coupling{response::CouplingParams{}};
  response::ProxyParams proxy;
  geom::Pose X_W_probe;             ///< the proxy: the probe body's pose
  double delta_m = 0.0;             ///< this tick's predictive distance
  double last_penetration_m = 0.0;  ///< of the rows at the current proxy pose
  /// The deepest pair's normal at the current proxy pose, out of its environment side, when that
  /// pair is the held set's (else zero): the direction a sub-step too deep is pushed back along
  Vec3 deepest_normal_W{0.0};
  bool proxy_sliding = false;  ///< the proxy slid with friction in its last step
  bool first_step = true;
  response::ContactRows rows;
  ReservedVector<std::uint32_t> row_env;        ///< per row: the environment body's world id
  ReservedVector<ContactPoint> contact_points;  ///< Simulation::contactPoints()
  std::vector<BodyPose> body_poses;             ///< Simulation::bodyPoses()
  /// body_poses are to be read again for every body at the next tick (not only for those the
  /// collision world says were given a pose: CollisionWorld::posed()).
  bool body_poses_stale = false;
  std::vector<std::uint8_t> active;  ///< per world body: 1 in the scene (edits)
  /// An edit changed the collision world since the last rows: the next step runs the collision
  /// step once before the proxy's, so that the proxy sees the edit.
  bool world_dirty = false;
  /// With dynamics: a kinematic target given to the dynamics, which move the body in this
  /// tick's dynamics step (the collision world sees it from the next tick on).
  bool kinematic_target_pending = false;
  /// Per world body: how far (scene units) setKinematicPose moved its points since the last
  /// collision step that saw it (raises the proxy's travel bound when it pushes the held set).
  std::vector<double> edit_travel;
  HeldSet held;
  GrabState grab;
  DeviceTrack device;
  DrivenHinges driven;

  /// Writes every field the file comment lists, in a fixed order.
  void writeState(StateWriter& w) const;
};

/// The state at the start (the scene's poses, the proxy at the probe body, everything at rest),
/// with every capacity step() needs. Errors: what the dynamics refuse (a dynamic body without a
/// positive mass, a joint out of range). Off the servo thread.
Result<SceneState> makeState(const SimModel& model);

/// Steps of the collision world and the dynamics a prewarm runs at most, and the still steps in
/// a row after which it stops and the scene sleeps (prewarmState).
inline constexpr std::uint32_t kMaxPrewarmSteps = 32;
inline constexpr std::uint32_t kPrewarmStillSteps = 4;

/// A scene swap's prewarm (docs/architecture.md "Scene swaps"), on a state makeState() just made,
/// off the servo thread: what the scene's first ticks would compute cold is done here, so that
/// the servo thread's swap is a pointer exchange and its first ticks cost what later ones do
/// (the CollisionWorld's ColdCounters do not move on them while the device stays put):
///  - a probe sphere (the scene marks no probe body) is placed at X_W_device, as the first tick
///    places it, and the collision step runs there: every pair the first ticks test has its
///    cache (no pair query starts cold on the servo thread);
///  - with dynamics: steps of the collision world and the dynamics, the held body standing
///    where it is, until the scene has been still kPrewarmStillSteps steps in a row (at most
///    kMaxPrewarmSteps); a scene still then sleeps at once (Dynamics::sleepIfStill) instead of
///    solving every tick for sleep_time_s; one still moving is handed over with its contacts and
///    warm starts, those steps of simulated time later;
///  - the broad phase's position tables rebuilt (CollisionWorld::prewarm), the rows gathered.
/// The proxy, the coupling and the device tracking are untouched: the first tick starts as it
/// would without the prewarm. No X_W_device (or one not finite): the probe stays at its pose.
PrewarmReport prewarmState(const SimModel& model,
                           SceneState& state,
                           const std::optional<geom::Pose>& X_W_device);

/// The state's cold work so far (collision::CollisionWorld::coldCounters). Any thread that may
/// read the state; no allocation.
ColdWork coldWork(const SceneState& state);

/// One tick. The thread that owns `state`; no allocation, lock, log or throw.
TickOutput step(const SimModel& model, SceneState& state, const TickInput& input);

/// The scene edits (Simulation::setKinematicPose, setBodyActive); take effect in the next step.
EditStatus setKinematicPose(const SimModel& model,
                            SceneState& state,
                            std::uint32_t body,
                            const Pose& X_WB);
EditStatus setBodyActive(const SimModel& model,
                         SceneState& state,
                         std::uint32_t body,
                         bool active,
                         const Pose& X_WB);

/// The dynamics' counters and energy (all zero without dynamics).
DynamicsStatus dynamicsStatus(const SimModel& model, const SceneState& state);

/// A stable 64-bit hash (FNV-1a, core/common/state_writer.h) of everything writeState() writes:
/// equal states hash equal in every run and process. Any thread that may read the state; no
/// allocation.
std::uint64_t stateHash(const SceneState& state);

/// Bitwise equality of everything writeState() writes. Allocates (off the servo thread).
bool operator==(const SceneState& a, const SceneState& b);

}  // namespace hapticd::sim
