// One tick of the dynamics (§6.1 of Gregory et al. 2000): forces, contacts gathered from the
// collision world with their warm starts, the solves through the times of impact, drift
// correction, the held body's feedback, poses back to the world, sleep.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/dynamics/dynamics_internal.h"
#include "core/geometry/rotation.h"

namespace hapticd::dynamics {

using detail::kInf;
using detail::pairKey;
using detail::tangents;

namespace {

// a primitive without a material: frictionless, inelastic, combined by average as if declared
// (scene.h; built before main, never on the servo thread)
const scene::Material kNoMaterial = [] {
  scene::Material m;
  m.friction_combine_declared = m.restitution_combine_declared = true;
  return m;
}();

}  // namespace

// velocities first (semi-implicit Euler); the kinematic bodies' velocities that reach their
// targets; the speed clamp that keeps every body within the world's box margin per tick
void Dynamics::integrateForces(double dt, double margin, const HeldInput* held) {
  held_kinematic_ = false;
  bool held_wrench = false;
  if (held != nullptr && held_ >= 0 && static_cast<std::size_t>(held_) < bodies_.size()) {
    if (held->mode == HeldMode::kKinematic && geom::finite(held->X_WB_target.translation) &&
        geom::finite(held->X_WB_target.rotation) && glm::length(held->X_WB_target.rotation) > 0.5) {
      setKinematicPose(static_cast<std::uint32_t>(held_), held->X_WB_target);
      held_kinematic_ = true;
    } else if (held->mode == HeldMode::kWrench && geom::finite(held->force_W_n) &&
               geom::finite(held->torque_W_nm)) {
      held_wrench = true;
    }
  }
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    BodyState& b = bodies_[i];
    const bool held_here = held_kinematic_ && static_cast<std::int32_t>(i) == held_;
    b.infinite = b.motion != scene::Motion::kDynamic || held_here || b.driven || !b.enabled;
    b.pv = Vec3{0.0};
    b.pw = Vec3{0.0};
    if (!b.enabled) {
      // out of the scene: frozen where it left (no gravity, no velocity)
      b.inv_inertia_W = Mat3{0.0};
      b.v_W = b.w_W = Vec3{0.0};
      b.has_target = false;
      continue;
    }
    if (b.infinite) {
      b.inv_inertia_W = Mat3{0.0};
      if (b.motion == scene::Motion::kStatic)
        continue;
      if (b.has_target) {
        b.v_W = (b.target_x - b.x_W) / dt;
        b.w_W = geom::rotationVector(b.target_q * glm::conjugate(b.q)) / dt;
      } else if (b.coast) {
        b.v_W = b.v_coast;
        b.w_W = b.w_coast;
      } else {
        b.v_W = Vec3{0.0};
        b.w_W = Vec3{0.0};
      }
      continue;
    }
    b.has_target = false;
    Vec3 force = b.force_W, torque = b.torque_W;
    if (held_wrench && static_cast<std::int32_t>(i) == held_) {
      force += held->force_W_n;
      torque += held->torque_W_nm;
    }
    b.v_W += dt * (b.gravity_W + b.inv_mass * force);
    b.updateInertia();
    b.w_W += dt * (b.inv_inertia_W * torque);
    if (!geom::finite(b.v_W) || !geom::finite(b.w_W)) {
      b.v_W = Vec3{0.0};
      b.w_W = Vec3{0.0};
    }
    {
      // no tunnelling: a body never travels more than this per tick
      const double limit = std::max(margin, options_.max_travel_fraction * b.size);
      const double reach = glm::length(b.v_W) * dt;
      const double spin = glm::length(b.w_W) * b.size * dt;
      if (reach > limit || spin > limit) {
        if (reach > limit)
          b.v_W *= limit / reach;
        if (spin > limit)
          b.w_W *= limit / spin;
        ++counters_.speed_clamped;
        step_flags_ |= kStepSpeedClamped;
      }
    }
  }
}

