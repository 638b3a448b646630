#pragma once
/// \file
/// Impulse-based rigid-body dynamics for the bodies a scene declares dynamic (Mirtich & Canny,
/// "Impulse-based simulation of rigid bodies", I3D 1995; §6.1–6.2 of Gregory et al. 2000).
///
/// One tick (step()):
///  1. external forces: gravity where the scene declares it (SceneModel::gravity_W times each
///     body's gravity_factor), per-body external wrenches and the held body's input; velocities
///     first (semi-implicit Euler). Rotation carries the angular momentum L through the step by
///     the free-rigid-body splitting (McLachlan 1993, Touma & Wisdom 1994: exact rotations about
///     the principal axes, composed symmetrically; quaternions normalised), so the gyroscopic
///     term never blows up (|ω| <= |L| / I_min) and the energy error stays bounded;
///  0. islands touched by something that moves wake (sleep is per island, step 6);
///  2. constraints from the CollisionWorld's contacts (manifold points, close but separated ones
///     included; persistent: a point of last tick that the manifold does not name again is kept
///     while its two surface points stay together, so a resting box keeps its four corners) and
///     from the scene's joints (fixed, hinge with limits, the general joint);
///  3. the time-of-impact loop of §6.1: for every contact point the time at which its gap closes
///     is estimated from the relative velocity, the normal and the distance; all bodies advance to
///     the earliest, the impulses there (restitution, Coulomb friction, joints; sequential
///     impulses, Catto 2005; restitution by Poisson's hypothesis, scaled down if needed so that
///     no solve adds energy) are applied, and the loop goes on with the rest of the tick, at most
///     DynamicsOptions::max_toi_substeps times (then the remaining approaching points are treated
///     speculatively for the rest of the tick and kStepToiCapped is set);
///  4. drift correction: split impulses (pseudo-velocities that move poses but add no energy) for
///     penetration beyond a slop relative to the bodies' size and for joint error. Split
///     impulses rather than Baumgarte (a velocity bias: adds energy, stacks jitter) or soft
///     constraints with sub-steps (several solves per tick: too costly at 1 kHz). A frictionless
///     resting point may also close toward the slop's depth in the velocity solve (20% per
///     tick, no faster than the restitution threshold), so a body's resting points settle at
///     one depth and a frictionless box rests flat instead of sliding off the tilt its first
///     ticks gave it; a resting frictionless flat contact pressed at every point is levelled
///     from the bottom up at the end of the tick (levelSweep: the upper body's pose turned, and
///     the bodies' relative turn about its tangents taken out of the velocities by a couple);
///  5. new poses written back with CollisionWorld::setPose (its next step() sees them; a
///     sleeping body's are not);
///  6. sleep per island: contacts and joints join dynamic bodies into islands; an island at rest
///     for sleep_time_s sleeps, the whole scene when every island does.
///
/// Tolerances, all relative (docs/dynamics.md, "One tick"): slop 0.2% of the smaller body's
/// size (radius about its centre of mass), at most |gravity| * (8 ms)^2; touching: a quarter of the
/// slop; point persistence 2% and warm-start matching 5% of the size; restitution and
/// static-friction threshold max(4 ticks of gravity, 1% of the size per second); travel per tick <=
/// max(box margin, 50% of the size); still (sleep): slower than 0.1% of the size per second.
///
/// Threads and memory: create() off the servo thread (allocates every capacity); step(),
/// setKinematicPose(), setExternalWrench() and the getters on the servo thread: no allocation, no
/// lock, no log, no throw. A Dynamics is owned by one thread at a time.
///
/// Units: any consistent set (SI in the scene model: metres, kilograms, seconds, radians); every
/// tolerance is relative to the bodies' sizes or to the tick, so a scene in millimetres gives the
/// same relative motion. Frames: W = scene, B = body origin (SceneModel::Body::X_WB).

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "core/collision/collision_world.h"
#include "core/common/reserved_vector.h"
#include "core/common/result.h"
#include "core/common/state_writer.h"
#include "core/dynamics/impulse_spreader.h"
#include "core/dynamics/scene_world.h"
#include "core/geometry/mass_properties.h"
#include "core/geometry/pose.h"
#include "core/scene/scene.h"

