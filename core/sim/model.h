#pragma once
/// \file
/// The compiled model of one scene for the simulation (docs/architecture.md "Model apart from
/// state"): the immutable SceneModel and everything derived from it and the SimOptions at
/// create() (per-body facts, shading tables, the probe sphere, constants of the response). It
/// never changes after compile(); the per-tick state is SceneState (core/sim/scene_state.h).
///
/// Threads: compile() off the servo thread (allocates); a compiled model is read-only and may be
/// read by any thread.

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/collision/collision_world.h"
#include "core/common/result.h"
#include "core/dynamics/dynamics.h"
#include "core/response/coupling.h"
#include "core/response/proxy.h"
#include "core/response/shading.h"
#include "core/sim/simulation.h"

namespace hapticd::sim {

/// What the simulation knows of one world body (the scene's bodies in order, then the probe
/// sphere when the scene marks no probe body).
struct BodyInfo {
  std::int32_t scene_index = -1;  ///< -1: the probe sphere
  collision::BodyKind kind = collision::BodyKind::kStatic;
  Vec3 com_B{0.0};
  double stiffness = 0.0;      ///< felt stiffness of its surfaces (N per scene unit)
  double origin_radius = 0.0;  ///< largest distance of its points from its origin (scene units)
  /// A hinge to the scene frame (or to a static body), for the attach modes: its point and axis
  /// in the body's frame, and the largest distance of the body's points from the axis.
  bool hinge = false;
  Vec3 hinge_o_B{0.0}, hinge_a_B{0.0};
  double hinge_radius = 0.0;
  std::vector<response::ShadingTable> shading;  ///< per primitive (empty: shading off)
};

/// The compiled model. Built by compile(); immutable after.
struct SimModel {
  std::shared_ptr<const scene::SceneModel> scene;
  SimOptions options;
  /// The probe sphere's hull when the scene marks no probe body (else null).
  std::shared_ptr<const geom::Polytope> probe_sphere;
  std::vector<BodyInfo> info;  ///< per world body
  /// Body pairs (world ids) that a joint keeps from colliding.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded_pairs;
  /// World ids of the non-static scene bodies, in index order (SceneState::body_poses).
  std::vector<std::uint32_t> pose_bodies;
  /// Per world body: its index in pose_bodies, or -1.
  std::vector<std::int32_t> pose_slot;
  std::uint32_t probe = 0;  ///< world id of the probe body
  /// The plan has dynamics (SceneState::dynamics exists); `dynamics_active`: a dynamic body
  /// exists too (the stage does work).
  bool dynamics = false;
  bool dynamics_active = false;
  dynamics::DynamicsOptions dynamics_options;
  collision::WorldOptions world_options;
  /// The plan has friction (scene::SimulationPlan::friction): the held set's rows carry the
  /// combined materials' coefficients (docs/response.md "Friction at the probe").
  bool friction = false;
  /// The material of the config's probe sphere, which is not in the scene: none (no friction);
  /// a collider that declares no material has scene::defaultMaterial().
  scene::Material no_material;
  double backstop_m = 0.0;  ///< depth into a dynamic body beyond which its penalty rows act
  /// The safe distance of one proxy sub-step (ResponseOptions::safe_distance_fraction of the
  /// probe's radius, or max_speed_m_per_s * tick_s when that is set).
  double max_travel_m = 0.0;
  /// ResponseOptions::penetration_allowance_m, or when 0 what it derives from: 1.5 times the
  /// proxy's deepest penetration at the force limit, max_force_n / (ratio * k_s).
  double penetration_allowance_m = 0.0;
  /// ResponseOptions::attach_distance_m, or when 0 attach_distance_fraction of the probe's
  /// radius (and never less than two safe distances: the proxy rests delta from what it touches).
  double attach_distance_m = 0.0;
  double speed_decay = 0.0;  ///< per-tick decay of the speed bound v_c
  double k_s = 0.0;          ///< felt stiffness at the device (N per scene unit)
  double k_c = 0.0;          ///< coupling stiffness
  double probe_radius_m = 0.0;
  double grab_beta = 1.0;  ///< the grab inertia low-pass's gain per tick
  /// The response's parameters at the start (SceneState keeps the current ones).
  response::CouplingParams coupling;
  response::ProxyParams proxy;

  /// Checks the options and the scene and derives the model. Errors name the option or the
  /// body. Off the servo thread.
  static Result<std::shared_ptr<const SimModel>> compile(
      std::shared_ptr<const scene::SceneModel> scene,
      const SimOptions& options);

  /// The shape of primitive `prim` of world body `body`.
  const geom::Polytope& primShape(std::uint32_t body, std::uint32_t prim) const;
  /// Bodies `a` and `b` (world ids) are kept from colliding by a joint.
  bool excluded(std::uint32_t a, std::uint32_t b) const;
  /// Largest distance of body's points from c_W, the body at X_WB.
  double radiusAbout(std::uint32_t body, const geom::Pose& X_WB, const Vec3& c_W) const;
};

}  // namespace hapticd::sim