void Dynamics::gatherContacts(std::span<const collision::Contact> contacts, StepReport& report) {
  points_.clear();
  const std::size_t cap = max_points_;
  std::size_t warm = 0;  // warm_ is sorted like the contacts: walk both
  for (const collision::Contact& c : contacts) {
    if (!c.answered || c.body_a >= bodies_.size() || c.body_b >= bodies_.size())
      continue;
    BodyState& A = bodies_[c.body_a];
    BodyState& B = bodies_[c.body_b];
    if ((A.infinite && B.infinite) || !A.enabled || !B.enabled)
      continue;
    if (!no_collide_.empty() &&
        std::binary_search(no_collide_.begin(), no_collide_.end(), pairKey(c.body_a, c.body_b))) {
      continue;
    }
    if (c.age > 0)
      step_flags_ |= kStepStaleContacts;
    // materials of the two primitives (none declared: frictionless, no restitution)
    const auto material = [&](std::uint32_t body, std::uint32_t prim) -> const scene::Material& {
      if (body >= scene_->bodies.size())
        return kNoMaterial;
      const auto& prims = scene_->bodies[body].primitives;
      if (prim >= prims.size())
        return kNoMaterial;
      const std::int32_t m = prims[prim].material;
      return m >= 0 && static_cast<std::size_t>(m) < scene_->materials.size()
                 ? scene_->materials[static_cast<std::size_t>(m)]
                 : kNoMaterial;
    };
    const scene::Material& ma = material(c.body_a, c.prim_a);
    const scene::Material& mb = material(c.body_b, c.prim_b);
    // KHR_physics_rigid_bodies' combine rule, the one implementation the plan uses too
    const double e = scene::combineMaterials(ma, mb, scene::MaterialValue::kRestitution);
    const double mu_s = scene::combineMaterials(ma, mb, scene::MaterialValue::kStaticFriction);
    const double mu_d = scene::combineMaterials(ma, mb, scene::MaterialValue::kDynamicFriction);
    const double size = std::min(A.infinite ? kInf : A.size, B.infinite ? kInf : B.size);

    while (warm < warm_.size() &&
           std::tie(warm_[warm].a, warm_[warm].b, warm_[warm].prim_a, warm_[warm].prim_b) <
               std::tie(c.body_a, c.body_b, c.prim_a, c.prim_b)) {
      ++warm;
    }
    const std::size_t count = c.manifold.count;
    for (std::size_t k = 0; k < std::max<std::size_t>(count, 1); ++k) {
      Vec3 p, n;
      double gap;
      if (count > 0) {
        p = c.manifold.points[k].point;
        n = c.manifold.points[k].normal;
        gap = -c.manifold.points[k].depth;
      } else {
        p = 0.5 * (c.point_a + c.point_b);
        n = c.normal;
        gap = c.distance;
      }
      const double nl = glm::length(n);
      if (!(nl > 0.5) || !geom::finite(p) || !std::isfinite(gap))
        continue;
      if (points_.size() == cap) {
        ++counters_.points_dropped;
        step_flags_ |= kStepCapacityFull;
        continue;
      }
      ContactPoint& cp = points_.emplace_back();
      cp.a = c.body_a;
      cp.b = c.body_b;
      cp.prim_a = c.prim_a;
      cp.prim_b = c.prim_b;
      cp.n = n / nl;
      tangents(cp.n, &cp.t1, &cp.t2);
      cp.ra = p - A.x_W;
      cp.rb = p - B.x_W;
      cp.ra_B = glm::transpose(A.R) * cp.ra;
      cp.rb_B = glm::transpose(B.R) * cp.rb;
      cp.gap = gap;
      cp.size = size;
      cp.e = e;
      cp.mu_s = mu_s;
      cp.mu_d = mu_d;
      // warm start: the nearest point of the same primitive pair last tick
      double best = 0.05 * size * 0.05 * size;
      for (std::size_t w = warm; w < warm_.size() && warm_[w].a == cp.a && warm_[w].b == cp.b &&
                                 warm_[w].prim_a == cp.prim_a && warm_[w].prim_b == cp.prim_b;
           ++w) {
        const Vec3 dr = warm_[w].ra_B - cp.ra_B;
        const double d2 = glm::dot(dr, dr);
        if (d2 < best) {
          best = d2;
          cp.total_n = warm_[w].ln;
          cp.total_t = warm_[w].lt;
        }
      }
    }
  }
  // the held set pushes with at most held_max_force_n, shared by its points
  if (options_.held_max_force_n > 0.0) {
    const auto heldSet = [&](std::uint32_t i) {
      return static_cast<std::int32_t>(i) == held_ || bodies_[i].driven;
    };
    std::uint32_t n = 0;
    for (const ContactPoint& cp : points_)
      n += heldSet(cp.a) || heldSet(cp.b) ? 1u : 0u;
    const double per_point = n > 0 ? options_.held_max_force_n * tick_dt_ / n : 0.0;
    for (ContactPoint& cp : points_) {
      cp.ln_max = heldSet(cp.a) || heldSet(cp.b) ? per_point : 0.0;
      if (cp.ln_max > 0.0)
        cp.total_n = std::min(cp.total_n, cp.ln_max);
    }
  }
  report.contact_points = static_cast<std::uint32_t>(points_.size());
}