namespace hapticd::dynamics {

using geom::Mat3;
using geom::Pose;
using geom::Quat;
using geom::Vec3;

/// Knobs of the dynamics; every default documented here and in docs/dynamics.md.
struct DynamicsOptions {
  /// Sequential-impulse iterations per solve (each time of impact solves once).
  std::uint32_t velocity_iterations = 12;
  /// A solve stops early (after at least 2 iterations) once no row corrects a velocity error
  /// above this fraction of the restitution threshold below (0: always all iterations).
  double velocity_tolerance_fraction = 1e-7;
  /// Split-impulse iterations of the drift correction at the end of the tick.
  std::uint32_t position_iterations = 6;
  /// Settling. A solve that has not converged after velocity_iterations goes on while its
  /// residual still falls and would still move a body by more than settle_tolerance_fraction
  /// of the smallest body's size of its island in a tick (each contact's residual relative to
  /// the slop's length of its island), up to this many iterations (the first ticks of an
  /// offset or mass-graded tower, whose load crosses many contacts: the error left is of order
  /// g dt, which is a large part of a small body's size). At most velocity_iterations: none.
  std::uint32_t velocity_iterations_max = 100;
  /// Likewise the split impulses: beyond position_iterations while the levelling of a resting
  /// frictionless flat contact still changes (its largest correction falls), up to this many.
  /// A frictionless stack has nothing else that holds its boxes over each other: a levelling
  /// left unconverged each tick grows a shear from rounding. At most position_iterations: none.
  std::uint32_t position_iterations_max = 30;
  /// The settling iterations' tolerance (above), a fraction of the smallest body's size of the
  /// island per tick.
  double settle_tolerance_fraction = 1e-6;
  /// The settling iterations of a tick (both kinds, all solves) solve at most this many rows
  /// (contact points and joints, once per iteration) beyond the fixed counts: a bound on the
  /// tick's extra work whatever the scene's size.
  std::uint32_t settle_row_budget = 4096;
  /// Time-of-impact substeps per tick beyond the first solve (§6.1); when the cap is hit the
  /// remaining approaching contacts are solved speculatively and kStepToiCapped is set.
  std::uint32_t max_toi_substeps = 8;
  /// Allowed penetration (slop), as a fraction of the smallest size (Polytope::radius of its
  /// primitives) among the dynamic bodies of the contact's island (the bodies its tick's contact
  /// points join), or of its smaller body's if that is smaller; below it no position correction
  /// acts, so resting contact stays put. One slop for a whole stack, not each contact's own: a
  /// box bridging two supports of different sizes rested on contacts of different depths, tilted,
  /// and without friction slid off (a running-bond wall's half bricks at the ends of its rows:
  /// thrown off the floor at 5 mm and 10 cm). Per island, not for the scene: a slop far below
  /// the bodies' own (0.1 of it) let a frictionless wall fall, and a bead on the floor would
  /// have set it for every stack.
  double slop_fraction = 0.002;
  /// ... and at most |gravity| * slop_settle_time_s^2 (the largest acceleration declared, as
  /// restitution_threshold_ticks reads it; 0: no such bound). A resting frictionless point
  /// closes toward the slop at no more than the restitution threshold, so a deep slop (large
  /// bodies: over about 0.3 m under 9.81 m/s2) took a stack ~90 ticks to sink into, its top
  /// falling at rows x that speed, and stopped it all at once: the stop's uneven shares turned
  /// the bricks of a frictionless wall, which then slid apart. Within this bound a stack settles
  /// from the bottom up in ~20 ticks. In seconds, not ticks: the same slop at every rate.
  double slop_settle_time_s = 0.008;
  /// Fraction of the penetration (beyond the slop) or joint error removed per tick.
  double position_correction = 0.2;
  /// Restitution acts only when the closing speed exceeds this many ticks' worth of the
  /// largest acceleration declared (|gravity_W| * gravity_factor) ...
  double restitution_threshold_ticks = 4.0;
  /// ... or this fraction of the smaller body's size per second, whichever is larger.
  double restitution_threshold_fraction = 0.01;
  /// Static friction applies while the tangential speed is below this fraction of the
  /// restitution threshold; dynamic friction above it.
  double static_friction_speed_fraction = 1.0;
  /// No tunnelling: a body travels at most max(its box margin in the world, this fraction of
  /// its size) per tick, its speed (and spin) clamped beyond (kStepSpeedClamped, counted).
  /// Contacts are found within the margins before they touch (time of impact) and, for faster
  /// bodies, on the tick they overlap (then resolved from the overlap). A free dynamic body's
  /// margin follows its speed (freeBodyMargin, core/dynamics/scene_world.h): at least 10% of its
  /// size, twice its travel in a tick, at most the world's box margin.
  double max_travel_fraction = 0.5;
  /// A free dynamic body's boxes grow by a margin of its own size and speed (freeBodyMargin,
  /// docs/dynamics.md "Margins of their own"); false: by the world's box margin, as every body's
  /// did before 2026-12-06 (for comparison: Dynamics/small_parts).
  bool body_margins = true;
  /// Persistent contact points: a point of last tick that the collision manifold does not name
  /// again is kept while its two surface points stay within this fraction of the smaller body's
  /// size of each other (along the contact plane and across it); a new point that near one of
  /// last tick's takes its impulses (warm start; shared equally when several take the same
  /// one). At most 4 points per primitive pair.
  double contact_persist_fraction = 0.02;
  /// Contact points the solver may hold per tick; 0 picks 16 per moving primitive + 64.
  /// Overflow drops points (kStepCapacityFull, counted), never allocates: the farthest
  /// contacts' first (the contacts nearest to touching, or deepest, are taken while they fit).
  std::uint32_t max_contact_points = 0;
  /// Sleep, per island: contacts (touching, between dynamic bodies) and joints join dynamic
  /// bodies into islands; an island whose every body has moved slower than
  /// sleep_speed_fraction of its size per second for sleep_time_s sleeps (velocities zeroed;
  /// its bodies take no part in the ticks, as if of infinite mass, and their poses are not
  /// given to the world again). It wakes when a body that moves (an awake dynamic body, the
  /// held body or a driven one moving, a kinematic body with a target or a velocity) has a
  /// contact within the world's box margin with one of its bodies, or when an external wrench
  /// is set on one of them. A kinematically held body touching a body keeps that body's
  /// island awake. When every island sleeps the whole scene sleeps (steps do nothing) until
  /// the held body's input, a kinematic target or an external wrench could move something; in
  /// free space the held body is taken to its target while the scene sleeps. Bodies held by a
  /// joint with a velocity drive never sleep. 0 s: never sleep.
  double sleep_time_s = 0.5;
  double sleep_speed_fraction = 1e-3;
  /// For a scene without a probe body (SceneModel::probe_body < 0) whose Simulation adds a probe
  /// of its own to the world (a sphere from config) right after the scene's bodies: that body's
  /// world id, which must be the scene's body count. It is then the held body, of infinite
  /// mass, moved by HeldInput::kKinematic. -1: none.
  std::int32_t extra_probe_body = -1;
  /// Window (s) over which each impulse on the held body is spread as a force (Hann profile:
  /// peak 2 J / window, integral J). 0: the impulse is returned as one tick of force J / dt.
  double impulse_window_s = 0.020;
  /// Servo tick (s) the spreader is built for; step() takes its dt per call.
  double tick_s = 0.001;
  /// The held body (and the bodies driven with it, setDriven) pushes dynamic bodies with at most
  /// this force (N), shared equally by its contact points (a cap on each point's normal impulse
  /// per solve of held_max_force_n * dt / points): the hand cannot push harder than the device
  /// can render, and a body wedged between the held body and something fixed is not squeezed
  /// out at high speed. 0: unlimited (an infinite-mass pusher). The Simulation sets it to the
  /// device's force limit.
  double held_max_force_n = 0.0;
};

/// How the held body (SceneModel::probe_body) is driven this tick.
enum class HeldMode : std::uint8_t {
  kNone,       ///< as the scene says (dynamic bodies integrate, kinematic ones keep their pose)
  kWrench,     ///< a dynamic held body receives force_W_n / torque_W_nm (at its centre of mass)
  kKinematic,  ///< the held body follows X_WB_target: infinite mass this tick, pushes others
};

/// Per-tick input for the held body, in scene coordinates.
struct HeldInput {
  HeldMode mode = HeldMode::kNone;
  Vec3 force_W_n{0.0};    ///< kWrench: force at the centre of mass (N)
  Vec3 torque_W_nm{0.0};  ///< kWrench: torque (N m)
  Pose X_WB_target;       ///< kKinematic: pose of the body origin at the end of the tick
};

/// What the held body received this tick, in scene coordinates.
struct HeldFeedback {
  /// Sum of the contact and joint impulses on the held body this tick (N s), and their moment
  /// about its centre of mass (N m s). Gravity and the input wrench are not included.
  Vec3 impulse_W_ns{0.0};
  Vec3 angular_impulse_W_nms{0.0};
  /// The same spread over DynamicsOptions::impulse_window_s (ImpulseSpreader): the force and
  /// torque to render this tick so that the impacts can be felt (N, N m).
  Vec3 force_W_n{0.0};
  Vec3 torque_W_nm{0.0};
  Vec3 com_W{0.0};  ///< the held body's centre of mass the moments are taken about
};

/// Status bits of a step (StepReport::flags).
enum StepFlags : std::uint32_t {
  kStepToiCapped = 1u << 0,      ///< max_toi_substeps was reached
  kStepCapacityFull = 1u << 1,   ///< contact points were dropped (max_contact_points)
  kStepSpeedClamped = 1u << 2,   ///< a body's speed was clamped (max_travel_fraction)
  kStepStaleContacts = 1u << 3,  ///< some contacts were answers of earlier ticks (scheduler)
  kStepAsleep = 1u << 4,         ///< the scene was at rest: the step did no work
};

/// Figures of one step.
struct StepReport {
  std::uint32_t contact_points = 0;       ///< manifold points taken into the solver
  std::uint32_t active_points = 0;        ///< of them, touching by the end of the tick
  std::uint32_t impulse_points = 0;       ///< of them, given a normal impulse this tick
  std::uint32_t toi_substeps = 0;         ///< times of impact advanced to (0: none this tick)
  std::uint32_t velocity_iterations = 0;  ///< sequential-impulse iterations run, all solves
  std::uint32_t flags = 0;                ///< StepFlags
};

/// Counters since create().
struct DynamicsCounters {
  std::uint64_t ticks = 0;           ///< steps that did work (0 for a scene without dynamics)
  std::uint64_t toi_capped = 0;      ///< steps that hit max_toi_substeps
  std::uint64_t points_dropped = 0;  ///< contact points dropped for capacity
  std::uint64_t speed_clamped = 0;   ///< body-ticks whose speed was clamped
  std::uint64_t ticks_asleep = 0;    ///< steps skipped because the scene was at rest
};

/// Mass properties (mass, centre of mass, inertia about it in the body frame).
using geom::MassProperties;

/// Volume, centre of mass and inertia of a body's primitives at a density (kg/m^3 in SI):
/// geom::polytopeIntegrals summed over them (the primitives are assumed not to overlap), then
/// geom::massFromIntegrals. Any thread.
MassProperties computeMassProperties(std::span<const scene::Primitive> primitives, double density);

/// The dynamics stage of one scene. See the file comment for the tick.
class Dynamics {
 public:
  /// Builds the stage for `scene` on `world` (whose body ids are the scene's body indices, as
  /// buildCollisionWorld makes them; read here only for the poses of bodies after the scene's).
  /// The scene must outlive the Dynamics; step() is given the world each tick. A scene without
  /// dynamic bodies yields an inactive stage whose step() returns at once. Errors: a dynamic body
  /// with non-positive or non-finite mass, a joint naming a body out of range, options out of
  /// range. Off the servo thread.
  static Result<std::unique_ptr<Dynamics>> create(const scene::SceneModel& scene,
                                                  const collision::CollisionWorld& world,
                                                  const DynamicsOptions& options = {});
  ~Dynamics();
  /// A copy is a stage in the same state (for a copy of the simulation state; it shares the
  /// scene and needs a copy of the world to step). Off the servo thread: allocates, keeping
  /// every capacity.
  Dynamics(const Dynamics&);
  Dynamics(Dynamics&&) noexcept;
  Dynamics& operator=(const Dynamics&);
  Dynamics& operator=(Dynamics&&) noexcept;

