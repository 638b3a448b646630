// Impulse-based rigid-body dynamics (Mirtich & Canny 1995; §6.1 of Gregory et al. 2000): the
// stage's creation (bodies' mass properties, joints, capacities), its edits and accessors, its
// state for the simulation's hash. The tick is dynamics_step.cpp, the solvers dynamics_solver.cpp.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/dynamics/dynamics_internal.h"
#include "core/dynamics/scene_world.h"
#include "core/geometry/rotation.h"

namespace hapticd::dynamics {

using detail::kInf;
using detail::pairKey;

namespace {

// eigen-decomposition of a symmetric 3x3 matrix by Jacobi rotations: A = P diag(d) P^T, P a
// proper rotation (columns: the principal axes)
void principalAxes(const Mat3& A_in, Mat3* P_out, Vec3* d_out) {
  double a[3][3];
  double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      a[i][j] = 0.5 * (A_in[j][i] + A_in[i][j]);
  }
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-30 * diag)
      break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0.0)
          continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), sn = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - sn * akq;
          a[k][q] = sn * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - sn * aqk;
          a[q][k] = sn * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - sn * vkq;
          v[k][q] = sn * vkp + c * vkq;
        }
      }
    }
  }
  Mat3 P;
  for (int c = 0; c < 3; ++c)
    P[c] = Vec3{v[0][c], v[1][c], v[2][c]};
  if (glm::determinant(P) < 0.0)
    P[2] = -P[2];
  *P_out = P;
  *d_out = Vec3{a[0][0], a[1][1], a[2][2]};
}

}  // namespace

void Dynamics::writeState(StateWriter& w) const {
  w.flag(active_);
  w.integer(held_);
  w.flag(held_kinematic_);
  w.flag(asleep_);
  w.flag(warm_pending_);
  for (const double v : {min_size_, velocity_tolerance_, ke_episode_start_, accel_scale_, tick_dt_})
    w.f64(v);
  w.integer(bodies_.size());
  for (const BodyState& b : bodies_) {
    w.integer(b.motion);
    for (const bool f :
         {b.infinite, b.coast, b.driven, b.enabled, b.isotropic, b.has_target, b.asleep})
      w.flag(f);
    w.f64(b.rest_s);
    w.integer(b.island);
    w.f64(b.inv_mass);
    w.f64(b.size);
    for (const Mat3& m : {b.inertia_B, b.inv_inertia_B, b.inv_inertia_W, b.R})
      w.glm(m);
    for (const Quat& q : {b.q_BP, b.q, b.target_q})
      w.glm(q);
    for (const Vec3& v : {b.inertia_P, b.inv_inertia_P, b.com_B, b.x_W, b.v_W, b.w_W, b.gravity_W,
                          b.force_W, b.torque_W, b.pv, b.pw, b.target_x, b.v_coast, b.w_coast})
      w.glm(v);
  }
  w.integer(joints_.size());
  for (const JointState& j : joints_) {
    for (const bool f : {j.off, j.has_min, j.has_max})
      w.flag(f);
    w.integer(j.a);
    w.integer(j.b);
    for (const Mat3& m : {j.point_mass, j.ang_mass})
      w.glm(m);
    for (const Vec3& v : {j.ra, j.rb, j.axis, j.p1, j.p2, j.l_point, j.l_ang, j.err_point,
                          j.err_ang, j.warm_J, j.warm_L, j.total_J, j.total_L})
      w.glm(v);
    for (const double v : {j.m1, j.m2, j.m_axis, j.c_min, j.c_max, j.l1, j.l2, j.l_lo, j.l_hi,
                           j.size, j.tot_lo, j.tot_hi, j.warm_lo, j.warm_hi})
      w.f64(v);
  }
  w.integer(general_.size());
  for (const GeneralJoint& g : general_) {
    w.flag(g.off);
    w.integer(g.euler_shift);
    w.integer(g.rows.size());
    for (const JointRow& r : g.rows) {
      for (const bool f : {r.active, r.was_active, r.pos_on})
        w.flag(f);
      for (const Vec3& v : {r.u, r.ca, r.cb, r.ia, r.ib})
        w.glm(v);
      for (const double v : {r.mass, r.soft_mass, r.bias, r.gamma, r.lo, r.hi, r.acc, r.warm,
                             r.position, r.lp, r.pos_err})
        w.f64(v);
    }
  }
  w.integer(warm_.size());
  for (const WarmPoint& p : warm_) {
    for (const std::uint32_t i : {p.a, p.b, p.prim_a, p.prim_b})
      w.integer(i);
    w.glm(p.sa_B);
    w.glm(p.sb_B);
    w.glm(p.na_B);
    w.glm(p.nb_B);
    w.f64(p.ln);
    w.glm(p.lt);
  }
  w.array(no_collide_);
  spreader_.writeState(w);
  for (const Vec3& v : {held_feedback_.impulse_W_ns, held_feedback_.angular_impulse_W_nms,
                        held_feedback_.force_W_n, held_feedback_.torque_W_nm, held_feedback_.com_W})
    w.glm(v);
  for (const std::uint64_t c : {counters_.ticks, counters_.toi_capped, counters_.points_dropped,
                                counters_.speed_clamped, counters_.ticks_asleep})
    w.u64(c);
}