// moves every body by h with its current velocities; rotation with the angular momentum kept
// (a midpoint in orientation), so the gyroscopic term is exact for torque-free motion
void Dynamics::advance(double h) {
  if (h <= 0.0)
    return;
  for (ContactPoint& cp : points_) {
    const BodyState& A = bodies_[cp.a];
    const BodyState& B = bodies_[cp.b];
    cp.gap += glm::dot(B.velocityAt(cp.rb) - A.velocityAt(cp.ra), cp.n) * h;
  }
  for (BodyState& b : bodies_) {
    if (b.motion == scene::Motion::kStatic)
      continue;
    b.x_W += b.v_W * h;
    if (b.infinite) {
      b.q = glm::normalize(geom::quatFromRotationVector(b.w_W * h) * b.q);
      b.updateInertia();
      continue;
    }
    // the free-rigid-body splitting (McLachlan 1993; Touma & Wisdom 1994): in the principal
    // frame the kinetic energy is a sum of three terms, each of whose flows is an exact rotation
    // about one principal axis; composed symmetrically (Strang) they give a symplectic,
    // time-reversible step that keeps L exactly and the energy within a bounded error
    const Vec3 L = b.R * (b.inertia_B * (glm::transpose(b.R) * b.w_W));
    if (b.isotropic) {
      // a sphere-like body turns about its constant w: exact
      b.q = glm::normalize(geom::quatFromRotationVector(b.w_W * h) * b.q);
      b.updateInertia();
      continue;
    }
    Quat q_WP = b.q * b.q_BP;
    Vec3 L_P = glm::conjugate(q_WP) * L;
    const auto turn = [&](int i, double hh) {
      const double psi = hh * L_P[i] * b.inv_inertia_P[i];
      Vec3 axis{0.0};
      axis[i] = 1.0;
      const Quat r = glm::angleAxis(psi, axis);
      q_WP = q_WP * r;
      L_P = glm::conjugate(r) * L_P;
    };
    turn(0, 0.5 * h);
    turn(1, 0.5 * h);
    turn(2, h);
    turn(1, 0.5 * h);
    turn(0, 0.5 * h);
    b.q = glm::normalize(q_WP * glm::conjugate(b.q_BP));
    b.updateInertia();
    b.w_W = b.inv_inertia_W * L;
  }
  for (ContactPoint& cp : points_) {
    cp.ra = bodies_[cp.a].R * cp.ra_B;
    cp.rb = bodies_[cp.b].R * cp.rb_B;
  }
}