  /// True when the scene has at least one dynamic body (the plan's `dynamics`).
  bool active() const { return active_; }

  /// One tick of dt seconds (> 0) on `world` (the one create() was given, or a copy of it with
  /// a copy of this stage). Call it after world.step() of this tick (it reads contacts()); it
  /// writes the new poses with world.setPose. `held` may be null.
  /// Servo thread; no allocation. An inactive stage returns an empty report at once.
  StepReport step(collision::CollisionWorld& world, double dt, const HeldInput* held = nullptr);

  /// Moves a kinematic body to X_WB by the end of the next step, with the velocity that takes
  /// it there (contacts see that velocity); without a new call it stays. Ignored for other
  /// bodies, an index out of range or a pose that is not finite (the held body is moved by
  /// HeldInput::kKinematic, which is ignored for a pose that is not finite). Servo thread.
  void setKinematicPose(std::uint32_t body, const Pose& X_WB);

  /// Takes a kinematic or dynamic body (not the held one) out of the scene (enabled = false) or
  /// puts it back at X_WB (true): while disabled it is frozen where it was (no gravity, no
  /// velocity, not integrated), has no contacts (the Simulation also disables it in the
  /// CollisionWorld), its joints are inert, and it counts in neither the energies nor the
  /// scene's sleep; pose() keeps its last pose. Enabled, it starts at X_WB at rest (a coasting
  /// body, declared mass 0, too). Either way the scene wakes (what rested on it falls).
  /// Bodies with SceneModel::Body::active false start disabled. Ignored for a static body, the
  /// held body, an index out of range, or (enabling) a pose that is not finite. Servo thread; no
  /// allocation.
  void setEnabled(std::uint32_t body, bool enabled, const Pose& X_WB = Pose{});
  /// Whether a body is in the scene (true for an inactive stage or an index out of range).
  bool enabled(std::uint32_t body) const;
  /// Whether a dynamic body's island sleeps (DynamicsOptions::sleep_time_s); false for other
  /// bodies, an inactive stage or an index out of range. Servo thread (or the owner thread).
  bool asleep(std::uint32_t body) const;