Dynamics::Dynamics() = default;
Dynamics::~Dynamics() = default;
Dynamics::Dynamics(const Dynamics&) = default;
Dynamics::Dynamics(Dynamics&&) noexcept = default;
Dynamics& Dynamics::operator=(const Dynamics&) = default;
Dynamics& Dynamics::operator=(Dynamics&&) noexcept = default;
std::uint32_t Dynamics::bodyCount() const {
  return static_cast<std::uint32_t>(bodies_.size());
}

namespace {

Result<bool> checkOptions(const DynamicsOptions& options) {
  if (options.velocity_iterations == 0 || options.velocity_iterations > 1000 ||
      options.position_iterations > 1000 || options.max_toi_substeps > 1000 ||
      options.velocity_iterations_max > 1000 || options.position_iterations_max > 1000) {
    return Error{"dynamics: iteration counts must be 1..1000 (velocity) and 0..1000"};
  }
  if (!(options.settle_tolerance_fraction >= 0.0) ||
      !std::isfinite(options.settle_tolerance_fraction))
    return Error{"dynamics: settle_tolerance_fraction must be >= 0"};
  if (!(options.slop_fraction >= 0.0 && options.slop_fraction < 0.5) ||
      !(options.slop_settle_time_s >= 0.0) || !std::isfinite(options.slop_settle_time_s) ||
      !(options.position_correction >= 0.0 && options.position_correction <= 1.0) ||
      !(options.restitution_threshold_ticks >= 0.0) ||
      !(options.restitution_threshold_fraction >= 0.0) ||
      !(options.static_friction_speed_fraction >= 0.0) ||
      !(options.max_travel_fraction > 0.0 && options.max_travel_fraction <= 1.0) ||
      !(options.velocity_tolerance_fraction >= 0.0 && options.velocity_tolerance_fraction < 1.0) ||
      !(options.sleep_time_s >= 0.0) || !std::isfinite(options.sleep_time_s) ||
      !(options.sleep_speed_fraction >= 0.0) || !std::isfinite(options.sleep_speed_fraction) ||
      !(options.impulse_window_s >= 0.0) || !(options.held_max_force_n >= 0.0) ||
      !std::isfinite(options.held_max_force_n) || !(options.tick_s > 0.0) ||
      !std::isfinite(options.impulse_window_s) ||
      !std::isfinite(options.restitution_threshold_ticks) ||
      !std::isfinite(options.restitution_threshold_fraction)) {
    return Error{"dynamics: an option is out of range (see DynamicsOptions)"};
  }
  return true;
}

}  // namespace