StepReport Dynamics::step(collision::CollisionWorld& world, double dt, const HeldInput* held) {
  StepReport report;
  if (!active_)
    return report;
  if (!(dt > 0.0) || !std::isfinite(dt))
    return report;
  if (asleep_) {
    if (!wakeRequested(world, held)) {
      stepAsleep(held);
      report.flags = kStepAsleep;
      return report;
    }
    asleep_ = false;
    rest_s_ = 0.0;
  }
  ++counters_.ticks;
  step_flags_ = 0;
  tick_dt_ = dt;
  integrateForces(dt, world.options().box_margin, held);
  gatherContacts(world.contacts(), report);
  prepareJoints();
  prepareGeneralJoints();
  solveThroughImpacts(dt, report);
  correctPositions(dt);

  // kinematic bodies end exactly on their targets
  for (BodyState& b : bodies_) {
    if (!b.infinite || !b.has_target)
      continue;
    b.x_W = b.target_x;
    b.q = b.target_q;
    b.updateInertia();
    if (b.motion == scene::Motion::kKinematic || b.driven)
      b.has_target = false;
  }
  held_feedback_ = heldFeedbackOfTick();
  storeWarmStart();

  // poses back to the collision world
  std::uint32_t active_points = 0;
  for (const ContactPoint& cp : points_)
    active_points += cp.active && cp.gap <= touchTolerance(cp);
  report.active_points = active_points;
  for (const ContactPoint& cp : points_)
    report.impulse_points += cp.total_n > 0.0;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const BodyState& b = bodies_[i];
    if (b.motion == scene::Motion::kStatic || !b.enabled)
      continue;
    world.setPose(i, Pose{b.x_W - b.R * b.com_B, b.q});
  }
  updateSleep(world, dt);
  report.flags = step_flags_;
  return report;
}

// the whole scene rests: nothing moves until something pushes; impulses still in the
// spreader's window are delivered
void Dynamics::stepAsleep(const HeldInput* held) {
  ++counters_.ticks_asleep;
  if (held_ < 0)
    return;
  // a kinematically held body that touches nothing moves on while the scene sleeps (taken
  // straight to its target: it pushes nothing), so that it does not jump on waking
  BodyState& h = bodies_[static_cast<std::size_t>(held_)];
  const Quat& tq = held != nullptr ? held->X_WB_target.rotation : Quat{1.0, 0.0, 0.0, 0.0};
  if (held != nullptr && held->mode == HeldMode::kKinematic &&
      geom::finite(held->X_WB_target.translation) && std::isfinite(glm::length(tq)) &&
      glm::length(tq) > 0.5) {
    h.q = glm::normalize(held->X_WB_target.rotation);
    h.x_W = held->X_WB_target.translation + glm::mat3_cast(h.q) * h.com_B;
    h.v_W = h.w_W = Vec3{0.0};
    h.updateInertia();
  }
  HeldFeedback fb;
  fb.com_W = bodies_[static_cast<std::size_t>(held_)].x_W;
  spreader_.pop(&fb.force_W_n, &fb.torque_W_nm);
  held_feedback_ = fb;
}

// restitution and friction thresholds, relative to the tick's gravity and the bodies' size
double Dynamics::restitutionThreshold(const ContactPoint& cp) const {
  return std::max(options_.restitution_threshold_ticks * accel_scale_ * tick_dt_,
                  options_.restitution_threshold_fraction * cp.size);
}

// a point whose gap closes counts as touching from here (never zero: a gap that closes exactly
// at its time of impact may be left at +1e-18 by rounding)
double Dynamics::touchTolerance(const ContactPoint& cp) const {
  return std::max(0.25 * options_.slop_fraction, 1e-9) * cp.size;
}

// a point taking part in the solves from now: its restitution if it strikes, its friction
void Dynamics::activate(ContactPoint& cp) const {
  const BodyState& A = bodies_[cp.a];
  const BodyState& B = bodies_[cp.b];
  const Vec3 vrel = B.velocityAt(cp.rb) - A.velocityAt(cp.ra);
  const double vn = glm::dot(vrel, cp.n);
  const double thr = restitutionThreshold(cp);
  cp.active = true;
  cp.bounce = vn < -thr ? cp.e : 0.0;
  const double vt = glm::length(vrel - cp.n * vn);
  cp.mu = vt < options_.static_friction_speed_fraction * thr ? cp.mu_s : cp.mu_d;
}