  /// Hands a dynamic body over to the caller (driven = true) or back (false): while driven it has
  /// infinite mass, follows setKinematicPose() like a kinematic body (standing still without a
  /// new target) and its contact impulses count in heldFeedback() as the held body's (the
  /// Simulation drives a body attached to the probe this way, docs/dynamics.md). Handed back, it
  /// moves on from the velocity of its last driven tick. Ignored for other bodies, the held body
  /// and an index out of range. Servo thread.
  void setDriven(std::uint32_t body, bool driven);

  /// A force (at the centre of mass) and torque applied to a dynamic body on every step until
  /// changed (N, N m, scene frame). Ignored for other bodies or values that are not finite.
  /// Servo thread.
  void setExternalWrench(std::uint32_t body, const Vec3& force_W_n, const Vec3& torque_W_nm);

  /// Pose of a body's origin, its linear velocity (of the centre of mass) and angular velocity,
  /// scene frame, after the last step. Servo thread (or the owner thread).
  Pose pose(std::uint32_t body) const;
  Vec3 linearVelocity(std::uint32_t body) const;
  Vec3 angularVelocity(std::uint32_t body) const;
  /// Centre of mass in the scene frame.
  Vec3 centerOfMass(std::uint32_t body) const;
  /// A dynamic body's mass (kg), centre of mass (body frame) and inertia about it (body frame,
  /// kg m^2), as the dynamics use them (declared, or computed from the primitives); all zero for
  /// a body of infinite mass (static, kinematic, a declared mass of 0), an inactive stage or an
  /// index out of range.
  MassProperties massProperties(std::uint32_t body) const;
  /// The acceleration gravity gives a dynamic body (the scene's gravity times its
  /// gravity_factor, scene units per s^2); zero for other bodies.
  Vec3 gravity(std::uint32_t body) const;
  /// Kinetic energy of all dynamic bodies (J) and their potential energy in the scene's
  /// gravity (J, zero at the origin). For tests and status.
  double kineticEnergy() const;
  double potentialEnergy() const;