Result<std::unique_ptr<Dynamics>> Dynamics::create(const scene::SceneModel& scene,
                                                   const collision::CollisionWorld& world,
                                                   const DynamicsOptions& options) {
  if (auto ok = checkOptions(options); !ok.ok())
    return ok.error();
  std::unique_ptr<Dynamics> d(new Dynamics());
  d->scene_ = &scene;
  d->options_ = options;
  d->held_ = scene.probe_body;
  for (const scene::Body& b : scene.bodies)
    d->active_ = d->active_ || b.motion == scene::Motion::kDynamic;
  if (!d->active_)
    return d;

  const Vec3 g = scene.gravity_W.value_or(Vec3{0.0});
  if (!geom::finite(g))
    return Error{"dynamics: gravity is not finite"};
  d->bodies_.resize(scene.bodies.size());
  std::size_t moving_prims = 0;
  for (std::uint32_t i = 0; i < scene.bodies.size(); ++i) {
    if (auto ok = d->initBody(i, g, &moving_prims); !ok.ok())
      return ok.error();
  }
  // each primitive's material, in one array (gatherContacts; the scene's bodies are far apart)
  d->prim_first_.reserve(scene.bodies.size() + 1);
  for (const scene::Body& b : scene.bodies) {
    d->prim_first_.push_back(static_cast<std::uint32_t>(d->prim_material_.size()));
    for (const scene::Primitive& p : b.primitives)
      d->prim_material_.push_back(&scene::materialOf(scene, p.material));
  }
  d->prim_first_.push_back(static_cast<std::uint32_t>(d->prim_material_.size()));
  d->default_material_ = &scene::materialOf(scene, -1);
  if (scene.probe_body < 0 && options.extra_probe_body >= 0) {
    if (static_cast<std::size_t>(options.extra_probe_body) != scene.bodies.size()) {
      return Error{"dynamics: extra_probe_body must be the world id after the scene's bodies"};
    }
    d->held_ = options.extra_probe_body;
    d->bodies_.resize(static_cast<std::size_t>(options.extra_probe_body) + 1);
    for (std::size_t i = scene.bodies.size(); i < d->bodies_.size(); ++i) {
      BodyState& b = d->bodies_[i];
      b.motion = static_cast<std::int32_t>(i) == d->held_ ? scene::Motion::kKinematic
                                                          : scene::Motion::kStatic;
      b.infinite = true;
      const Pose X = world.pose(static_cast<std::uint32_t>(i));
      b.q = glm::normalize(X.rotation);
      b.x_W = X.translation;
      b.size = scene.length_scale;
      b.updateInertia();
    }
  }
  if (auto ok = d->initJoints(); !ok.ok())
    return ok.error();
  d->min_size_ = kInf;
  double max_size = 0.0;
  for (const BodyState& b : d->bodies_) {
    if (b.motion == scene::Motion::kDynamic) {
      d->min_size_ = std::min(d->min_size_, b.size);
      max_size = std::max(max_size, b.size);
    }
  }
  d->one_size_ = !(max_size > d->min_size_);
  const std::size_t cap =
      options.max_contact_points != 0 ? options.max_contact_points : 16 * moving_prims + 64;
  d->max_points_ = cap;
  d->gap_points_.resize(world.reservedPairs());
  d->points_.reserve(cap);
  d->blocks_.assign(cap, NormalBlock{});
  d->level_order_.reserve(cap);
  d->level_points_.reserve(cap);
  d->level_pinned_.assign(d->bodies_.size(), 0);
  d->level_reach_.assign(d->bodies_.size(), {});
  d->level_load_.assign(d->bodies_.size(), {});
  d->parent_.assign(d->bodies_.size(), 0);
  d->island_rest_.assign(d->bodies_.size(), 0.0);
  d->slop_size_.assign(d->bodies_.size(), kInf);
  d->dv_.assign(d->bodies_.size(), Vec3{0.0});
  d->dw_.assign(d->bodies_.size(), Vec3{0.0});
  d->warm_.reserve(cap);
  d->warm_next_.reserve(cap);
  d->spreader_ = ImpulseSpreader(options.impulse_window_s, options.tick_s);
  return d;
}

