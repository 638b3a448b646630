#pragma once
/// \file
/// The compiled scene model: what exists in a scene and so what must be simulated
/// (docs/scenes.md; KHR_physics_rigid_bodies, KHR_implicit_shapes). Built off the
/// servo thread by the loader (core/scene/loader.h) or by code; immutable once built; read by
/// collision, response, dynamics and the daemon (MuJoCo's model: `step(const SceneModel&,
/// state...)`).
///
/// This header is the contract between the scene loader, the simulation and the daemon: fields may
/// be added, none renamed or removed.
///
/// Units: metres, kilograms, seconds, radians; Y up. Frames: W = scene (world), B = body, P =
/// primitive.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/polytope.h"
#include "core/geometry/pose.h"

namespace hapticd::scene {

using geom::Mat3;
using geom::Pose;
using geom::Vec3;

/// How a body moves (KHR_physics_rigid_bodies `motion`).
enum class Motion : std::uint8_t {
  kStatic,     ///< no motion above its colliders: never moves
  kKinematic,  ///< `motion.isKinematic`: moved by clients (scene updates), infinite mass
  kDynamic,    ///< `motion`: moved by the dynamics
};

/// How two material values combine (KHR `frictionCombine`, `restitutionCombine`).
enum class Combine : std::uint8_t { kAverage, kMinimum, kMaximum, kMultiply };

/// A physics material (KHR `physicsMaterials[i]`). A declared material's undeclared values take
/// the extension's defaults (friction 0.6, restitution 0); a collider without a material takes
/// defaultMaterial() (friction 0.5, restitution 0). A declared 0 is 0: no friction.
struct Material {
  std::string name;
  double static_friction = 0.0;
  double dynamic_friction = 0.0;
  double restitution = 0.0;
  Combine friction_combine = Combine::kAverage;     ///< as declared; kAverage when not declared
  Combine restitution_combine = Combine::kAverage;  ///< as declared; kAverage when not declared
  bool friction_combine_declared = false;           ///< `frictionCombine` was given
  bool restitution_combine_declared = false;        ///< `restitutionCombine` was given
};

/// Which value of a pair of materials combineMaterials combines.
enum class MaterialValue : std::uint8_t { kStaticFriction, kDynamicFriction, kRestitution };

/// The value two materials give together, as KHR_physics_rigid_bodies says: "average" if either
/// declares it, else "minimum" if either does, else "maximum", else "multiply"; a material that
/// declares no combine mode takes no part in the choice, and when neither declares one the values
/// are averaged. The one implementation of the rule (plan, dynamics). Pure; any thread.
double combineMaterials(const Material& a, const Material& b, MaterialValue which);

/// Friction (static and dynamic) of a collider that declares no physics material: 0.5, the
/// default of Bullet (btRigidBody's m_friction) and PhysX; a scene that wants ice says so with a
/// material of friction 0. No restitution: a collider bounces only when a material asks for it.
inline constexpr double kDefaultFriction = 0.5;

/// The material of a collider without one (Primitive::material < 0): static and dynamic friction
/// kDefaultFriction, restitution 0, no combine mode declared (so the other material's mode, or
/// the average, combines them). Any thread; a reference to an object built before main.
const Material& defaultMaterial();

/// The material a primitive's index names: SceneModel::materials[index], or defaultMaterial() for
/// -1 (or an index out of range). Any thread; no allocation.
struct SceneModel;
const Material& materialOf(const SceneModel& scene, std::int32_t index);

/// What a primitive was made from, for messages and `hapticctl check`.
enum class ShapeSource : std::uint8_t {
  kBox,
  kSphere,
  kCapsule,
  kCylinder,
  kPlane,       ///< KHR_implicit_shapes (curved ones tessellated)
  kMeshHull,    ///< a mesh node with `convexHull: true` (OMI `convex`; a plain model's points or
                ///< lines)
  kConvexMesh,  ///< a mesh node verified convex (a plain model's convex mesh primitive)
  kCode,        ///< built by code, not from a file
  /// A convex piece of a mesh that is not convex (a mesh collider without `convexHull`, an OMI
  /// `trimesh`, a plain model's mesh): today the mesh's convex hull, one piece, until the convex
  /// decomposition lands (core/scene/decompose.h).
  kMeshPiece,
};

/// One convex primitive of a body.
struct Primitive {
  std::shared_ptr<const geom::Polytope> shape;  ///< in the primitive's frame P
  Pose X_BP;                                    ///< the primitive's pose in its body's frame
  ShapeSource source = ShapeSource::kCode;
  std::int32_t node = -1;      ///< glTF node index of the collider, -1 if none
  std::int32_t material = -1;  ///< index into SceneModel::materials, -1: no material declared
  /// Collision filter as bits: two primitives collide when (a.group & b.mask) && (b.group &
  /// a.mask). The loader gives each distinct collision behaviour (KHR `collisionFilters`, decided
  /// by the extension's rule in both directions) one bit in `group` and sets in `mask` the bits of
  /// the behaviours it collides with; unfiltered primitives share one bit. Triggers: 0 and 0.
  std::uint32_t group = 1;
  std::uint32_t mask = ~0u;
  /// A trigger volume (KHR `trigger`, OMI trigger): in the scene, never in contact (group = mask
  /// = 0), no mass. Listed by `hapticctl check`.
  bool trigger = false;
};

/// One rigid body: a node with `motion`, or a static collider (or a group of them).
struct Body {
  std::string name;        ///< node name (record-bodies uses it); "node<i>" when unnamed
  std::int32_t node = -1;  ///< glTF node index, -1 when built by code
  Motion motion = Motion::kStatic;
  bool probe = false;  ///< `extras.haptic.probe`: the body the probe holds
  /// Mass in kg; 0 for static and kinematic bodies. For a dynamic body: the declared mass, or
  /// computed from the primitives' volume at density 1000 kg/m^3 when not declared.
  double mass = 0.0;
  Vec3 com_B{0.0};  ///< centre of mass in the body frame
  /// Inertia tensor about the centre of mass, in the body frame (kg m^2); declared or computed.
  Mat3 inertia_B{0.0};
  bool mass_declared = false;
  /// 1 / mass (1/kg); 0 for an infinite mass: static and kinematic bodies, and a declared mass of
  /// 0 (KHR: 0 means infinite). The dynamics use this, never 1 / mass.
  double inverse_mass = 0.0;
  /// Inverse of inertia_B (1/(kg m^2)); 0 along axes of infinite inertia (a declared
  /// inertiaDiagonal component of 0, which inertia_B holds as 0), all 0 for infinite mass.
  Mat3 inverse_inertia_B{0.0};
  bool inertia_declared = false;
  Vec3 linear_velocity_W{0.0};   ///< initial, m/s
  Vec3 angular_velocity_W{0.0};  ///< initial, rad/s
  double gravity_factor = 1.0;
  /// `extras.haptic.stiffness` (N/m): contact stiffness of this body's surfaces, if declared.
  std::optional<double> stiffness_n_per_m;
  Pose X_WB;  ///< initial pose in the scene
  std::vector<Primitive> primitives;
  /// `extras.haptic.active` (default true). An inactive body is in the scene but out of it: it
  /// neither collides nor moves until a client's scene update adds it (SceneUpdate::added) at a
  /// pose; a scene update's `removed` makes a body inactive again. Static bodies are always active.
  bool active = true;
};

/// One limit of a joint (KHR `physicsJoints[i].limits[j]`), in the joint's attachment frame.
struct JointLimit {
  std::uint8_t linear_axes = 0;   ///< bit k: axis k (0..2) is limited linearly
  std::uint8_t angular_axes = 0;  ///< bit k: axis k is limited angularly
  std::optional<double> min;      ///< metres or radians; absent: no lower bound
  std::optional<double> max;
  std::optional<double> stiffness;  ///< absent: a hard limit
  double damping = 0.0;
};

/// A joint's kind, from which of its degrees of freedom are locked (hard limits with min = max =
/// 0). The dynamics simulate every kind: plain kFixed and kHinge on their own rows, the others (and
/// any joint with drives or soft limits) on general rows built from `limits` and `drives`
/// (docs/dynamics.md).
enum class JointKind : std::uint8_t {
  kFixed,    ///< all six degrees locked
  kHinge,    ///< rotation about one axis of the attachment frame only (optionally limited)
  kSlider,   ///< translation along one axis only (a prismatic joint; optionally limited)
  kBall,     ///< the three linear axes locked, rotation free or limited (a cone, a twist)
  kGeneric,  ///< any other combination of limits (ranged, one-sided, soft), drives alone
};

/// A drive of a joint (KHR `physicsJoints[i].drives[j]`): a force (or torque) along (or about)
/// one axis of the attachment frame, stiffness * (position_target - position) + damping *
/// (velocity_target - velocity), limited to max_force.
struct JointDrive {
  bool angular = false;             ///< `type`: false "linear" (N, m), true "angular" (N m, rad)
  bool acceleration = false;        ///< `mode`: false "force", true "acceleration" (scaled by mass)
  std::uint8_t axis = 0;            ///< 0..2, an axis of the attachment frame
  std::optional<double> max_force;  ///< N or N m; absent: not limited
  std::optional<double> position_target;  ///< m or rad; absent: no position target
  std::optional<double> velocity_target;  ///< m/s or rad/s; absent: no velocity target
  double stiffness = 0.0;                 ///< N/m or N m/rad
  double damping = 0.0;                   ///< N s/m or N m s/rad
};

/// A joint between two bodies (KHR node `joint`), kept for the dynamics.
struct Joint {
  JointKind kind = JointKind::kFixed;
  std::int32_t body_a = -1;  ///< body of the node carrying the joint
  std::int32_t body_b = -1;  ///< body of `connectedNode`; -1: the fixed scene frame
  Pose X_AJ;                 ///< attachment frame in body a's frame
  Pose X_BJ;                 ///< attachment frame in body b's frame (scene frame when body_b < 0)
  std::uint8_t hinge_axis = 0;  ///< kHinge: the free angular axis (0..2); kSlider: the free linear
  std::optional<double> hinge_min, hinge_max;  ///< kHinge: limits in radians, where declared
  std::vector<JointLimit> limits;              ///< as declared
  bool enable_collision = false;               ///< KHR default: constrained bodies do not collide
  std::vector<JointDrive> drives;              ///< as declared
  std::int32_t node = -1;                      ///< glTF node index of the node carrying the joint
};

/// Which stages run for this scene: "simulate only the effects a scene calls for".
struct SimulationPlan {
  bool contact_forces = true;  ///< always
  bool dynamics = false;       ///< at least one dynamic body
  bool gravity = false;        ///< the scene declares gravity and a dynamic body feels it
  bool friction = false;  ///< a material with non-zero friction is used by a dynamic or probe body
  /// The smallest and largest friction (static or dynamic, combined as the contacts combine
  /// them) of the pairs a dynamic or probe body can make; both 0 without friction.
  double friction_min = 0.0, friction_max = 0.0;
  /// Some collider a dynamic or probe body can touch (or that body itself) has no physics
  /// material and so takes defaultMaterial()'s friction.
  bool friction_default = false;
  bool restitution = false;  ///< a material with non-zero restitution is used by a dynamic body
  bool joints = false;       ///< at least one joint
  /// Primitives the broad phase keeps (static ones are tracked but never paired with each other).
  std::uint32_t static_primitives = 0;
  std::uint32_t moving_primitives = 0;  ///< the scene's own, without the probe sphere
  /// The scene names no probe body: the simulation adds the probe sphere of the config, one more
  /// moving primitive (describePlan counts it).
  bool probe_sphere = false;
  /// What the loader ignored or stood in for, and what is parsed but not simulated, one line each
  /// ("ignored (appearance only): KHR_lights_punctual"; "body 'Belt': kinematic velocity not
  /// simulated: ..."); a line starting "warning: " is a warning. describePlan prints them.
  std::vector<std::string> notes;
};

/// Limits and tolerances of scene loading (config [scene]); every default documented there.
struct SceneLimits {
  std::uint64_t max_file_bytes = 64ull << 20;
  std::uint32_t max_nodes = 10000;
  std::uint32_t max_bodies = 2000;
  std::uint32_t max_primitives = 10000;
  std::uint32_t max_hull_input_points = 100000;
  std::uint32_t max_hull_vertices = 4096;
  /// Curved implicit shapes are tessellated so that no surface point is farther than this
  /// fraction of the shape's size from the polytope.
  double tessellation_tolerance = 1e-3;
  /// Hull input points over all colliders of a scene (colliders may share one big mesh).
  std::uint64_t max_total_hull_input_points = 4000000;
};

/// The whole compiled scene. Immutable after building; any thread may read it.
struct SceneModel {
  std::string name;  ///< file name or demo name
  std::vector<Body> bodies;
  std::vector<Material> materials;
  std::vector<Joint> joints;  ///< every joint; the dynamics simulate all kinds
  /// Kept for interface stability: the loader leaves it empty since the dynamics simulate every
  /// joint (issue 15 item 4); joints a model built by code puts here are simulated too.
  std::vector<Joint> unsimulated_joints;
  std::optional<Vec3> gravity_W;  ///< `extras.haptic.gravity` on the scene; absent: no gravity
  std::int32_t probe_body =
      -1;  ///< index of the body with `probe: true`, -1: a probe sphere from config
  /// Characteristic length (m): the bounding-box diagonal of all primitives, for relative
  /// tolerances.
  double length_scale = 1.0;
  SimulationPlan plan;
};

/// The plan of a scene, from what it declares, with the notes the scene itself tells (kinematic
/// velocities without dynamics, triggers, nothing to touch). Pure; any thread.
SimulationPlan makePlan(const SceneModel& scene);

/// A multi-line human-readable description of the plan (printed by `hapticctl check`, reported
/// by the daemon's status).
std::string describePlan(const SimulationPlan& plan);

}  // namespace hapticd::scene