  // --- added by the scene swap's prewarm (core/sim/scene_state.h prewarmState) ---
  /// Whether every moving body is still now by the sleep test
  /// (DynamicsOptions::sleep_speed_fraction; a kinematically held body touching a dynamic body
  /// keeps the scene awake), after the last step. false for an inactive stage or with sleep off
  /// (sleep_time_s 0). Any thread that may read the stage.
  bool stillNow(const collision::CollisionWorld& world) const;
  /// Off the servo thread, for a scene about to be swapped in whose first steps the loader ran:
  /// if it is still now (stillNow()), the whole scene sleeps at once, as if it had been still
  /// for sleep_time_s (velocities zeroed; it wakes as a sleeping scene does). Returns whether it
  /// sleeps. A scene loaded at rest then costs the servo thread nothing from its first tick,
  /// instead of sleep_time_s of whole solves.
  bool sleepIfStill(const collision::CollisionWorld& world);
  /// Gives the collision world the sleep of the dynamic bodies (CollisionWorld::setAsleep), so
  /// that a sleeping island's pairs with each other and with static bodies are neither tested,
  /// listed nor looked at by the world's step; a kinematic body the dynamics move (a target or a
  /// velocity) is woken in the world (and stays awake). step() calls it before and after waking
  /// islands (and relists the world's contacts when a body woke, so that what moves is seen
  /// touching a sleeping island and a woken island's own contacts are solved in that step) and
  /// after putting islands to sleep; call it after sleepIfStill(). Returns whether a body woke
  /// in the world. Servo thread; no allocation.
  bool syncSleep(collision::CollisionWorld& world) const;