// scene body i: its motion, pose, size; a dynamic one its mass properties too
Result<bool> Dynamics::initBody(std::uint32_t i, const Vec3& g, std::size_t* moving_prims) {
  const scene::SceneModel& scene = *scene_;
  const scene::Body& sb = scene.bodies[i];
  BodyState& b = bodies_[i];
  b.motion = sb.motion;
  b.infinite = sb.motion != scene::Motion::kDynamic;
  b.com_B = sb.com_B;
  // extras.haptic.active false: in the scene but out of it until setEnabled (never the held
  // body or a static one)
  b.enabled = sb.active || sb.motion == scene::Motion::kStatic ||
              static_cast<std::int32_t>(i) == scene.probe_body;
  if (sb.motion == scene::Motion::kDynamic && sb.mass_declared && sb.mass == 0.0) {
    // KHR_physics_rigid_bodies: a mass of 0 is an infinite mass. Nothing pushes the body;
    // it coasts at its initial velocities (no gravity: it cannot be accelerated either)
    b.motion = scene::Motion::kKinematic;
    b.infinite = true;
    b.coast = true;
    b.v_W = b.v_coast = sb.linear_velocity_W;
    b.w_W = b.w_coast = sb.angular_velocity_W;
  } else if (sb.motion == scene::Motion::kKinematic &&
             (sb.linear_velocity_W != Vec3{0.0} || sb.angular_velocity_W != Vec3{0.0})) {
    // KHR `motion.linearVelocity` / `angularVelocity` of a kinematic body: it moves at them
    // (scene frame, about its centre of mass) whenever no client target moves it
    b.coast = true;
    b.v_W = b.v_coast = sb.linear_velocity_W;
    b.w_W = b.w_coast = sb.angular_velocity_W;
  } else if (sb.motion == scene::Motion::kDynamic) {
    *moving_prims += sb.primitives.size();
    if (auto ok = initMass(sb, g, b); !ok.ok())
      return ok.error();
  }
  if (sb.motion != scene::Motion::kStatic)
    *moving_prims += sb.primitives.size();
  b.q = glm::normalize(sb.X_WB.rotation);
  b.R = glm::mat3_cast(b.q);
  b.x_W = sb.X_WB.translation + b.R * b.com_B;
  const double size = bodySize(sb, b.com_B);
  b.size = size > 0.0 ? size : scene.length_scale;
  b.updateInertia();
  return true;
}

// a dynamic body's mass, inertia about its principal axes, gravity and initial velocities
Result<bool> Dynamics::initMass(const scene::Body& sb, const Vec3& g, BodyState& b) {
  if (!(sb.mass > 0.0) || !std::isfinite(sb.mass)) {
    return Error{"dynamics: dynamic body '" + sb.name + "' needs a positive, finite mass"};
  }
  Mat3 inertia = sb.inertia_B;
  Vec3 com = sb.com_B;
  const double tr = inertia[0][0] + inertia[1][1] + inertia[2][2];
  if (!sb.inertia_declared && !(tr > 0.0)) {
    // not given: computed from the primitives, scaled to the body's mass
    const MassProperties mp = computeMassProperties(sb.primitives, 1.0);
    if (!(mp.mass > 0.0)) {
      return Error{"dynamics: body '" + sb.name + "' has no inertia and no volume"};
    }
    inertia = mp.inertia_B * (sb.mass / mp.mass);
    if (!sb.mass_declared && glm::length(com) == 0.0)
      com = mp.com_B;
  }
  for (int c = 0; c < 3; ++c) {
    if (!geom::finite(inertia[c]) || !geom::finite(com)) {
      return Error{"dynamics: body '" + sb.name + "' has a non-finite inertia or centre of mass"};
    }
  }
  // principal axes; a principal moment of 0 is an infinite inertia about that axis (KHR: a
  // declared inertiaDiagonal component of 0): the body does not turn about it
  Mat3 P;
  principalAxes(inertia, &P, &b.inertia_P);
  const double i_max = std::max({b.inertia_P.x, b.inertia_P.y, b.inertia_P.z});
  Vec3 inv_P{0.0};
  for (int k = 0; k < 3; ++k) {
    if (b.inertia_P[k] < -1e-12 * i_max) {
      return Error{"dynamics: body '" + sb.name + "' has an inertia tensor that is not positive"};
    }
    if (b.inertia_P[k] <= 1e-12 * i_max)
      b.inertia_P[k] = 0.0;
    inv_P[k] = b.inertia_P[k] > 0.0 ? 1.0 / b.inertia_P[k] : 0.0;
  }
  b.inv_inertia_P = inv_P;
  b.com_B = com;
  b.inv_mass = 1.0 / sb.mass;
  b.inertia_B = inertia;
  b.inv_inertia_B = P * Mat3{inv_P.x, 0, 0, 0, inv_P.y, 0, 0, 0, inv_P.z} * glm::transpose(P);
  b.q_BP = glm::normalize(glm::quat_cast(P));
  const double i_min = std::min({b.inertia_P.x, b.inertia_P.y, b.inertia_P.z});
  b.isotropic = i_max - i_min <= 1e-12 * i_max;
  b.gravity_W = g * sb.gravity_factor;
  accel_scale_ = std::max(accel_scale_, glm::length(b.gravity_W));
  b.v_W = sb.linear_velocity_W;
  b.w_W = i_max > 0.0 ? sb.angular_velocity_W : Vec3{0.0};
  if (!b.isotropic) {
    // no spin about an axis of infinite inertia
    const Mat3 R0 = glm::mat3_cast(glm::normalize(sb.X_WB.rotation));
    const Vec3 w_P = glm::transpose(R0 * P) * b.w_W;
    b.w_W =
        R0 * P * Vec3{inv_P.x > 0 ? w_P.x : 0, inv_P.y > 0 ? w_P.y : 0, inv_P.z > 0 ? w_P.z : 0};
  }
  return true;
}

