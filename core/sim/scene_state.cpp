// The simulation's state at the start, and its hash and comparison (core/sim/scene_state.h).
#include "core/sim/scene_state.h"

#include "core/common/state_writer.h"
#include "core/dynamics/scene_world.h"
#include "core/sim/tick.h"

namespace hapticd::sim {
namespace {

using collision::BodyKind;

void writePose(StateWriter& w, const geom::Pose& X) {
  w.glm(X.translation);
  w.glm(X.rotation);
}

void writeTransform(StateWriter& w, const geom::Transform& X) {
  w.glm(X.R);
  w.glm(X.t);
}

void writeHeld(StateWriter& w, const HeldSet& h) {
  for (const std::uint32_t id : h.ids)
    w.integer(id);
  w.integer(h.count);
  w.integer(h.mode);
  w.integer(h.attached);
  writeTransform(w, h.X_probe_attached);
  writeTransform(w, h.X_attached_probe);
  w.glm(h.q_attached_probe);
  for (const Vec3& v : {h.centre_h_W, h.hinge_o_W, h.hinge_a_W})
    w.glm(v);
  w.f64(h.radius_m);
  w.integer(h.last_buttons);
}

void writeGrab(StateWriter& w, const GrabState& g) {
  w.f64(g.mass);
  w.glm(g.inertia_B);
  w.glm(g.q1);
  w.integer(g.history);
  for (const Vec3& v : {g.gravity_W, g.com_B, g.r_P, g.c1, g.c2, g.w1, g.a_f, g.alpha_f})
    w.glm(v);
}

void writeResponse(StateWriter& w, const SceneState& s) {
  s.coupling.writeState(w);
  const response::ProxyParams& p = s.proxy;
  for (const double v : {p.coupling_stiffness, p.rot_coupling_stiffness, p.delta, p.max_travel,
                         p.max_force_n, p.max_torque_nm})
    w.f64(v);
  w.integer(p.max_passes);
}

}  // namespace

void SceneState::writeState(StateWriter& w) const {
  world.writeState(w);
  w.flag(dynamics.has_value());
  if (dynamics)
    dynamics->writeState(w);
  writeResponse(w, *this);
  writePose(w, X_W_probe);
  w.f64(delta_m);
  w.f64(last_penetration_m);
  w.glm(deepest_normal_W);
  w.flag(proxy_sliding);
  for (const bool f : {first_step, world_dirty, kinematic_target_pending})
    w.flag(f);
  rows.writeState(w);
  w.array(row_env);
  w.integer(contact_points.size());
  for (const ContactPoint& c : contact_points) {
    w.glm(c.p_W);
    w.glm(c.n_W);
    w.f64(c.depth_m);
    w.integer(c.body);
  }
  w.integer(body_poses.size());
  for (const BodyPose& b : body_poses) {
    w.integer(b.body);
    writePose(w, b.X_WB);
  }
  w.flag(body_poses_stale);
  w.array(active);
  w.array(edit_travel);
  writeHeld(w, held);
  writeGrab(w, grab);
  w.flag(device.have_prev);
  w.glm(device.prev_h_W);
  w.glm(device.prev_q);
  w.f64(device.v_c);
  w.integer(driven.count);
  for (std::uint32_t d = 0; d < driven.count; ++d) {
    w.integer(driven.ids[d]);
    writePose(w, driven.before[d]);
  }
}

Result<SceneState> makeState(const SimModel& m) {
  const scene::SceneModel& sc = *m.scene;
  collision::BodyDesc sphere;
  if (m.probe_sphere) {
    sphere.kind = BodyKind::kProbe;
    sphere.group = sphere.mask = ~0u;  // unfiltered, as a scene's unfiltered collider
    sphere.primitives.push_back({m.probe_sphere, geom::Transform{}});
  }
  auto built =
      dynamics::buildCollisionWorld(sc, m.world_options, m.probe_sphere ? &sphere : nullptr);
  if (!built.ok())
    return built.error();
  SceneState s;
  s.world = std::move(*built.value());
  for (std::uint32_t id = 0; id < m.info.size(); ++id)
    s.active.push_back(s.world.enabled(id) ? 1 : 0);

  // capacities: as the world's, every pair a moving primitive can make
  const std::size_t pairs = s.world.reservedPairs();
  s.rows.reserve(pairs * collision::Manifold::kMaxPoints);
  s.row_env.reserve(pairs * collision::Manifold::kMaxPoints);
  s.contact_points.reserve(response::kMaxRows);
  s.edit_travel.assign(m.info.size(), 0.0);
  for (const std::uint32_t id : m.pose_bodies)
    s.body_poses.push_back({static_cast<std::uint32_t>(m.info[id].scene_index), s.world.pose(id)});

  if (m.dynamics) {
    auto created = dynamics::Dynamics::create(sc, s.world, m.dynamics_options);
    if (!created.ok())
      return created.error();
    s.dynamics.emplace(std::move(*created.value()));
  }
  // the dynamic bodies' poses are the dynamics' from the first tick on (one whole pass then)
  s.body_poses_stale = m.dynamics_active;
  // the bodies no stage moves sleep, so that their pairs with each other and with static bodies
  // cost nothing: without dynamics every non-static body but the probe (an attached body wakes
  // while it is held); with dynamics the kinematic ones only (the dynamics wake one they move,
  // and give the world their islands' sleep: Dynamics::syncSleep); bodies on a hinge are
  // quasi-static coordinates that the held set may turn: they stay awake
  for (std::uint32_t id = 0; id < m.info.size(); ++id) {
    if (id == m.probe || m.info[id].kind == BodyKind::kStatic)
      continue;
    if (m.dynamics_active && m.info[id].kind == BodyKind::kDynamic)
      continue;
    s.world.setAsleep(id, true);
  }

  // the probe starts at its scene pose (the sphere at the origin) and is coupled to the device
  s.X_W_probe = s.world.pose(m.probe);
  s.held.ids[0] = m.probe;
  s.held.count = 1;
  detail::updateDriven(m, s);
  s.held.radius_m = m.probe_radius_m;
  s.delta_m = m.proxy.delta;
  s.coupling = response::VirtualCoupling(m.coupling);
  s.proxy = m.proxy;

  s.world.step();
  detail::gatherRows(m, s);
  return s;
}

DynamicsStatus dynamicsStatus(const SimModel& m, const SceneState& s) {
  DynamicsStatus st;
  if (!s.dynamics)
    return st;
  st.active = m.dynamics_active;
  st.ticks = s.dynamics->counters().ticks;
  st.ticks_asleep = s.dynamics->counters().ticks_asleep;
  st.kinetic_energy_j = s.dynamics->kineticEnergy();
  st.potential_energy_j = s.dynamics->potentialEnergy();
  return st;
}

std::uint64_t stateHash(const SceneState& s) {
  StateHash h;
  s.writeState(h);
  return h.digest();
}

bool operator==(const SceneState& a, const SceneState& b) {
  StateBytes x, y;
  a.writeState(x);
  b.writeState(y);
  return x.data() == y.data();
}

}  // namespace hapticd::sim