// the first solve at the start of the tick (the points touching now, the joints); then §6.1:
// advance to the earliest time of impact, apply the impulses there, go on; the rest of the tick
void Dynamics::solveThroughImpacts(double dt, StepReport& report) {
  const double v_gravity = options_.restitution_threshold_ticks * accel_scale_ * dt;
  velocity_tolerance_ = options_.velocity_tolerance_fraction *
                        std::max(v_gravity, options_.restitution_threshold_fraction * min_size_);
  for (ContactPoint& cp : points_) {
    const double size = std::isfinite(cp.size) ? cp.size : scene_->length_scale;
    cp.size = size;
  }
  warm_pending_ = true;
  bool any_active = !joints_.empty() || !general_.empty();
  for (ContactPoint& cp : points_) {
    cp.active = false;
    cp.speculative = false;
    if (cp.gap <= touchTolerance(cp)) {
      activate(cp);
      any_active = true;
    }
  }
  if (any_active) {
    solveVelocities(dt);
  } else {
    for (ContactPoint& cp : points_)
      cp.total_n = 0.0, cp.total_t = Vec3{0.0};
  }
  warm_pending_ = false;

  double t = 0.0;
  for (;;) {
    const double remaining = dt - t;
    double earliest = remaining;
    for (const ContactPoint& cp : points_) {
      if (cp.active)
        continue;
      const double vn =
          glm::dot(bodies_[cp.b].velocityAt(cp.rb) - bodies_[cp.a].velocityAt(cp.ra), cp.n);
      if (vn >= 0.0)
        continue;
      const double toi = std::max(cp.gap, 0.0) / -vn;
      earliest = std::min(earliest, toi);
    }
    if (earliest >= remaining)
      break;
    if (report.toi_substeps == options_.max_toi_substeps) {
      // the cap: whatever still approaches is held apart speculatively for the rest of the tick
      step_flags_ |= kStepToiCapped;
      ++counters_.toi_capped;
      for (ContactPoint& cp : points_) {
        if (!cp.active)
          cp.speculative = true;
      }
      solveVelocities(remaining);
      break;
    }
    advance(earliest);
    t += earliest;
    ++report.toi_substeps;
    for (ContactPoint& cp : points_) {
      if (!cp.active && cp.gap <= touchTolerance(cp))
        activate(cp);
    }
    solveVelocities(dt - t);
  }
  advance(dt - t);
}

// held body feedback: what the contacts and joints gave it this tick
HeldFeedback Dynamics::heldFeedbackOfTick() {
  HeldFeedback fb;
  if (held_ < 0 || static_cast<std::size_t>(held_) >= bodies_.size())
    return fb;
  const auto h = static_cast<std::uint32_t>(held_);
  const BodyState& H = bodies_[h];
  fb.com_W = H.x_W;
  // the held body and the bodies the caller drives with it (setDriven: an attached body)
  auto heldSet = [&](std::uint32_t i) { return i == h || bodies_[i].driven; };
  for (const ContactPoint& cp : points_) {
    if (!heldSet(cp.a) && !heldSet(cp.b))
      continue;
    const Vec3 J = cp.n * cp.total_n + cp.total_t;
    const Vec3 p = bodies_[cp.b].x_W + cp.rb;  // the contact point, end of tick
    const Vec3 Jh = heldSet(cp.b) ? J : -J;
    fb.impulse_W_ns += Jh;
    fb.angular_impulse_W_nms += glm::cross(p - H.x_W, Jh);
  }
  for (const JointState& js : joints_) {
    if (static_cast<std::int32_t>(js.a) == held_) {
      fb.impulse_W_ns -= js.total_J;
      fb.angular_impulse_W_nms -= js.total_L + glm::cross(js.ra, js.total_J);
    } else if (js.b == held_) {
      fb.impulse_W_ns += js.total_J;
      fb.angular_impulse_W_nms += js.total_L + glm::cross(js.rb, js.total_J);
    }
  }
  generalFeedback(fb);
  spreader_.add(fb.impulse_W_ns, fb.angular_impulse_W_nms);
  spreader_.pop(&fb.force_W_n, &fb.torque_W_nm);
  return fb;
}