// the scene's joints, and the body pairs they keep from colliding: plain fixed joints and hinges
// (their limits hard) on the rows of dynamics_solver.cpp, every other joint (sliders, ball joints,
// cones, soft limits, drives) on the general rows of dynamics_joints.cpp
Result<bool> Dynamics::initJoints() {
  const scene::SceneModel& scene = *scene_;
  const auto n = static_cast<std::int32_t>(scene.bodies.size());
  for (const auto* list : {&scene.joints, &scene.unsimulated_joints}) {
    for (const scene::Joint& j : *list) {
      if (j.body_a < 0 || j.body_a >= n || j.body_b >= n || j.body_a == j.body_b ||
          j.hinge_axis > 2) {
        return Error{"dynamics: a joint names a body out of range (or itself, or an axis > 2)"};
      }
      const bool soft = std::any_of(j.limits.begin(), j.limits.end(),
                                    [](const scene::JointLimit& l) { return l.stiffness; });
      const bool plain =
          (j.kind == scene::JointKind::kFixed || j.kind == scene::JointKind::kHinge) &&
          j.drives.empty() && !soft;
      if (!plain) {
        if (auto ok = initGeneralJoint(j); !ok.ok())
          return ok.error();
        continue;
      }
      JointState js;
      js.joint = &j;
      js.a = static_cast<std::uint32_t>(j.body_a);
      js.b = j.body_b;
      js.size = std::max(bodies_[js.a].size,
                         js.b >= 0 ? bodies_[static_cast<std::size_t>(js.b)].size : 0.0);
      joints_.push_back(js);
      if (!j.enable_collision && j.body_b >= 0) {
        no_collide_.push_back(pairKey(js.a, static_cast<std::uint32_t>(j.body_b)));
      }
    }
  }
  std::sort(no_collide_.begin(), no_collide_.end());
  return true;
}

void Dynamics::setKinematicPose(std::uint32_t body, const Pose& X_WB) {
  if (!active_ || body >= bodies_.size())
    return;
  BodyState& b = bodies_[body];
  const bool held = static_cast<std::int32_t>(body) == held_;
  if ((b.motion != scene::Motion::kKinematic && !held && !b.driven) || !b.enabled)
    return;
  const Quat& q = X_WB.rotation;
  const double qn = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!geom::finite(X_WB.translation) || !std::isfinite(qn) || !(qn > 0.5))
    return;  // not a pose: ignored, nothing changes
  b.has_target = true;
  target_given_ = true;
  b.target_q = glm::normalize(X_WB.rotation);
  b.target_x = X_WB.translation + glm::mat3_cast(b.target_q) * b.com_B;
}

void Dynamics::setEnabled(std::uint32_t body, bool enabled, const Pose& X_WB) {
  if (!active_ || body >= bodies_.size() || static_cast<std::int32_t>(body) == held_)
    return;
  BodyState& b = bodies_[body];
  if (b.motion == scene::Motion::kStatic)
    return;
  if (enabled) {
    const Quat& q = X_WB.rotation;
    const double qn = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!geom::finite(X_WB.translation) || !std::isfinite(qn) || !(qn > 0.5))
      return;  // not a pose: ignored, nothing changes
    b.q = glm::normalize(q);
    b.R = glm::mat3_cast(b.q);
    b.x_W = X_WB.translation + b.R * b.com_B;
  }
  b.enabled = enabled;
  b.v_W = b.w_W = Vec3{0.0};
  b.pv = b.pw = Vec3{0.0};
  b.has_target = false;
  b.updateInertia();
  // last tick's impulses on it belong to a contact that is gone (no allocation: in place)
  warm_.erase(std::remove_if(warm_.begin(), warm_.end(),
                             [body](const WarmPoint& w) { return w.a == body || w.b == body; }),
              warm_.end());
  // something changed: what rested on it (or under where it appears) must move
  asleep_ = false;
  for (BodyState& o : bodies_)
    o.asleep = false, o.rest_s = 0.0;
}

