// The compiled model of a scene for the simulation: the options checked, and everything the
// ticks read that never changes (core/sim/model.h).
#include "core/sim/model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "core/dynamics/scene_world.h"
#include "core/geometry/sphere_points.h"

namespace hapticd::sim {
namespace {

using collision::BodyKind;
using geom::Transform;

bool finitePositive(double v) {
  return std::isfinite(v) && v > 0.0;
}

bool finiteNonNegative(double v) {
  return std::isfinite(v) && v >= 0.0;
}

// the checks of ResponseOptions and SimOptions, in order: the first that fails is the error; the
// message names the config key (the table's name: daemon/config_keys.cpp)
Result<bool> checkOptions(const SimOptions& o) {
  const ResponseOptions& r = o.response;
  const double fraction = r.min_predictive_fraction;
  const double crease = r.crease_angle_deg;
  const double backstop = r.dynamic_backstop_fraction;
  const std::pair<bool, const char*> checks[] = {
      {finitePositive(r.stiffness_n_per_m), "[response] stiffness_n_per_m must be > 0"},
      {finitePositive(r.tick_s), "[response] tick_s (0: 1 / [servo] rate_hz) must give a tick > 0"},
      {finitePositive(r.max_force_n), "[device] max_force_n must be > 0"},
      {finitePositive(r.max_torque_nm), "[device] max_torque_nm must be > 0"},
      {finitePositive(r.max_force_step_n), "[device] max_force_step_n must be > 0"},
      {finitePositive(r.max_torque_step_nm), "[device] max_torque_step_nm must be > 0"},
      {finiteNonNegative(r.ramp_s), "[servo] ramp_in_s must be >= 0"},
      {finiteNonNegative(r.max_speed_m_per_s),
       "[response] max_speed_m_per_s must be >= 0 (0: the safe distance from "
       "safe_distance_fraction)"},
      {std::isfinite(r.safe_distance_fraction) && r.safe_distance_fraction > 0.0 &&
           r.safe_distance_fraction <= 1.0,
       "[response] safe_distance_fraction must be in (0, 1]"},
      {r.max_substeps >= 1, "[response] max_substeps must be >= 1"},
      {finiteNonNegative(r.speed_decay_s), "[response] speed_decay_s must be >= 0"},
      {std::isfinite(fraction) && fraction > 0.0 && fraction <= 1.0,
       "[response] min_predictive_fraction must be in (0, 1]"},
      {std::isfinite(r.proxy_stiffness_ratio) && r.proxy_stiffness_ratio > 1.0,
       "[response] proxy_stiffness_ratio must be > 1"},
      {finiteNonNegative(r.coupling_damping_factor),
       "[response] coupling_damping_factor must be >= 0"},
      {finiteNonNegative(r.rot_stiffness_nm_per_rad),
       "[response] rot_stiffness_nm_per_rad must be >= 0"},
      {finiteNonNegative(r.penetration_allowance_m),
       "[response] penetration_allowance_m must be >= 0 (0: from the force limit and the "
       "stiffness)"},
      {std::isfinite(crease) && crease >= 0.0 && crease < 90.0,
       "[response] crease_angle_deg must be in [0, 90)"},
      {std::isfinite(backstop) && backstop >= 0.0 && backstop <= 1.0,
       "[response] dynamic_backstop_fraction must be in [0, 1]"},
      {finiteNonNegative(o.dynamics_impulse_window_s), "[response] impulse_window_s must be >= 0"},
      {finiteNonNegative(o.dynamics_sleep_time_s), "[response] dynamics_sleep_time_s must be >= 0"},
      {o.dynamics_velocity_iterations >= 1 && o.dynamics_velocity_iterations <= 1000,
       "[response] dynamics_velocity_iterations must be in [1, 1000]"},
      {o.dynamics_position_iterations <= 1000,
       "[response] dynamics_position_iterations must be in [0, 1000]"},
      {o.dynamics_velocity_iterations_max <= 1000,
       "[response] dynamics_velocity_iterations_max must be in [0, 1000]"},
      {o.dynamics_position_iterations_max <= 1000,
       "[response] dynamics_position_iterations_max must be in [0, 1000]"},
      {finiteNonNegative(r.attach_distance_m), "[response] attach_distance_m must be >= 0"},
      {std::isfinite(r.attach_distance_fraction) && r.attach_distance_fraction >= 0.0 &&
           r.attach_distance_fraction <= 1.0,
       "[response] attach_distance_fraction must be in [0, 1]"},
      {finiteNonNegative(r.grab_inertia_filter_s), "[response] grab_inertia_filter_s must be >= 0"},
  };
  for (const auto& [ok, message] : checks) {
    if (!ok)
      return Error{message};
  }
  return true;
}

// the world body's pose at the start: the scene's, the probe sphere at the origin
geom::Pose initialPose(const scene::SceneModel& sc, std::uint32_t body) {
  return body < sc.bodies.size() ? sc.bodies[body].X_WB : geom::Pose{};
}

// per scene body: kind, felt stiffness, shading tables, origin radius
Result<bool> addBodies(SimModel& m, double crease) {
  const scene::SceneModel& sc = *m.scene;
  for (std::size_t i = 0; i < sc.bodies.size(); ++i) {
    const scene::Body& b = sc.bodies[i];
    BodyInfo info;
    info.scene_index = static_cast<std::int32_t>(i);
    info.kind = dynamics::worldKind(sc, i);
    info.com_B = b.com_B;
    info.stiffness =
        b.stiffness_n_per_m.has_value() ? std::min(*b.stiffness_n_per_m, m.k_s) : m.k_s;
    for (const scene::Primitive& p : b.primitives) {
      if (!p.shape)
        return Error{"body '" + b.name + "': a primitive has no shape"};
      const Transform X = p.X_BP.toTransform();
      for (const auto& v : p.shape->vertices())
        info.origin_radius = std::max(info.origin_radius, glm::length(X.apply(v.p)));
    }
    if (!(info.stiffness > 0.0))
      return Error{"body '" + b.name + "': stiffness must be > 0"};
    if (crease > 0.0) {
      for (const scene::Primitive& p : b.primitives)
        info.shading.emplace_back(*p.shape, crease);
    }
    m.info.push_back(std::move(info));
  }
  if (sc.probe_body < 0) {
    auto hull =
        geom::Polytope::fromPoints(geom::spiralSpherePoints(m.options.probe_sphere_radius_m, 64));
    if (!hull.ok())
      return Error{"probe sphere: " + hull.error().message};
    m.probe_sphere = std::make_shared<const geom::Polytope>(std::move(hull).value());
    BodyInfo info;
    info.kind = BodyKind::kProbe;
    info.stiffness = m.k_s;
    if (crease > 0.0)
      info.shading.emplace_back(*m.probe_sphere, crease);
    m.probe = static_cast<std::uint32_t>(sc.bodies.size());
    m.info.push_back(std::move(info));
  } else {
    m.probe = static_cast<std::uint32_t>(sc.probe_body);
  }
  return true;
}

// joints: hinges to the scene frame (or a static body) for the attach modes, with the largest
// distance of the body's points from the axis; pairs that the joint keeps from colliding
Result<bool> addJoints(SimModel& m) {
  const scene::SceneModel& sc = *m.scene;
  for (const scene::Joint& j : sc.joints) {
    const auto nb = static_cast<std::int32_t>(sc.bodies.size());
    if (j.body_a < 0 || j.body_a >= nb || j.body_b >= nb)
      return Error{"joint: body out of range"};
    if (j.body_b >= 0 && !j.enable_collision)
      m.excluded_pairs.emplace_back(static_cast<std::uint32_t>(j.body_a),
                                    static_cast<std::uint32_t>(j.body_b));
    if (j.kind != scene::JointKind::kHinge || j.hinge_axis > 2)
      continue;
    const bool to_ground = j.body_b < 0 || sc.bodies[static_cast<std::size_t>(j.body_b)].motion ==
                                               scene::Motion::kStatic;
    if (!to_ground)
      continue;
    BodyInfo& info = m.info[static_cast<std::size_t>(j.body_a)];
    info.hinge = true;
    info.hinge_o_B = j.X_AJ.translation;
    Vec3 axis{0.0};
    axis[j.hinge_axis] = 1.0;
    info.hinge_a_B = glm::normalize(j.X_AJ.rotation * axis);
  }
  for (std::uint32_t id = 0; id < m.info.size(); ++id) {
    BodyInfo& bi = m.info[id];
    if (!bi.hinge || id == m.probe || bi.kind == BodyKind::kStatic)
      continue;
    const geom::Pose X = initialPose(sc, id);
    const Vec3 o = X.translation + X.rotation * bi.hinge_o_B;
    const Vec3 a = glm::normalize(X.rotation * bi.hinge_a_B);
    double hr = 0.0;
    const Transform XB = X.toTransform();
    for (const auto& p : sc.bodies[static_cast<std::size_t>(bi.scene_index)].primitives) {
      const Transform XP = XB * p.X_BP.toTransform();
      for (const auto& v : p.shape->vertices()) {
        const Vec3 d = XP.apply(v.p) - o;
        hr = std::max(hr, glm::length(d - glm::dot(d, a) * a));
      }
    }
    bi.hinge_radius = hr;
  }
  return true;
}

// the lengths of the response, relative to the probe's size or derived from the device's force
// limit and the stiffness unless an absolute value is configured (docs/response.md "Knobs")
void setLengths(SimModel& m) {
  const ResponseOptions& r = m.options.response;
  const scene::SceneModel& sc = *m.scene;
  const geom::Pose X_probe = initialPose(sc, m.probe);
  const Vec3 c = X_probe.translation + X_probe.rotation * m.info[m.probe].com_B;
  m.probe_radius_m = std::max(m.radiusAbout(m.probe, X_probe, c), 1e-9);
  m.max_travel_m = r.max_speed_m_per_s > 0.0 ? r.max_speed_m_per_s * r.tick_s
                                             : r.safe_distance_fraction * m.probe_radius_m;
  m.penetration_allowance_m =
      r.penetration_allowance_m > 0.0
          ? r.penetration_allowance_m
          : 1.5 * r.max_force_n / (r.proxy_stiffness_ratio * r.stiffness_n_per_m);
  m.attach_distance_m =
      r.attach_distance_m > 0.0
          ? r.attach_distance_m
          : std::max(r.attach_distance_fraction * m.probe_radius_m, 2.0 * m.max_travel_m);
}

// the response's parameters at the start: the coupling's stiffness k_c in series with the proxy's
// contact springs gives k_s; rotational stiffness k_c r^2 with r the probe's radius
void setResponse(SimModel& m) {
  const ResponseOptions& r = m.options.response;

  response::CouplingParams& cp = m.coupling;
  cp.tick_s = r.tick_s;
  cp.stiffness_n_per_m = m.k_c;
  cp.damping_n_s_per_m = r.coupling_damping_factor * m.k_c * r.tick_s;
  cp.rot_stiffness_nm_per_rad = r.rot_stiffness_nm_per_rad > 0.0
                                    ? r.rot_stiffness_nm_per_rad
                                    : m.k_c * m.probe_radius_m * m.probe_radius_m;
  cp.rot_damping_nm_s_per_rad = r.coupling_damping_factor * cp.rot_stiffness_nm_per_rad * r.tick_s;

  m.proxy.coupling_stiffness = cp.stiffness_n_per_m;
  m.proxy.rot_coupling_stiffness = cp.rot_stiffness_nm_per_rad;
  m.proxy.delta =
      r.predictive ? std::min(m.max_travel_m, r.min_predictive_fraction * m.probe_radius_m) : 0.0;
  m.proxy.max_travel = m.max_travel_m;
  m.proxy.max_force_n = r.max_force_n;
  m.proxy.max_torque_nm = r.max_torque_nm;
}

// the dynamics, exactly when the plan asks (world ids are the scene's body indices, the probe
// sphere, if any, right after them)
void setDynamics(SimModel& m) {
  const ResponseOptions& r = m.options.response;
  const scene::SceneModel& sc = *m.scene;
  m.dynamics = sc.plan.dynamics;
  if (!m.dynamics)
    return;
  m.dynamics_active = std::any_of(sc.bodies.begin(), sc.bodies.end(), [](const scene::Body& b) {
    return b.motion == scene::Motion::kDynamic;
  });
  dynamics::DynamicsOptions& d = m.dynamics_options;
  d.tick_s = r.tick_s;
  d.held_max_force_n = r.max_force_n;
  d.impulse_window_s = m.options.dynamics_impulse_window_s;
  d.sleep_time_s = m.options.dynamics_sleep_time_s;
  d.velocity_iterations = m.options.dynamics_velocity_iterations;
  d.position_iterations = m.options.dynamics_position_iterations;
  d.velocity_iterations_max = m.options.dynamics_velocity_iterations_max;
  d.position_iterations_max = m.options.dynamics_position_iterations_max;
  if (sc.probe_body < 0)
    d.extra_probe_body = static_cast<std::int32_t>(sc.bodies.size());
  m.backstop_m = r.dynamic_backstop_fraction * m.penetration_allowance_m;
}

}  // namespace

Result<std::shared_ptr<const SimModel>> SimModel::compile(
    std::shared_ptr<const scene::SceneModel> scene,
    const SimOptions& options) {
  if (!scene)
    return Error{"no scene"};
  if (auto ok = checkOptions(options); !ok.ok())
    return ok.error();
  auto m = std::make_shared<SimModel>();
  m->scene = std::move(scene);
  m->options = options;
  const ResponseOptions& r = options.response;
  const scene::SceneModel& sc = *m->scene;
  m->grab_beta =
      r.grab_inertia_filter_s > 0.0 ? 1.0 - std::exp(-r.tick_s / r.grab_inertia_filter_s) : 1.0;
  if (sc.probe_body >= static_cast<std::int32_t>(sc.bodies.size()))
    return Error{"scene: probe body " + std::to_string(sc.probe_body) + " out of range (" +
                 std::to_string(sc.bodies.size()) + " bodies)"};
  if (sc.probe_body < 0 && !finitePositive(options.probe_sphere_radius_m))
    return Error{"probe sphere radius must be > 0"};

  m->speed_decay = r.speed_decay_s > 0.0 ? std::exp(-r.tick_s / r.speed_decay_s) : 0.0;
  m->k_s = r.stiffness_n_per_m;
  // series springs: k_c in series with ratio * k_s gives k_s
  m->k_c = m->k_s * r.proxy_stiffness_ratio / (r.proxy_stiffness_ratio - 1.0);

  if (auto ok = addBodies(*m, r.crease_angle_deg * std::numbers::pi / 180.0); !ok.ok())
    return ok.error();
  if (auto ok = addJoints(*m); !ok.ok())
    return ok.error();
  setLengths(*m);
  // pairs within the predictive distance plus one sub-step's travel are found
  // (buildCollisionWorld raises the margin to the dynamics' when the scene has dynamic bodies);
  // a pair of bodies that did not move keeps its exact answer
  m->world_options.box_margin = 2.0 * m->max_travel_m;
  m->world_options.budget.max_pairs = options.max_pairs_per_tick;
  m->world_options.skip_unmoved_pairs = true;
  m->world_options.query_method = options.query_method;
  // the margin finds pairs up to four safe distances apart, which for a probe of many small
  // pieces is many times the pairs the proxy reads: without dynamics (which read every listed
  // pair) the world answers only pairs that may be nearer than what the rows (two safe distances,
  // three when both sides move, rows.cpp gatherRows) and the attach distance read
  if (!m->scene->plan.dynamics) {
    m->world_options.far_distance = std::max(3.0 * m->max_travel_m, m->attach_distance_m);
    m->world_options.far_distance_static = 2.0 * m->max_travel_m;
  }
  // with dynamics the margin is raised to the dynamics' (0.5% of the scene's size), which for a
  // small probe in a large scene is many times what the proxy reads: the probe's boxes grow by
  // what the unraised margin found (two safe distances on each side) and the attach distance,
  // and by twice its travel in a tick when it moves faster (the dynamics set it, at most the
  // raised margin)
  if (m->scene->plan.dynamics)
    m->world_options.probe_margin = std::max(4.0 * m->max_travel_m, m->attach_distance_m);
  // the bodies whose poses are listed
  m->pose_slot.assign(m->info.size(), -1);
  for (std::uint32_t id = 0; id < m->info.size(); ++id) {
    const BodyInfo& bi = m->info[id];
    if (bi.kind != BodyKind::kStatic && bi.scene_index >= 0) {
      m->pose_slot[id] = static_cast<std::int32_t>(m->pose_bodies.size());
      m->pose_bodies.push_back(id);
    }
  }
  setDynamics(*m);
  setResponse(*m);
  m->friction = sc.plan.friction;
  return std::shared_ptr<const SimModel>(std::move(m));
}

const geom::Polytope& SimModel::primShape(std::uint32_t body, std::uint32_t prim) const {
  const BodyInfo& bi = info[body];
  if (bi.scene_index < 0)
    return *probe_sphere;
  return *scene->bodies[static_cast<std::size_t>(bi.scene_index)].primitives[prim].shape;
}

bool SimModel::excluded(std::uint32_t a, std::uint32_t b) const {
  for (const auto& [x, y] : excluded_pairs) {
    if ((x == a && y == b) || (x == b && y == a))
      return true;
  }
  return false;
}

double SimModel::radiusAbout(std::uint32_t body, const geom::Pose& X_WB, const Vec3& c_W) const {
  const Transform X = X_WB.toTransform();
  double r = 0.0;
  if (info[body].scene_index < 0) {
    for (const auto& v : probe_sphere->vertices())
      r = std::max(r, glm::length(X.apply(v.p) - c_W));
    return r;
  }
  for (const auto& p : scene->bodies[static_cast<std::size_t>(info[body].scene_index)].primitives) {
    const Transform XP = X * p.X_BP.toTransform();
    for (const auto& v : p.shape->vertices())
      r = std::max(r, glm::length(XP.apply(v.p) - c_W));
  }
  return r;
}

}  // namespace hapticd::sim
