// The held set (§6.2 of Gregory et al. 2000): the probe, a body it attaches to (grabbed
// rigidly, or turned about its hinge at a rim point or at the centre), the hinged bodies it may
// turn, and the proxy step's motion applied to them.
#include <algorithm>
#include <cmath>

#include "core/geometry/rotation.h"
#include "core/sim/tick.h"

namespace hapticd::sim::detail {
namespace {

using collision::BodyKind;
using geom::Quat;
using geom::Transform;

void setHeldPoses(SceneState& s) {
  s.world.setPose(s.held.ids[0], s.X_W_probe);
  if (s.held.mode == AttachMode::kFree || s.held.attached == kNoBody)
    return;
  if (s.held.mode == AttachMode::kGrab) {
    const Transform T = s.X_W_probe.toTransform() * s.held.X_probe_attached;
    geom::Pose X;
    X.translation = T.t;
    X.rotation = glm::normalize(glm::quat_cast(T.R));
    s.world.setPose(s.held.attached, X);
  }
}

// a dynamic body grabbed rigidly: its mass properties for its weight and inertia at the hand
void startGrab(const SimModel& m, SceneState& s, std::uint32_t body, const geom::Pose& Xb) {
  s.grab.mass = 0.0;
  if (!m.dynamics_active || m.info[body].kind != BodyKind::kDynamic)
    return;
  const dynamics::MassProperties mp = s.dynamics->massProperties(body);
  if (!(mp.mass > 0.0 && std::isfinite(mp.mass)))
    return;
  GrabState& g = s.grab;
  g.mass = mp.mass;
  g.gravity_W = s.dynamics->gravity(body);
  g.com_B = mp.com_B;
  g.inertia_B = mp.inertia_B;
  const Vec3 c = Xb.translation + Xb.rotation * g.com_B;
  g.r_P = glm::conjugate(s.X_W_probe.rotation) * (c - comW(m, s, s.held.ids[0]));
  g.history = 0;
  g.a_f = g.alpha_f = Vec3{0.0};
}

}  // namespace

void attach(const SimModel& m, SceneState& s, std::uint32_t body) {
  const BodyInfo& bi = m.info[body];
  HeldSet& h = s.held;
  h.attached = body;
  s.world.setAsleep(body, false);
  if (m.dynamics_active)
    s.dynamics->setDriven(body, true);  // the proxy step moves it now; the dynamics see it held
  h.ids[1] = body;
  h.count = 2;
  updateDriven(m, s);
  const geom::Pose& Xb = s.world.pose(body);
  if (!bi.hinge) {
    h.mode = AttachMode::kGrab;
    h.X_probe_attached = geom::relativeTransform(s.X_W_probe, Xb);
    h.radius_m = heldRadius(m, s, comW(m, s, m.probe));
    setRotationalStiffness(m, s);
    startGrab(m, s, body, Xb);
    return;
  }
  h.hinge_o_W = Xb.translation + Xb.rotation * bi.hinge_o_B;
  h.hinge_a_W = glm::normalize(Xb.rotation * bi.hinge_a_B);
  const Vec3 c = comW(m, s, m.probe);
  const Vec3 rel = c - h.hinge_o_W;
  const Vec3 radial = rel - glm::dot(rel, h.hinge_a_W) * h.hinge_a_W;
  const double body_radius = radiusAbout(m, s, body, comW(m, s, body));
  using HA = ResponseOptions::HingeAttach;
  const HA choice = m.options.response.hinge_attach;
  const bool centre =
      choice == HA::kCentre ||
      (choice == HA::kAuto &&
       glm::length(radial) < m.options.response.centre_radius_fraction * body_radius);
  if (centre) {
    h.mode = AttachMode::kCentre;
    h.centre_h_W = c;
    h.q_attached_probe = glm::normalize(glm::conjugate(Xb.rotation) * s.X_W_probe.rotation);
  } else {
    h.mode = AttachMode::kRim;
    h.X_attached_probe = geom::relativeTransform(Xb, s.X_W_probe);
  }
  h.radius_m = heldRadius(m, s, comW(m, s, body));
  setRotationalStiffness(m, s);
}

void updateDriven(const SimModel& m, SceneState& s) {
  s.driven.count = 0;
  for (std::uint32_t id = 0; id < m.info.size(); ++id) {
    const BodyInfo& bi = m.info[id];
    if (!bi.hinge || isHeld(s, id) || bi.kind == BodyKind::kStatic || s.active[id] == 0)
      continue;
    if (m.dynamics_active && bi.kind == BodyKind::kDynamic)
      continue;  // the dynamics turn it on its hinge joint, with its inertia
    if (s.driven.count == s.driven.ids.size())
      break;  // more stay fixed (docs/response.md)
    s.driven.ids[s.driven.count++] = id;
    s.world.setAsleep(id, false);
  }
}

void detach(const SimModel& m, SceneState& s) {
  HeldSet& h = s.held;
  if (h.attached != kNoBody && m.dynamics_active)
    s.dynamics->setDriven(h.attached, false);
  if (h.attached != kNoBody && !m.info[h.attached].hinge &&
      !(m.dynamics_active && m.info[h.attached].kind == BodyKind::kDynamic))
    s.world.setAsleep(h.attached, true);
  h.mode = AttachMode::kFree;
  h.attached = kNoBody;
  s.grab.mass = 0.0;
  h.count = 1;
  h.radius_m = m.probe_radius_m;
  setRotationalStiffness(m, s);
  updateDriven(m, s);
}

void setRotationalStiffness(const SimModel& m, SceneState& s) {
  // k_r = k_c r^2, unless the options fix it: r is the held set's radius when a body is grabbed
  // or attached at its centre (its feel comes through the handle's torque), the probe's own when
  // free or attached at a rim (the hand does not turn with a rim: the probe's orientation does)
  const ResponseOptions& r = m.options.response;
  const AttachMode mode = s.held.mode;
  const double radius =
      mode == AttachMode::kGrab || mode == AttachMode::kCentre ? s.held.radius_m : m.probe_radius_m;
  const double kr =
      r.rot_stiffness_nm_per_rad > 0.0 ? r.rot_stiffness_nm_per_rad : m.k_c * radius * radius;
  s.coupling.setRotational(kr, r.coupling_damping_factor * kr * r.tick_s);
  s.proxy.rot_coupling_stiffness = kr;
}

void updateAttachment(const SimModel& m, SceneState& s, const TickInput& input) {
  const std::uint32_t mask = m.options.response.attach_button_mask;
  const bool down = (input.buttons & mask) != 0, was = (s.held.last_buttons & mask) != 0;
  s.held.last_buttons = input.buttons;
  if (down && !was && s.held.mode == AttachMode::kFree) {
    // the nearest non-static body the probe touches
    std::uint32_t best = kNoBody;
    double best_d = m.attach_distance_m;
    for (const collision::Contact& c : s.world.contacts()) {
      if (!c.answered)
        continue;
      if (c.body_a != m.probe && c.body_b != m.probe)
        continue;
      const std::uint32_t other = c.body_a == m.probe ? c.body_b : c.body_a;
      if (m.info[other].kind == BodyKind::kStatic || m.excluded(m.probe, other))
        continue;
      if (c.distance <= best_d)
        best_d = c.distance, best = other;
    }
    if (best != kNoBody) {
      attach(m, s, best);
      gatherRows(m, s);
    }
  } else if (!down && was && s.held.mode != AttachMode::kFree) {
    detach(m, s);
    gatherRows(m, s);
  }
}

void applyStep(const SimModel& m, SceneState& s, const response::ProxyStep& step) {
  for (std::uint32_t d = 0; d < s.driven.count; ++d) {
    if (step.driven_angle[d] == 0.0)
      continue;  // unmoved: its pairs keep their answers
    const std::uint32_t id = s.driven.ids[d];
    const BodyInfo& bi = m.info[id];
    geom::Pose X = s.world.pose(id);
    const Vec3 o = X.translation + X.rotation * bi.hinge_o_B;
    const Vec3 a = glm::normalize(X.rotation * bi.hinge_a_B);
    const Quat dq = geom::quatFromRotationVector(a * step.driven_angle[d]);
    X.rotation = glm::normalize(dq * X.rotation);
    X.translation = o + dq * (X.translation - o);
    s.world.setPose(id, X);
  }
  HeldSet& h = s.held;
  if (h.mode == AttachMode::kFree || h.mode == AttachMode::kGrab) {
    const Vec3 c = comW(m, s, m.probe);
    const Quat dq = geom::quatFromRotationVector(step.dtheta_W);
    s.X_W_probe.rotation = glm::normalize(dq * s.X_W_probe.rotation);
    s.X_W_probe.translation = c + step.dc_W + dq * (s.X_W_probe.translation - c);
    setHeldPoses(s);
    return;
  }
  // a hinge: turn the attached body about its axis by the step's one coordinate
  const Quat dq = geom::quatFromRotationVector(h.hinge_a_W * step.x[0]);
  geom::Pose Xb = s.world.pose(h.attached);
  Xb.rotation = glm::normalize(dq * Xb.rotation);
  Xb.translation = h.hinge_o_W + dq * (Xb.translation - h.hinge_o_W);
  s.world.setPose(h.attached, Xb);
  if (h.mode == AttachMode::kRim) {
    const Transform T = Xb.toTransform() * h.X_attached_probe;
    s.X_W_probe.translation = T.t;
    s.X_W_probe.rotation = glm::normalize(glm::quat_cast(T.R));
  } else {
    s.X_W_probe.rotation = glm::normalize(Xb.rotation * h.q_attached_probe);
    s.X_W_probe.translation = h.centre_h_W - s.X_W_probe.rotation * m.info[m.probe].com_B;
  }
  s.world.setPose(m.probe, s.X_W_probe);
}

}  // namespace hapticd::sim::detail