  /// The held body's feedback of the last step (zero when the scene has no held body).
  const HeldFeedback& heldFeedback() const { return held_feedback_; }
  const DynamicsCounters& counters() const { return counters_; }
  std::uint32_t bodyCount() const;

  /// Writes the stage's state (bodies, joints' warm starts, warm contact points, spreader,
  /// feedback, sleep, counters; not the per-tick contact points or scratch) for the simulation
  /// state's hash and comparison (core/sim/scene_state.h). Any thread that may read it.
  void writeState(StateWriter& w) const;

 private:
  struct BodyState;
  struct Row;
  struct ContactPoint;
  struct NormalBlock;
  struct PairVelocity;
  struct JointState;
  struct WarmPoint;
  struct JointRowSpec;
  struct JointRow;
  struct GeneralJoint;

  Dynamics();
  // create (dynamics.cpp)
  Result<bool> initBody(std::uint32_t i, const Vec3& g, std::size_t* moving_prims);
  Result<bool> initMass(const scene::Body& sb, const Vec3& g, BodyState& b);
  Result<bool> initJoints();
  // the tick (dynamics_step.cpp)
  void stepAsleep(const HeldInput* held);
  void integrateForces(double dt, const collision::CollisionWorld& world, const HeldInput* held);
  bool takes(const collision::Contact& c) const;
  std::pair<std::size_t, std::size_t> warmRange(const collision::Contact& c,
                                                std::size_t& cursor) const;
  double gapThatFits(std::span<const collision::Contact> contacts);
  void gatherContacts(std::span<const collision::Contact> contacts, StepReport& report);
  void solveThroughImpacts(double dt, StepReport& report);
  double restitutionThreshold(const ContactPoint& cp) const;
  double touchTolerance(const ContactPoint& cp) const;
  double slop(const ContactPoint& cp) const;
  double slopSize(const ContactPoint& cp) const;
  void activate(ContactPoint& cp) const;
  void advance(double h);
  HeldFeedback heldFeedbackOfTick();
  void updateSleep(double dt);
  void wakeIslands(const collision::CollisionWorld& world, const HeldInput* held);
  void wakeIsland(std::uint32_t island);
  std::uint32_t findRoot(std::uint32_t i);
  void joinRoots(std::uint32_t a, std::uint32_t b);
  void islandSizes();
  bool wakeRequested(const collision::CollisionWorld& world, const HeldInput* held) const;
  bool heldTouchesDynamic(const collision::CollisionWorld& world) const;
  void storeWarmStart(StepReport& report);
  // the solvers (dynamics_solver.cpp)
  void prepareJoints();
  void solveVelocities(double remaining);
  bool prepareRows(double remaining, bool warm);
  void prepareRow(ContactPoint& cp, double remaining);
  void applyJointWarmStart();
  void warmStartPoint(ContactPoint& cp);
  void solveJoint(JointState& js, double inv_dt, double& residual);
  void solveContact(ContactPoint& cp, double& residual);
  void solveBlock(const NormalBlock& blk, double& residual);
  static void solveFriction(ContactPoint& cp, PairVelocity& v, double& residual);
  static void solveNormal(ContactPoint& cp, PairVelocity& v, double& residual);
  void prepareBlock(std::size_t first);
  bool solveNormalBlock(const NormalBlock& blk, PairVelocity& v, double& residual);
  static bool shareBlock(const NormalBlock& blk,
                         const double* err,
                         const double* old,
                         double* lnew);
  bool correctBlock(const NormalBlock& blk, double beta, double inv_dt);
  void levelSweep(double dt);
  bool sidewaysPush(const ContactPoint& cp) const;
  // the gravity a contact between A and B works against: B's, or A's if B has none
  static const Vec3& contactGravity(const BodyState& A, const BodyState& B);
  Vec3 loadCentre(std::uint32_t u, double dt) const;
  void passLoadsDown(double dt);
  static bool levels(const ContactPoint& cp);
  void applyRestitution();
  void correctPositions(double dt);
  bool measureJointErrors();
  void correctJoint(JointState& js, double beta, double inv_dt);
  void correctContact(ContactPoint& cp, double beta, double inv_dt);
  // the general joints (dynamics_joints.cpp)
  Result<bool> initGeneralJoint(const scene::Joint& j);
  struct JointFrames;
  JointFrames jointFrames(const GeneralJoint& gj) const;
  bool measureRow(const JointFrames& f, const JointRowSpec& spec, JointRow& row) const;
  void prepareGeneralJoints();
  void warmStartGeneralJoints();
  void solveGeneralJoint(GeneralJoint& gj, double& residual);
  bool measureGeneralErrors();
  void correctGeneralJoint(GeneralJoint& gj, double beta, double inv_dt);
  void generalFeedback(HeldFeedback& fb) const;