bool Dynamics::enabled(std::uint32_t body) const {
  return !active_ || body >= bodies_.size() || bodies_[body].enabled;
}

bool Dynamics::asleep(std::uint32_t body) const {
  return active_ && body < bodies_.size() && bodies_[body].asleep;
}

void Dynamics::setDriven(std::uint32_t body, bool driven) {
  if (!active_ || body >= bodies_.size())
    return;
  BodyState& b = bodies_[body];
  if (b.motion != scene::Motion::kDynamic || static_cast<std::int32_t>(body) == held_)
    return;
  b.driven = driven;
  b.has_target = false;
  if (driven) {
    asleep_ = false;
    if (b.asleep)
      wakeIsland(b.island);
    b.rest_s = 0.0;
  }
}

void Dynamics::setExternalWrench(std::uint32_t body,
                                 const Vec3& force_W_n,
                                 const Vec3& torque_W_nm) {
  if (!active_ || body >= bodies_.size() || bodies_[body].motion != scene::Motion::kDynamic)
    return;
  if (!geom::finite(force_W_n) || !geom::finite(torque_W_nm))
    return;  // not a wrench: ignored, nothing changes
  BodyState& b = bodies_[body];
  const bool changed = b.force_W != force_W_n || b.torque_W != torque_W_nm;
  b.force_W = force_W_n;
  b.torque_W = torque_W_nm;
  if (changed && b.asleep) {
    wakeIsland(b.island);  // its island wakes, and the scene
    asleep_ = false;
  }
}

Pose Dynamics::pose(std::uint32_t body) const {
  if (!active_)
    return body < scene_->bodies.size() ? scene_->bodies[body].X_WB : Pose{};
  if (body >= bodies_.size())
    return Pose{};
  const BodyState& b = bodies_[body];
  return Pose{b.x_W - b.R * b.com_B, b.q};
}
Vec3 Dynamics::linearVelocity(std::uint32_t body) const {
  return active_ && body < bodies_.size() ? bodies_[body].v_W : Vec3{0.0};
}
Vec3 Dynamics::angularVelocity(std::uint32_t body) const {
  return active_ && body < bodies_.size() ? bodies_[body].w_W : Vec3{0.0};
}
Vec3 Dynamics::centerOfMass(std::uint32_t body) const {
  if (!active_ || body >= bodies_.size())
    return Vec3{0.0};
  return bodies_[body].x_W;
}

MassProperties Dynamics::massProperties(std::uint32_t body) const {
  MassProperties mp;
  if (!active_ || body >= bodies_.size())
    return mp;
  const BodyState& b = bodies_[body];
  if (b.motion != scene::Motion::kDynamic || !(b.inv_mass > 0.0))
    return mp;
  mp.mass = 1.0 / b.inv_mass;
  mp.com_B = b.com_B;
  mp.inertia_B = b.inertia_B;
  return mp;
}

Vec3 Dynamics::gravity(std::uint32_t body) const {
  if (!active_ || body >= bodies_.size() || bodies_[body].motion != scene::Motion::kDynamic)
    return Vec3{0.0};
  return bodies_[body].gravity_W;
}

double Dynamics::kineticEnergy() const {
  double e = 0.0;
  for (const BodyState& b : bodies_) {
    if (b.motion != scene::Motion::kDynamic || !b.enabled)
      continue;
    const Vec3 w_B = glm::transpose(b.R) * b.w_W;
    e += 0.5 * glm::dot(b.v_W, b.v_W) / b.inv_mass + 0.5 * glm::dot(w_B, b.inertia_B * w_B);
  }
  return e;
}

double Dynamics::potentialEnergy() const {
  double e = 0.0;
  for (const BodyState& b : bodies_) {
    if (b.motion != scene::Motion::kDynamic || !b.enabled)
      continue;
    e -= glm::dot(b.gravity_W, b.x_W) / b.inv_mass;
  }
  return e;
}

}  // namespace hapticd::dynamics