// sleep: once every moving body has been still for sleep_time_s
void Dynamics::updateSleep(const collision::CollisionWorld& world, double dt) {
  if (!(options_.sleep_time_s > 0.0))
    return;
  bool still = true;
  for (const BodyState& b : bodies_) {
    if (b.motion == scene::Motion::kStatic || b.driven || !b.enabled ||
        (b.motion == scene::Motion::kKinematic && !b.coast))
      continue;
    const double speed = glm::length(b.v_W) + glm::length(b.w_W) * b.size;
    still = still && speed <= options_.sleep_speed_fraction * b.size;
  }
  // a held body moving in free space does not keep the scene awake; one touching a dynamic
  // body does
  still = still && !(held_kinematic_ && heldTouchesDynamic(world));
  rest_s_ = still ? rest_s_ + dt : 0.0;
  if (rest_s_ >= options_.sleep_time_s) {
    asleep_ = true;
    for (BodyState& b : bodies_) {
      if (b.motion == scene::Motion::kDynamic)
        b.v_W = b.w_W = Vec3{0.0};
    }
  }
}

// the held body (or a body driven with it) has a contact this tick, within the world's box
// margin, with a dynamic body the dynamics move
bool Dynamics::heldTouchesDynamic(const collision::CollisionWorld& world) const {
  const double margin = world.options().box_margin;
  const auto heldSet = [&](std::uint32_t i) {
    return static_cast<std::int32_t>(i) == held_ || bodies_[i].driven;
  };
  for (const collision::Contact& c : world.contacts()) {
    if (!c.answered || c.body_a >= bodies_.size() || c.body_b >= bodies_.size())
      continue;
    const bool ha = heldSet(c.body_a), hb = heldSet(c.body_b);
    if (ha == hb)
      continue;
    const BodyState& other = bodies_[ha ? c.body_b : c.body_a];
    if (other.motion == scene::Motion::kDynamic && !other.driven && !other.coast &&
        c.distance <= margin)
      return true;
  }
  return false;
}

// anything that could move a resting scene: the held body's input, a kinematic target, an
// external wrench
bool Dynamics::wakeRequested(const collision::CollisionWorld& world, const HeldInput* held) const {
  if (held != nullptr && held_ >= 0) {
    if (held->mode == HeldMode::kWrench &&
        (glm::length(held->force_W_n) > 0.0 || glm::length(held->torque_W_nm) > 0.0))
      return true;
    if (held->mode == HeldMode::kKinematic) {
      const BodyState& h = bodies_[static_cast<std::size_t>(held_)];
      const Vec3 x =
          held->X_WB_target.translation + glm::mat3_cast(held->X_WB_target.rotation) * h.com_B;
      if ((x != h.x_W || std::abs(glm::dot(held->X_WB_target.rotation, h.q)) < 1.0) &&
          heldTouchesDynamic(world))
        return true;
    }
  }
  for (const BodyState& b : bodies_) {
    if (!b.enabled)
      continue;
    if (b.has_target && (b.motion == scene::Motion::kKinematic || b.driven))
      return true;
    if (b.motion == scene::Motion::kDynamic &&
        (glm::length(b.force_W) > 0.0 || glm::length(b.torque_W) > 0.0))
      return true;
  }
  return false;
}

void Dynamics::storeWarmStart() {
  warm_next_.clear();
  for (const ContactPoint& cp : points_) {
    if (!cp.active || cp.total_n <= 0.0)
      continue;
    WarmPoint& w = warm_next_.emplace_back();
    w.a = cp.a;
    w.b = cp.b;
    w.prim_a = cp.prim_a;
    w.prim_b = cp.prim_b;
    w.ra_B = cp.ra_B;
    w.ln = cp.total_n;
    w.lt = cp.total_t;
  }
  std::swap(warm_, warm_next_);
}

}  // namespace hapticd::dynamics