  std::uint32_t step_flags_ = 0;
  double tick_dt_ = 0.001;
  double min_size_ = 1.0;             // smallest dynamic body's size
  bool one_size_ = true;              // every dynamic body of one size: slop_size_ not needed
  double velocity_tolerance_ = 0.0;   // this tick's convergence tolerance of the solves
  double mass_ratio_ = 1.0;           // this tick's largest mass ratio across a resting contact
  double ke_episode_start_ = 0.0;     // kinetic energy before a solve with restitution
  std::uint32_t iterations_run_ = 0;  // this tick's velocity iterations, all solves
  std::uint32_t settle_rows_ = 0;     // this tick's rows solved by settling iterations
  double level_residual_ = 0.0;       // largest levelling correction of a position iteration
  std::vector<Vec3> dv_, dw_;         // per body: scratch of the restitution impulses
  bool warm_pending_ = false;
  bool asleep_ = false;  // every island sleeps: step() does no work
  // a kinematic target may be pending (setKinematicPose; a step consumes them all): the asleep
  // scene's wake test walks the bodies for one only then (not state: derived)
  bool target_given_ = false;
  std::vector<std::uint32_t> parent_;  // per body: the islands' union-find (scratch)
  std::vector<double> island_rest_;    // per root: its bodies' shortest rest (scratch)
  // per body: the smallest dynamic size in its island of this tick's contact points (the slop's
  // length; infinite for a body of infinite mass), written by islandSizes unless one_size_
  std::vector<double> slop_size_;

