// One servo tick of the whole simulation (docs/architecture.md "One servo tick"; §3.1, §6.1 of
// Gregory et al. 2000): edits seen, attachment, the predictive distance, the proxy's step (backed
// off when it went too deep), the dynamics, the coupling and the raw wrench on the hand (the
// caller's output stage shapes it: response::OutputStage), the outputs.
#include <algorithm>
#include <cmath>

#include "core/geometry/rotation.h"
#include "core/sim/tick.h"

namespace hapticd::sim {
namespace {

using collision::BodyKind;
using detail::comW;
using geom::Quat;

bool finitePose(const Vec3& p, const Quat& q) {
  return geom::finite(p) && geom::finite(q);
}

// scene edits since the last tick: the collision world and the rows see them before the proxy
// steps (a kinematic body moved into the proxy pushes it out from this tick's rows)
struct EditsSeen {
  std::uint32_t pairs_tested = 0;
  double pusher_travel = 0.0;  // the farthest a kinematic body touching the held set was moved
};

EditsSeen beginTick(const SimModel& m, SceneState& s, const TickInput& input) {
  if (s.first_step && m.info[m.probe].scene_index < 0 &&
      geom::finite(input.X_W_device.translation) &&
      input.X_W_device.translation != s.X_W_probe.translation) {
    // the probe sphere has no pose in the scene: it starts where the device is (where it is
    // already, the world was stepped and the rows gathered there: by makeState, or by a swap's
    // prewarm at the device's pose)
    s.X_W_probe.translation = input.X_W_device.translation;
    s.world.setPose(m.probe, s.X_W_probe);
    s.world.step();
    detail::gatherRows(m, s);
  }
  s.first_step = false;
  EditsSeen e;
  if (!s.world_dirty)
    return e;
  s.world_dirty = false;
  e.pairs_tested = s.world.step().pairs_tested;
  detail::gatherRows(m, s);
  const auto rows = s.rows.rows();
  for (std::size_t i = 0; i < rows.size() && i < s.row_env.size(); ++i) {
    if (rows[i].first < 0)
      e.pusher_travel = std::max(e.pusher_travel, s.edit_travel[s.row_env[i]]);
  }
  std::fill(s.edit_travel.begin(), s.edit_travel.end(), 0.0);
  // at most one more safe distance: the rows see every surface within two of them (pairs
  // within max_travel * (1 + sides) get rows), so the proxy never steps past one it has no
  // row for, even when a client teleports a body touching it
  e.pusher_travel = std::min(e.pusher_travel, m.max_travel_m);
  return e;
}

// the device's handle: the probe body's centre of mass placed at the device pose
struct Device {
  Vec3 h_W{0.0};
  Quat q{1.0, 0.0, 0.0, 0.0};
  bool finite = false;
};

// the predictive distance (§5.2): delta = v_c dt, v_c bounding the speed of the held points
Device trackDevice(const SimModel& m, SceneState& s, const TickInput& input) {
  const ResponseOptions& r = m.options.response;
  Device dev;
  dev.h_W = input.X_W_device.translation + input.X_W_device.rotation * m.info[m.probe].com_B;
  dev.q = input.X_W_device.rotation;
  dev.finite = finitePose(dev.h_W, dev.q);
  DeviceTrack& t = s.device;
  if (t.have_prev && dev.finite) {
    const double v = glm::length(dev.h_W - t.prev_h_W) / r.tick_s +
                     glm::length(geom::rotationVector(dev.q * glm::conjugate(t.prev_q))) /
                         r.tick_s * s.held.radius_m;
    t.v_c = std::max(std::isfinite(v) ? v : 0.0, t.v_c * m.speed_decay);
  }
  if (dev.finite) {
    t.have_prev = true;
    t.prev_h_W = dev.h_W;
    t.prev_q = dev.q;
  }
  s.delta_m =
      r.predictive
          ? std::clamp(t.v_c * r.tick_s,
                       std::min(m.max_travel_m, r.min_predictive_fraction * s.held.radius_m),
                       m.max_travel_m)
          : 0.0;
  s.proxy.delta = s.delta_m;
  return dev;
}

// the proxy's problem (§5.2): its handle, the device's, the hinge it turns about, the driven
// hinges; a grabbed dynamic body's weight shifts the target (returned: m g, or zero)
Vec3 proxyProblem(const SimModel& m, SceneState& s, const Device& dev, response::ProxyProblem* pb) {
  const HeldSet& h = s.held;
  pb->h_W = comW(m, s, m.probe);
  pb->q_handle = s.X_W_probe.rotation;
  pb->h_target_W = dev.h_W;
  pb->q_target = dev.q;
  pb->radius = h.radius_m;
  if (h.mode == AttachMode::kRim || h.mode == AttachMode::kCentre) {
    pb->c_W = comW(m, s, h.attached);
    pb->basis = response::ProxyBasis::hinge(h.hinge_o_W, h.hinge_a_W, pb->c_W);
    pb->handle_fixed = h.mode == AttachMode::kCentre;
  } else {
    pb->c_W = pb->h_W;
  }
  if (!dev.finite) {
    // a bad pose moves nothing: hold the proxy where it is
    pb->h_target_W = pb->h_W;
    pb->q_target = pb->q_handle;
  }
  // a grabbed dynamic body's weight at its centre of mass: the proxy's target shifted by what
  // the coupling needs to carry it, so that the hand feels m g in free space and a surface the
  // held set rests on takes it (docs/dynamics.md)
  Vec3 grab_weight{0.0};
  const GrabState& g = s.grab;
  if (g.mass > 0.0 && h.mode == AttachMode::kGrab && m.options.response.grab_weight && dev.finite) {
    const geom::Pose& Xb = s.world.pose(h.attached);
    const Vec3 c = Xb.translation + Xb.rotation * g.com_B;
    grab_weight = g.mass * g.gravity_W;
    const Vec3 torque = glm::cross(c - pb->h_W, grab_weight);
    const double kc = s.proxy.coupling_stiffness, kr = s.proxy.rot_coupling_stiffness;
    if (kc > 0.0)
      pb->h_target_W = dev.h_W + grab_weight / kc;
    if (kr > 0.0)
      pb->q_target = glm::normalize(geom::quatFromRotationVector(torque / kr) * dev.q);
  }
  pb->driven_count = s.driven.count;
  for (std::uint32_t d = 0; d < s.driven.count; ++d) {
    const std::uint32_t id = s.driven.ids[d];
    const BodyInfo& bi = m.info[id];
    const geom::Pose& X = s.world.pose(id);
    s.driven.before[d] = X;
    pb->driven[d].o_W = X.translation + X.rotation * bi.hinge_o_B;
    pb->driven[d].a_W = glm::normalize(X.rotation * bi.hinge_a_B);
    pb->driven[d].radius = bi.hinge_radius;
    // a faint hold, so that an untouched hinge stays put: 1e-6 of the coupling at its radius
    pb->driven[d].drag = 1e-6 * m.k_c * std::max(bi.hinge_radius * bi.hinge_radius, 1e-12);
  }
  return grab_weight;
}

// one sub-step of the proxy, the collision step at the new pose and its rows; a step that went
// too deep (deeper than the allowance and deeper than it began, by more than rounding: 1e-6 of
// the allowance) is pushed back out along the deepest pair's normal, or else bisected back,
// three halvings and then undone (docs/response.md "A sub-step too deep"). A proxy already
// deeper (pushed there by a body) may move at that depth or out, never in. Until 2026-12-04 a
// step was too deep only when it went deeper by a twentieth of the allowance, and the third
// halving was kept whatever its depth: where the rows misled every step (a shaded normal tilted
// from its face, an edge's normal replaced by a face's, a tilted facet of the probe sphere) the
// proxy crept in by just less than that each tick, without bound (issue 16: 3.86 mm)
struct ProxyMove {
  response::ProxyStep step;
  collision::StepStats stats;
  double penetration_m = 0.0;
  bool backed_off = false;
  bool rows_dropped = false;
  std::uint32_t substeps = 0;
};

ProxyMove moveProxyOnce(const SimModel& m,
                        SceneState& s,
                        const response::ProxyProblem& pb,
                        double pusher_travel) {
  ProxyMove mv;
  const geom::Pose probe_before = s.X_W_probe;
  const geom::Pose attached_before =
      s.held.attached == kNoBody ? geom::Pose{} : s.world.pose(s.held.attached);
  const double pen_before = s.last_penetration_m;
  // a kinematic body pushing the held set moves it as far as it moved itself, so that a pusher
  // faster than the safe distance does not run over the proxy (docs/dynamics.md)
  s.proxy.max_travel = m.max_travel_m + pusher_travel;
  mv.step = response::solveProxyStep(pb, s.rows.rows(), s.proxy);
  s.proxy.max_travel = m.max_travel_m;
  detail::applyStep(m, s, mv.step);
  mv.stats = s.world.step();
  mv.penetration_m = detail::gatherRows(m, s);
  const double allowance = m.penetration_allowance_m;
  const auto tooDeep = [&](double pen) {
    return pen > allowance && pen - pen_before > 1e-6 * allowance;
  };
  // first pushed back out of the deepest pair along its normal by what it went too deep, up to
  // three times (the depth the rows read of a face against a face is its clipped points' along
  // the face's normal, a little more than the pair's along its own), at most a safe distance in
  // all, as a proxy pressed on a surface slides along it: a step the rows misled a little (a
  // shaded normal, a tilted facet, an edge read as a face) keeps its motion along the surface,
  // without going in. Only a freely held or grabbed set, and only when that leaves it no longer
  // too deep; the sub-steps then go on (their own rules stop them)
  const HeldSet& h = s.held;
  if (tooDeep(mv.penetration_m) && (h.mode == AttachMode::kFree || h.mode == AttachMode::kGrab)) {
    const geom::Pose probe_stepped = s.X_W_probe;
    Vec3 pushed{0.0};
    double pen = mv.penetration_m;
    for (int k = 0; k < 3 && tooDeep(pen); ++k) {
      const Vec3 n_deep = s.deepest_normal_W;
      const double excess = pen - std::max(allowance, pen_before);
      const double push = excess + 1e-3 * allowance;
      if (!(glm::dot(n_deep, n_deep) > 0.5) || glm::length(pushed) + push > m.max_travel_m)
        break;
      response::ProxyStep out;  // a translation of the held set, nothing else
      out.dc_W = push * n_deep;
      detail::applyStep(m, s, out);
      pushed += out.dc_W;
      const collision::StepStats again = s.world.step();
      mv.stats.pairs_tested += again.pairs_tested;
      mv.stats.pairs_skipped = again.pairs_skipped;
      pen = detail::gatherRows(m, s);
    }
    if (!tooDeep(pen)) {
      mv.penetration_m = pen;
      mv.step.dc_W += pushed;
      return mv;
    }
    s.X_W_probe = probe_stepped;  // the halvings below start again from probe_before
  }
  for (int k = 0; k < 4 && tooDeep(mv.penetration_m); ++k) {
    mv.backed_off = true;
    s.X_W_probe = probe_before;
    if (s.held.attached != kNoBody)
      s.world.setPose(s.held.attached, attached_before);
    for (std::uint32_t d = 0; d < s.driven.count; ++d)
      s.world.setPose(s.driven.ids[d], s.driven.before[d]);
    // halve it three times; the fourth time undo it
    const double f = k < 3 ? 0.5 : 0.0;
    for (double& angle : mv.step.driven_angle)
      angle *= f;
    s.world.setPose(m.probe, s.X_W_probe);
    for (double& x : mv.step.x)
      x *= f;
    mv.step.dc_W *= f;
    mv.step.dtheta_W *= f;
    detail::applyStep(m, s, mv.step);
    const collision::StepStats again = s.world.step();
    mv.stats.pairs_tested += again.pairs_tested;
    mv.stats.pairs_skipped = again.pairs_skipped;
    mv.penetration_m = detail::gatherRows(m, s);
  }
  return mv;
}

// how far the proxy's handle is from its target: the distance plus the angle times the radius
double couplingError(const response::ProxyProblem& pb) {
  return glm::length(pb.h_target_W - pb.h_W) +
         glm::length(geom::rotationVector(pb.q_target * glm::conjugate(pb.q_handle))) * pb.radius;
}

// a row of the held set within delta, or so near it that rounding decides (a row the step left
// at its equilibrium is within delta by its force over its stiffness, which may be next to
// nothing: a margin of 1e-9 of the held set's radius, rounding's, the same in mm and in km). The
// margin was 1e-3 safe distances until 2026-12-06: a row that far beyond delta pushes nothing,
// yet held the proxy as pressed, the sub-steps stopped, and the coupling's lag was felt with no
// contact: rolling off a pillar's edge in the stress demo scaled by 1e3 (the same stiffness in
// N/m), a row at 1.0003 delta left 10 N on the hand; scaled by 1e-3 the proxy lagged 0.8 mm /
// scale in free space (Demo/ProxyGeometryScale)
bool pressed(const SceneState& s) {
  const double reach = s.delta_m + 1e-9 * s.held.radius_m;
  for (const response::ContactRow& r : s.rows.rows()) {
    if (r.gap < reach && r.first < 0)
      return true;
  }
  return false;
}

// the proxy's move of one tick (§3.2, §5.2): sub-steps of at most the safe distance, each from
// the rows seen at its start, until the proxy reaches its equilibrium with the device (a step the
// safe distance did not cut, and that ended touching what stopped it, if anything did: rows of
// a rounded edge or of a tooth turning away may stop a step short of a surface it then does not
// touch, and the proxy steps on), a sub-step brings it no nearer its target by a quarter of a safe
// distance nor out of a surface (pressed or wedged, it slides no farther; pushed by a moving
// body, it is pushed out), a sub-step is bisected back, or
// max_substeps are taken. So in free space the proxy is at the device at the end of the tick
// whatever its speed, and the safe distance only limits how far it travels between two looks at
// what is near (toward contact).
ProxyMove moveProxy(const SimModel& m,
                    SceneState& s,
                    const Device& dev,
                    double pusher_travel,
                    Vec3* grab_weight) {
  ProxyMove mv;
  const std::uint32_t most = std::max<std::uint32_t>(m.options.response.max_substeps, 1);
  double error = 0.0, moved = 0.0, pen = 0.0;
  bool stopped_short = false;  // the last sub-step was stopped by rows, then touched nothing
  Vec3 last_dc{0.0}, last_dtheta{0.0};  // the last sub-step's move
  for (std::uint32_t k = 0; k < most; ++k) {
    response::ProxyProblem pb;
    *grab_weight = proxyProblem(m, s, dev, &pb);
    pb.sliding = s.proxy_sliding;
    const double error_before = couplingError(pb);
    // no nearer by a quarter of a safe distance, not pushed out of a surface by as much, and
    // the last sub-step hardly moved the handle or moved it away: it turns or slides on the spot
    // (a facet flipping under a face); unless the last sub-step stopped short of a surface
    const double quarter = 0.25 * m.max_travel_m;
    if (k > 0 && !stopped_short && !(error_before < error - quarter) &&
        !(s.last_penetration_m < pen - quarter) && !(moved >= quarter && error_before <= error))
      break;
    error = error_before;
    pen = s.last_penetration_m;
    const ProxyMove one = moveProxyOnce(m, s, pb, k == 0 ? pusher_travel : 0.0);
    moved = glm::length(one.step.dc_W);
    // this sub-step undid the last one (the proxy is back where it was two sub-steps ago, within
    // a quarter of a safe distance, turned back as well): a cycle of two, one sub-step toward
    // the device into a surface, the next pushed out of it (a probe on a sharp edge between two
    // pieces whose rows alternate). Each of the pair makes progress by the test above (the
    // coupling error, then the penetration), so without this the tick ran all max_substeps, the
    // proxy where it started (an imported dragon: 64 sub-steps a tick, ticks of 0.4 to 10 ms)
    const bool undone = k > 0 && moved >= quarter &&
                        glm::length(one.step.dc_W + last_dc) < quarter &&
                        glm::length(one.step.dtheta_W + last_dtheta) * pb.radius < quarter;
    last_dc = one.step.dc_W;
    last_dtheta = one.step.dtheta_W;
    s.proxy_sliding = one.step.sliding;
    mv.step = one.step;
    mv.stats.pairs_tested += one.stats.pairs_tested;
    mv.stats.pairs_skipped = one.stats.pairs_skipped;
    mv.penetration_m = one.penetration_m;
    mv.backed_off = mv.backed_off || one.backed_off;
    mv.rows_dropped = mv.rows_dropped || one.step.rows_dropped;
    ++mv.substeps;
    // the step's equilibrium was reached (not cut by the safe distance): done, unless rows it
    // solved with stopped it and, moved, the held set is within delta of nothing (the rows
    // were a linearisation of a surface the proxy has moved around: a rounded edge, a tooth
    // turning away): then it is not at its equilibrium and steps on toward the device
    stopped_short = one.step.active > 0 && !pressed(s);
    if (one.backed_off || (!one.step.travel_limited && !stopped_short) || undone)
      break;
  }
  return mv;
}

// the dynamics (only when the plan asks): after this tick's collision step, with the held body
// (and an attached dynamic body) following the proxy with infinite mass; the spread impulses
// on the held set are the impact wrench (about its centre of mass)
response::Wrench stepDynamics(const SimModel& m, SceneState& s, TickOutput* out) {
  response::Wrench impact;
  if (!m.dynamics_active)
    return impact;
  dynamics::Dynamics& dyn = *s.dynamics;
  if (s.held.attached != kNoBody && m.info[s.held.attached].kind == BodyKind::kDynamic)
    dyn.setKinematicPose(s.held.attached, s.world.pose(s.held.attached));
  dynamics::HeldInput held;
  held.mode = dynamics::HeldMode::kKinematic;
  held.X_WB_target = s.X_W_probe;
  const dynamics::StepReport dr = dyn.step(s.world, m.options.response.tick_s, &held);
  if ((dr.flags & dynamics::kStepAsleep) == 0) {
    out->flags |= kTickDynamics;
    // the step moved bodies the held set has rows with: the rows, and the depth the proxy's
    // back-off compares a sub-step with, are stale until the world is stepped again, so the
    // next tick starts by stepping it (beginTick), as after an edit. Otherwise a body the
    // dynamics push into the held set (wedged, or turning into it) deepens the contact
    // between the ticks, the proxy's first sub-step is judged to have gone deeper by itself
    // and is bisected back, and the body sinks into the proxy tick after tick
    if (detail::rowsWithDynamicBody(m, s))
      s.world_dirty = true;
  }
  if ((dr.flags & dynamics::kStepCapacityFull) != 0)
    out->flags |= kTickCapacityFull;
  out->dynamics_contact_points = dr.contact_points;
  impact.force_n = dyn.heldFeedback().force_W_n;
  impact.torque_nm = dyn.heldFeedback().torque_W_nm;
  if (s.kinematic_target_pending) {
    // the dynamics moved a kinematic body to its new target in this step
    s.kinematic_target_pending = false;
    s.world_dirty = true;
  }
  return impact;
}

// a body grabbed rigidly, felt with its inertia: -m a and -(I α + ω × I ω) of the body rigidly
// at the device's pose, a and α the device's low-passed accelerations (docs/dynamics.md);
// false (and *w zero) when there is none to add this tick
bool grabInertia(const SimModel& m, SceneState& s, const Device& dev, response::Wrench* w) {
  GrabState& g = s.grab;
  if (!(g.mass > 0.0 && s.held.mode == AttachMode::kGrab && m.options.response.grab_inertia))
    return false;
  if (!dev.finite) {
    g.history = 0;
    g.a_f = g.alpha_f = Vec3{0.0};
    return false;
  }
  // the body rigidly at the device's pose: its centre of mass, the device's rotation
  const double dt = m.options.response.tick_s;
  const Vec3 c_dev = dev.h_W + dev.q * g.r_P;
  Vec3 w_dev{0.0};
  if (g.history >= 1)
    w_dev = geom::rotationVector(dev.q * glm::conjugate(g.q1)) / dt;
  if (g.history >= 2) {
    const Vec3 a = (c_dev - 2.0 * g.c1 + g.c2) / (dt * dt);
    const Vec3 alpha = (w_dev - g.w1) / dt;
    if (geom::finite(a) && geom::finite(alpha)) {
      g.a_f += m.grab_beta * (a - g.a_f);
      g.alpha_f += m.grab_beta * (alpha - g.alpha_f);
    }
  }
  g.c2 = g.c1;
  g.c1 = c_dev;
  g.q1 = dev.q;
  g.w1 = w_dev;
  g.history = std::min<std::uint32_t>(g.history + 1, 2);
  const geom::Mat3 R = glm::mat3_cast(s.world.pose(s.held.attached).rotation);
  const geom::Mat3 I_W = R * g.inertia_B * glm::transpose(R);
  w->force_n = -g.mass * g.a_f;
  w->torque_nm =
      -(I_W * g.alpha_f + glm::cross(w_dev, I_W * w_dev)) + glm::cross(c_dev - dev.h_W, w->force_n);
  if (geom::finite(w->force_n) && geom::finite(w->torque_nm))
    return true;
  *w = response::Wrench{};
  return false;
}

// what the tick says besides the force: the penalty wrench, counts, flags, the lists
void fillOutput(const SimModel& m, SceneState& s, const ProxyMove& mv, TickOutput* out) {
  const HeldSet& h = s.held;
  const Vec3 c_ref = h.mode == AttachMode::kRim || h.mode == AttachMode::kCentre
                         ? comW(m, s, h.attached)
                         : comW(m, s, m.probe);
  const response::Wrench pw = response::penaltyWrench(s.rows.rows(), c_ref, s.delta_m);
  out->contact_force_W_n = pw.force_n;
  out->contact_torque_W_nm = pw.torque_nm;
  out->X_W_proxy = s.X_W_probe;
  std::uint32_t active = 0;
  for (const response::ContactRow& r : s.rows.rows())
    active += r.gap < s.delta_m && r.first < 0 ? 1u : 0u;
  out->contacts = active;
  out->held_dynamic_contacts = detail::heldDynamicContacts(m, s);
  out->max_penetration_m = std::max(0.0, mv.penetration_m);
  out->pairs_skipped = mv.stats.pairs_skipped;
  if (mv.stats.pairs_skipped > 0)
    out->flags |= kTickPairsSkipped;
  if (s.rows.full() || mv.rows_dropped)
    out->flags |= kTickCapacityFull;
  out->attach_mode = static_cast<std::uint8_t>(h.mode);
  out->attached_body = h.attached == kNoBody ? -1 : m.info[h.attached].scene_index;
  out->travel_limited = mv.step.travel_limited;
  out->proxy_substeps = mv.substeps;
  out->proxy_stuck = mv.step.stuck;
  out->proxy_sliding = mv.step.sliding;
  out->delta_m = s.delta_m;
  // the poses of the bodies given one since the last tick: every pose the dynamics, an edit or
  // the held set give a body goes to the collision world, so the others have not changed (a
  // resting scene costs nothing here, whatever its size)
  const auto poseOf = [&](std::uint32_t id) {
    return m.dynamics_active && m.info[id].kind == BodyKind::kDynamic ? s.dynamics->pose(id)
                                                                      : s.world.pose(id);
  };
  if (s.body_poses_stale) {
    for (std::size_t i = 0; i < m.pose_bodies.size(); ++i)
      s.body_poses[i].X_WB = poseOf(m.pose_bodies[i]);
    s.body_poses_stale = false;
  } else {
    for (const std::uint32_t id : s.world.posed()) {
      const std::int32_t i = id < m.pose_slot.size() ? m.pose_slot[id] : -1;
      if (i >= 0)
        s.body_poses[static_cast<std::size_t>(i)].X_WB = poseOf(id);
    }
  }
  s.world.clearPosed();
  detail::fillContactPoints(m, s, out);
}

}  // namespace

TickOutput step(const SimModel& m, SceneState& s, const TickInput& input) {
  TickOutput out;
  const collision::CollisionWorld::DepthCounters depth_before = s.world.depthCounters();
  const EditsSeen edits = beginTick(m, s, input);
  detail::updateAttachment(m, s, input);
  const Device dev = trackDevice(m, s, input);
  Vec3 grab_weight{0.0};
  const ProxyMove mv = moveProxy(m, s, dev, edits.pusher_travel, &grab_weight);
  if (mv.backed_off)
    out.flags |= kTickBackedOff;
  response::Wrench impact = stepDynamics(m, s, &out);

  // the coupling between the device and the proxy, the dynamics' impacts moved from the held
  // set's centre of mass to the handle point, a grabbed body's inertia: the raw wrench, which
  // the caller's one output stage shapes (response::OutputStage; the servo loop, or
  // sim::withOutputStage offline)
  const Vec3 h_prx = s.held.mode == AttachMode::kCentre ? s.held.centre_h_W : comW(m, s, m.probe);
  response::Wrench raw = s.coupling.step(dev.h_W, dev.q, h_prx, s.X_W_probe.rotation);
  if (m.dynamics_active) {
    const Vec3 c_fb = s.dynamics->heldFeedback().com_W;
    impact.torque_nm += glm::cross(c_fb - h_prx, impact.force_n);
    raw.force_n += impact.force_n;
    raw.torque_nm += impact.torque_nm;
  }
  response::Wrench inertia;
  if (grabInertia(m, s, dev, &inertia)) {
    raw.force_n += inertia.force_n;
    raw.torque_nm += inertia.torque_nm;
  }
  out.device_ok = input.device_ok && dev.finite;
  if (!out.device_ok) {
    // nothing to couple: zero, and the coupling starts afresh
    s.coupling.reset();
    raw = response::Wrench{};
  }

  out.force_W_n = raw.force_n;
  out.torque_W_nm = raw.torque_nm;
  out.impact_force_W_n = impact.force_n;
  out.impact_torque_W_nm = impact.torque_nm;
  out.grab_weight_W_n = grab_weight;
  out.grab_inertia_force_W_n = inertia.force_n;
  out.grab_inertia_torque_W_nm = inertia.torque_nm;
  out.pairs_tested = mv.stats.pairs_tested + edits.pairs_tested;
  fillOutput(m, s, mv, &out);
  // every collision step of the tick (edits, the proxy's sub-steps, the dynamics' relists)
  const collision::CollisionWorld::DepthCounters& depth = s.world.depthCounters();
  out.depth_certified = static_cast<std::uint32_t>(depth.certified - depth_before.certified);
  out.depth_fallbacks = static_cast<std::uint32_t>(depth.fallbacks - depth_before.fallbacks);
  out.depth_cold = static_cast<std::uint32_t>(depth.cold - depth_before.cold);
  out.depth_untracked = static_cast<std::uint32_t>(depth.untracked - depth_before.untracked);
  return out;
}

}  // namespace hapticd::sim