  const scene::SceneModel* scene_ = nullptr;
  DynamicsOptions options_;
  bool active_ = false;
  std::int32_t held_ = -1;
  bool held_kinematic_ = false;
  double accel_scale_ = 0.0;  // largest |gravity| * gravity_factor
  std::vector<BodyState> bodies_;
  ReservedVector<ContactPoint> points_;
  std::vector<NormalBlock> blocks_;  // per point: the block of the pair it is the first point of
  // levelSweep: (height, block) of the contacts it levels (scratch)
  ReservedVector<std::pair<double, std::uint32_t>> level_order_;
  // levelSweep: per body, touched outside it; its level_reach_ set this tick (scratch)
  std::vector<std::uint8_t> level_pinned_;
  // levelSweep: per body, its resting supports' extent across gravity: the support function of
  // their points (about its centre of mass) in kLevelDirs directions (scratch)
  static constexpr std::size_t kLevelDirs = 16;
  std::vector<std::array<double, kLevelDirs>> level_reach_;
  // levelSweep: per body, the load the bodies above passed to it this tick: the sum of the
  // normal impulses of their contacts on it, and of those impulses times the centre of each
  // upper body's own load (its weight and what it carries; world) (scratch)
  struct LevelLoad {
    Vec3 moment{0.0};
    double impulse = 0.0;
  };
  std::vector<LevelLoad> level_load_;
  // levelSweep: (height, point) of the contact points along gravity that pressed, to pass the
  // loads down from the top (scratch)
  ReservedVector<std::pair<double, std::uint32_t>> level_points_;
  std::size_t max_points_ = 0;  // the capacity of points_ (options' max_contact_points)
  // per contact the world can list: its gap and its points, when more points than max_points_
  // are offered (scratch of gapThatFits)
  std::vector<std::pair<double, std::size_t>> gap_points_;
  // the scene's primitives' materials (scene::materialOf), body after body: body i's are from
  // prim_first_[i] to prim_first_[i + 1]; a primitive out of range has default_material_
  std::vector<const scene::Material*> prim_material_;
  std::vector<std::uint32_t> prim_first_;
  const scene::Material* default_material_ = nullptr;
  ReservedVector<WarmPoint> warm_, warm_next_;
  std::vector<JointState> joints_;
  std::vector<GeneralJoint> general_;      // every other joint: limits, cones, soft limits, drives
  std::vector<std::uint64_t> no_collide_;  // body-pair keys kept apart by joints, sorted
  ImpulseSpreader spreader_;
  HeldFeedback held_feedback_;
  DynamicsCounters counters_;
};

}  // namespace hapticd::dynamics
