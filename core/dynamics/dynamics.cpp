// Impulse-based rigid-body dynamics (Mirtich & Canny 1995; §6.1 of Gregory et al. 2000); the
// solver is sequential impulses with accumulated clamping and split-impulse drift correction
// (Catto, "Iterative dynamics with temporal coherence", GDC 2005).
#include "core/dynamics/dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "core/geometry/rotation.h"

namespace hapticd::dynamics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// a primitive without a material: frictionless, inelastic (built before main, never on the
// servo thread)
const scene::Material kNoMaterial{};

// velocity iterations always run at least this many times per solve
constexpr std::uint32_t kMinIterations = 2;

Mat3 skew(const Vec3& v) {
  // column-major: columns are the images of e_x, e_y, e_z under v x .
  return Mat3{0.0, v.z, -v.y, -v.z, 0.0, v.x, v.y, -v.x, 0.0};
}

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

void tangents(const Vec3& n, Vec3* t1, Vec3* t2) {
  const Vec3 a = std::abs(n.x) < 0.57 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  *t1 = glm::normalize(glm::cross(n, a));
  *t2 = glm::cross(n, *t1);
}

double combine(double a, double b, scene::Combine ca, scene::Combine cb) {
  using scene::Combine;
  // KHR_physics_rigid_bodies: average, else minimum, else maximum, else multiply
  if (ca == Combine::kAverage || cb == Combine::kAverage)
    return 0.5 * (a + b);
  if (ca == Combine::kMinimum || cb == Combine::kMinimum)
    return std::min(a, b);
  if (ca == Combine::kMaximum || cb == Combine::kMaximum)
    return std::max(a, b);
  return a * b;
}

std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  if (a > b)
    std::swap(a, b);
  return static_cast<std::uint64_t>(a) << 32 | b;
}

}  // namespace

struct Dynamics::BodyState {
  scene::Motion motion = scene::Motion::kStatic;
  bool infinite = true;  // this tick: infinite mass (static, kinematic, held kinematic)
  double inv_mass = 0.0;
  Mat3 inertia_B{0.0}, inv_inertia_B{0.0};
  Quat q_BP{1.0, 0.0, 0.0, 0.0};  // principal axes in the body frame
  Vec3 inertia_P{1.0};            // principal moments (0: infinite about that axis)
  Vec3 inv_inertia_P{1.0};        // their inverses (0 for an infinite one)
  bool coast = false;             // infinite mass (declared 0): keeps its velocities
  bool driven = false;            // a dynamic body the caller moves (setDriven): infinite mass
  bool enabled = true;            // false: out of the scene (setEnabled): frozen, no contacts
  bool isotropic = false;         // all three equal (cubes, regular polyhedra)
  Mat3 inv_inertia_W{0.0};
  Vec3 com_B{0.0};
  Vec3 x_W{0.0};  // centre of mass
  Quat q{1.0, 0.0, 0.0, 0.0};
  Mat3 R{1.0};
  Vec3 v_W{0.0}, w_W{0.0};
  Vec3 gravity_W{0.0};
  Vec3 force_W{0.0}, torque_W{0.0};
  Vec3 pv{0.0}, pw{0.0};  // split-impulse pseudo-velocities
  double size = 0.0;      // radius about the centre of mass
  bool has_target = false;
  Vec3 target_x{0.0};
  Quat target_q{1.0, 0.0, 0.0, 0.0};

  void updateInertia() {
    R = glm::mat3_cast(q);
    inv_inertia_W = infinite ? Mat3{0.0} : R * inv_inertia_B * glm::transpose(R);
  }
  double invMass() const { return infinite ? 0.0 : inv_mass; }
  Vec3 velocityAt(const Vec3& r) const { return v_W + glm::cross(w_W, r); }
  Vec3 pseudoAt(const Vec3& r) const { return pv + glm::cross(pw, r); }
  void applyImpulse(const Vec3& J, const Vec3& r) {
    if (infinite)
      return;
    v_W += inv_mass * J;
    w_W += inv_inertia_W * glm::cross(r, J);
  }
  void applyPseudo(const Vec3& J, const Vec3& r) {
    if (infinite)
      return;
    pv += inv_mass * J;
    pw += inv_inertia_W * glm::cross(r, J);
  }
};

// one constraint row of a contact point along a unit direction u: the angular parts and the
// effective mass
struct Row {
  Vec3 ca{0.0}, cb{0.0};  // ra x u, rb x u
  Vec3 ia{0.0}, ib{0.0};  // inverse world inertia times those
  double mass = 0.0;
};

struct Dynamics::ContactPoint {
  std::uint32_t a = 0, b = 0;
  std::uint32_t prim_a = 0, prim_b = 0;
  Vec3 ra_B{0.0}, rb_B{0.0};  // from each centre of mass, body frames
  Vec3 ra{0.0}, rb{0.0};      // world, current
  Vec3 n{0.0}, t1{0.0}, t2{0.0};
  double gap = 0.0;     // > 0 apart, < 0 penetrating (tracked through the tick)
  double size = 0.0;    // the smaller body's size
  double mass_n = 0.0;  // normal effective mass (the split impulses use it)
  double ima = 0.0, imb = 0.0;
  Row rn, rt1, rt2;
  double e = 0.0, mu_s = 0.0, mu_d = 0.0, mu = 0.0;
  double bounce = 0.0;  // restitution of this impact (0 below the threshold, or done)
  double min_vn = 0.0;  // speculative: closing allowed up to this (<= 0), else 0
  double ln = 0.0, lt1 = 0.0, lt2 = 0.0;  // this episode
  double total_n = 0.0;                   // whole tick
  Vec3 total_t{0.0};                      // whole tick, world
  double lp = 0.0;                        // split impulse
  double ln_max = 0.0;  // largest normal impulse per solve (held_max_force_n), 0: none
  bool active = false;
  bool speculative = false;
};

struct Dynamics::JointState {
  const scene::Joint* joint = nullptr;
  bool off = false;  // this tick: a body of the joint is disabled (setEnabled): the joint is inert
  std::uint32_t a = 0;
  std::int32_t b = -1;  // -1: the scene frame
  Vec3 ra{0.0}, rb{0.0};
  Mat3 point_mass{0.0};  // inverse of K
  Mat3 ang_mass{0.0};    // fixed: inverse of angular K
  Vec3 axis{0.0}, p1{0.0}, p2{0.0};
  double m1 = 0.0, m2 = 0.0, m_axis = 0.0;
  bool has_min = false, has_max = false;
  double c_min = 0.0, c_max = 0.0;  // distance to the limits (rad), > 0 inside
  Vec3 l_point{0.0}, l_ang{0.0};    // this episode
  double l1 = 0.0, l2 = 0.0, l_lo = 0.0, l_hi = 0.0;
  Vec3 err_point{0.0}, err_ang{0.0};  // end of tick: b's anchor from a's; rotation error
  double size = 0.0;                  // the larger body's size: turns angular errors into speeds
  double tot_lo = 0.0, tot_hi = 0.0;  // whole tick: limit impulses (part of total_L)
  Vec3 warm_J{0.0}, warm_L{0.0};      // last tick's, for the warm start
  double warm_lo = 0.0, warm_hi = 0.0;
  Vec3 total_J{0.0},
      total_L{0.0};  // whole tick: impulse on b at its anchor (-J on a), pure angular impulse on b
};

struct Dynamics::WarmPoint {
  std::uint32_t a = 0, b = 0, prim_a = 0, prim_b = 0;
  Vec3 ra_B{0.0};
  double ln = 0.0;
  Vec3 lt{0.0};
};

void Dynamics::writeState(StateWriter& w) const {
  w.flag(active_);
  w.integer(held_);
  w.flag(held_kinematic_);
  w.flag(asleep_);
  w.flag(warm_pending_);
  for (const double v : {min_size_, velocity_tolerance_, ke_episode_start_, rest_s_, accel_scale_,
                         tick_dt_})
    w.f64(v);
  w.integer(bodies_.size());
  for (const BodyState& b : bodies_) {
    w.integer(b.motion);
    for (const bool f : {b.infinite, b.coast, b.driven, b.enabled, b.isotropic, b.has_target})
      w.flag(f);
    w.f64(b.inv_mass);
    w.f64(b.size);
    for (const Mat3& m : {b.inertia_B, b.inv_inertia_B, b.inv_inertia_W, b.R})
      w.glm(m);
    for (const Quat& q : {b.q_BP, b.q, b.target_q})
      w.glm(q);
    for (const Vec3& v : {b.inertia_P, b.inv_inertia_P, b.com_B, b.x_W, b.v_W, b.w_W, b.gravity_W,
                          b.force_W, b.torque_W, b.pv, b.pw, b.target_x})
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
  w.integer(warm_.size());
  for (const WarmPoint& p : warm_) {
    for (const std::uint32_t i : {p.a, p.b, p.prim_a, p.prim_b})
      w.integer(i);
    w.glm(p.ra_B);
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

Result<std::unique_ptr<Dynamics>> Dynamics::create(const scene::SceneModel& scene,
                                                   const collision::CollisionWorld& world,
                                                   const DynamicsOptions& options) {
  if (options.velocity_iterations == 0 || options.velocity_iterations > 1000 ||
      options.position_iterations > 1000 || options.max_toi_substeps > 1000) {
    return Error{"dynamics: iteration counts must be 1..1000 (velocity) and 0..1000"};
  }
  if (!(options.slop_fraction >= 0.0 && options.slop_fraction < 0.5) ||
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
    const scene::Body& sb = scene.bodies[i];
    BodyState& b = d->bodies_[i];
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
      b.v_W = sb.linear_velocity_W;
      b.w_W = sb.angular_velocity_W;
    } else if (sb.motion == scene::Motion::kDynamic) {
      moving_prims += sb.primitives.size();
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
          return Error{"dynamics: body '" + sb.name +
                       "' has a non-finite inertia or centre of mass"};
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
          return Error{"dynamics: body '" + sb.name +
                       "' has an inertia tensor that is not positive"};
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
      d->accel_scale_ = std::max(d->accel_scale_, glm::length(b.gravity_W));
      b.v_W = sb.linear_velocity_W;
      b.w_W = i_max > 0.0 ? sb.angular_velocity_W : Vec3{0.0};
      if (!b.isotropic) {
        // no spin about an axis of infinite inertia
        const Mat3 R0 = glm::mat3_cast(glm::normalize(sb.X_WB.rotation));
        const Vec3 w_P = glm::transpose(R0 * P) * b.w_W;
        b.w_W = R0 * P *
                Vec3{inv_P.x > 0 ? w_P.x : 0, inv_P.y > 0 ? w_P.y : 0, inv_P.z > 0 ? w_P.z : 0};
      }
    }
    if (sb.motion != scene::Motion::kStatic)
      moving_prims += sb.primitives.size();
    b.q = glm::normalize(sb.X_WB.rotation);
    b.R = glm::mat3_cast(b.q);
    b.x_W = sb.X_WB.translation + b.R * b.com_B;
    double size = 0.0;
    for (const scene::Primitive& p : sb.primitives) {
      if (!p.shape)
        continue;
      const Vec3 c = p.X_BP.translation + p.X_BP.rotation * p.shape->centroid();
      size = std::max(size, glm::length(c - b.com_B) + p.shape->radius());
    }
    b.size = size > 0.0 ? size : scene.length_scale;
    b.updateInertia();
  }
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
  for (const scene::Joint& j : scene.joints) {
    const auto n = static_cast<std::int32_t>(scene.bodies.size());
    if (j.body_a < 0 || j.body_a >= n || j.body_b >= n || j.body_a == j.body_b ||
        j.hinge_axis > 2) {
      return Error{"dynamics: a joint names a body out of range (or itself, or an axis > 2)"};
    }
    JointState js;
    js.joint = &j;
    js.a = static_cast<std::uint32_t>(j.body_a);
    js.b = j.body_b;
    js.size = std::max(d->bodies_[js.a].size,
                       js.b >= 0 ? d->bodies_[static_cast<std::size_t>(js.b)].size : 0.0);
    d->joints_.push_back(js);
    if (!j.enable_collision && j.body_b >= 0) {
      d->no_collide_.push_back(pairKey(js.a, static_cast<std::uint32_t>(j.body_b)));
    }
  }
  std::sort(d->no_collide_.begin(), d->no_collide_.end());
  d->min_size_ = kInf;
  for (const BodyState& b : d->bodies_) {
    if (b.motion == scene::Motion::kDynamic)
      d->min_size_ = std::min(d->min_size_, b.size);
  }
  const std::size_t cap =
      options.max_contact_points != 0 ? options.max_contact_points : 16 * moving_prims + 64;
  d->max_points_ = cap;
  d->points_.reserve(cap);
  d->dv_.assign(d->bodies_.size(), Vec3{0.0});
  d->dw_.assign(d->bodies_.size(), Vec3{0.0});
  d->warm_.reserve(cap);
  d->warm_next_.reserve(cap);
  d->spreader_ = ImpulseSpreader(options.impulse_window_s, options.tick_s);
  return d;
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
  rest_s_ = 0.0;
}

bool Dynamics::enabled(std::uint32_t body) const {
  return !active_ || body >= bodies_.size() || bodies_[body].enabled;
}

void Dynamics::setDriven(std::uint32_t body, bool driven) {
  if (!active_ || body >= bodies_.size())
    return;
  BodyState& b = bodies_[body];
  if (b.motion != scene::Motion::kDynamic || static_cast<std::int32_t>(body) == held_)
    return;
  b.driven = driven;
  b.has_target = false;
  if (driven)
    asleep_ = false, rest_s_ = 0.0;
}

void Dynamics::setExternalWrench(std::uint32_t body,
                                 const Vec3& force_W_n,
                                 const Vec3& torque_W_nm) {
  if (!active_ || body >= bodies_.size() || bodies_[body].motion != scene::Motion::kDynamic)
    return;
  if (!geom::finite(force_W_n) || !geom::finite(torque_W_nm))
    return;  // not a wrench: ignored, nothing changes
  bodies_[body].force_W = force_W_n;
  bodies_[body].torque_W = torque_W_nm;
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
        continue;
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
    const double e =
        combine(ma.restitution, mb.restitution, ma.restitution_combine, mb.restitution_combine);
    const double mu_s =
        combine(ma.static_friction, mb.static_friction, ma.friction_combine, mb.friction_combine);
    const double mu_d =
        combine(ma.dynamic_friction, mb.dynamic_friction, ma.friction_combine, mb.friction_combine);
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

// joint rows from the poses at the start of the tick (kept through its times of impact)
void Dynamics::prepareJoints() {
  for (JointState& js : joints_) {
    // last tick's impulses become this tick's warm start (axis of last tick)
    js.warm_J = js.total_J;
    js.warm_L = js.total_L - js.axis * (js.tot_lo + js.tot_hi);
    js.warm_lo = js.tot_lo;
    js.warm_hi = js.tot_hi;
    js.total_J = Vec3{0.0};
    js.total_L = Vec3{0.0};
    js.tot_lo = js.tot_hi = 0.0;
    js.off =
        !bodies_[js.a].enabled || (js.b >= 0 && !bodies_[static_cast<std::size_t>(js.b)].enabled);
    if (js.off) {
      js.warm_J = js.warm_L = Vec3{0.0};
      js.warm_lo = js.warm_hi = 0.0;
      continue;
    }
    const scene::Joint& j = *js.joint;
    const BodyState& A = bodies_[js.a];
    const Pose X_WA{A.x_W - A.R * A.com_B, A.q};
    const Vec3 pa = X_WA.translation + X_WA.rotation * j.X_AJ.translation;
    const Quat qa = X_WA.rotation * j.X_AJ.rotation;
    Vec3 pb;
    Quat qb;
    Mat3 ib_inv{0.0};
    double mb_inv = 0.0;
    if (js.b >= 0) {
      const BodyState& B = bodies_[static_cast<std::size_t>(js.b)];
      const Pose X_WB{B.x_W - B.R * B.com_B, B.q};
      pb = X_WB.translation + X_WB.rotation * j.X_BJ.translation;
      qb = X_WB.rotation * j.X_BJ.rotation;
      js.rb = pb - B.x_W;
      ib_inv = B.inv_inertia_W;
      mb_inv = B.invMass();
    } else {
      pb = j.X_BJ.translation;
      qb = j.X_BJ.rotation;
      js.rb = Vec3{0.0};
    }
    js.ra = pa - A.x_W;
    const Mat3 Sa = skew(js.ra), Sb = skew(js.rb);
    const Mat3 K =
        (A.invMass() + mb_inv) * Mat3{1.0} - Sa * A.inv_inertia_W * Sa - Sb * ib_inv * Sb;
    js.point_mass = glm::determinant(K) > 0.0 ? glm::inverse(K) : Mat3{0.0};
    const Mat3 Ka = A.inv_inertia_W + ib_inv;
    if (j.kind == scene::JointKind::kFixed) {
      js.ang_mass = glm::determinant(Ka) > 0.0 ? glm::inverse(Ka) : Mat3{0.0};
    } else {
      Vec3 e{0.0};
      e[j.hinge_axis] = 1.0;
      js.axis = glm::normalize(qa * e);
      tangents(js.axis, &js.p1, &js.p2);
      const auto eff = [&](const Vec3& u) {
        const double k = glm::dot(u, Ka * u);
        return k > 0.0 ? 1.0 / k : 0.0;
      };
      js.m1 = eff(js.p1);
      js.m2 = eff(js.p2);
      js.m_axis = eff(js.axis);
      const Quat rel = glm::conjugate(qa) * qb;
      const double angle = 2.0 * std::atan2(rel[j.hinge_axis], rel.w);
      const double theta = std::remainder(angle, 2.0 * std::numbers::pi);
      js.has_min = j.hinge_min.has_value();
      js.has_max = j.hinge_max.has_value();
      js.c_min = js.has_min ? theta - *j.hinge_min : 0.0;
      js.c_max = js.has_max ? *j.hinge_max - theta : 0.0;
    }
  }
}

// one episode of sequential impulses over the joints and the active contact points
void Dynamics::solveVelocities(double remaining) {
  for (ContactPoint& cp : points_) {
    if (!cp.active && !cp.speculative)
      continue;
    BodyState& A = bodies_[cp.a];
    BodyState& B = bodies_[cp.b];
    cp.ra = A.R * cp.ra_B;
    cp.rb = B.R * cp.rb_B;
    cp.ima = A.invMass();
    cp.imb = B.invMass();
    const auto row = [&](const Vec3& u, Row& r) {
      r.ca = glm::cross(cp.ra, u);
      r.cb = glm::cross(cp.rb, u);
      r.ia = A.inv_inertia_W * r.ca;
      r.ib = B.inv_inertia_W * r.cb;
      const double k = cp.ima + cp.imb + glm::dot(r.ca, r.ia) + glm::dot(r.cb, r.ib);
      r.mass = k > 0.0 ? 1.0 / k : 0.0;
    };
    row(cp.n, cp.rn);
    row(cp.t1, cp.rt1);
    row(cp.t2, cp.rt2);
    cp.mass_n = cp.rn.mass;
    cp.ln = cp.lt1 = cp.lt2 = 0.0;
    cp.min_vn = cp.speculative ? -std::max(cp.gap, 0.0) / remaining : 0.0;
  }
  for (JointState& js : joints_) {
    js.l_point = js.l_ang = Vec3{0.0};
    js.l1 = js.l2 = js.l_lo = js.l_hi = 0.0;
  }
  // warm start (the first episode of a tick): last tick's impulses, applied again
  if (warm_pending_) {
    warm_pending_ = false;
    for (JointState& js : joints_) {
      if (js.off)
        continue;
      BodyState& A = bodies_[js.a];
      BodyState* B = js.b >= 0 ? &bodies_[static_cast<std::size_t>(js.b)] : nullptr;
      js.l_lo = js.has_min ? js.warm_lo : 0.0;
      js.l_hi = js.has_max ? js.warm_hi : 0.0;
      // a hinge's rows act across its axis only: last tick's impulse loses its component along
      // this tick's axis (else the warm start would drive the free rotation)
      const Vec3 across = js.joint->kind == scene::JointKind::kHinge
                              ? js.warm_L - js.axis * glm::dot(js.warm_L, js.axis)
                              : js.warm_L;
      const Vec3 L = across + js.axis * (js.l_lo + js.l_hi);
      if (!A.infinite)
        A.w_W -= A.inv_inertia_W * L;
      if (B != nullptr && !B->infinite)
        B->w_W += B->inv_inertia_W * L;
      A.applyImpulse(-js.warm_J, js.ra);
      if (B != nullptr)
        B->applyImpulse(js.warm_J, js.rb);
      js.total_J += js.warm_J;
      js.total_L += L;
    }
    for (ContactPoint& cp : points_) {
      if (!cp.active || cp.total_n <= 0.0) {
        cp.total_n = 0.0;
        cp.total_t = Vec3{0.0};
        continue;
      }
      cp.ln = cp.total_n;
      cp.lt1 = glm::dot(cp.total_t, cp.t1);
      cp.lt2 = glm::dot(cp.total_t, cp.t2);
      const Vec3 J = cp.n * cp.ln + cp.t1 * cp.lt1 + cp.t2 * cp.lt2;
      bodies_[cp.a].applyImpulse(-J, cp.ra);
      bodies_[cp.b].applyImpulse(J, cp.rb);
      cp.total_n = 0.0;
      cp.total_t = Vec3{0.0};
    }
  }
  const double inv_dt = 1.0 / tick_dt_;
  bool bounces = false;
  for (const ContactPoint& cp : points_)
    bounces = bounces || (cp.bounce > 0.0 && cp.active);
  if (bounces)
    ke_episode_start_ = kineticEnergy();
  for (std::uint32_t it = 0; it < options_.velocity_iterations; ++it) {
    // the largest velocity error any row corrected in this iteration: below the tolerance the
    // episode has converged and stops early
    double residual = 0.0;
    for (JointState& js : joints_) {
      if (js.off)
        continue;
      BodyState& A = bodies_[js.a];
      BodyState* B = js.b >= 0 ? &bodies_[static_cast<std::size_t>(js.b)] : nullptr;
      const Vec3 wb = B != nullptr ? B->w_W : Vec3{0.0};
      const Mat3 ib = B != nullptr ? B->inv_inertia_W : Mat3{0.0};
      const auto applyAngular = [&](const Vec3& L) {
        if (!A.infinite)
          A.w_W -= A.inv_inertia_W * L;
        if (B != nullptr && !B->infinite)
          B->w_W += ib * L;
        js.total_L += L;
      };
      // angular rows
      if (js.joint->kind == scene::JointKind::kFixed) {
        const Vec3 L = js.ang_mass * (-(wb - A.w_W));
        js.l_ang += L;
        applyAngular(L);
        if (js.ang_mass[0][0] + js.ang_mass[1][1] + js.ang_mass[2][2] > 0.0) {
          residual = std::max(residual, glm::length(wb - A.w_W) * js.size);
        }
      } else {
        const Vec3 wrel = wb - A.w_W;
        const double l1 = js.m1 * -glm::dot(wrel, js.p1);
        const double l2 = js.m2 * -glm::dot(wrel, js.p2);
        applyAngular(js.p1 * l1 + js.p2 * l2);
        if (js.m1 > 0.0)
          residual = std::max(residual, std::abs(glm::dot(wrel, js.p1)) * js.size);
        if (js.m2 > 0.0)
          residual = std::max(residual, std::abs(glm::dot(wrel, js.p2)) * js.size);
        if (js.has_min) {
          const double vr = glm::dot((B != nullptr ? B->w_W : Vec3{0.0}) - A.w_W, js.axis);
          const double target = js.c_min > 0.0 ? -js.c_min * inv_dt : 0.0;
          const double old = js.l_lo;
          js.l_lo = std::max(0.0, old + js.m_axis * (target - vr));
          applyAngular(js.axis * (js.l_lo - old));
          if (js.m_axis > 0.0)
            residual = std::max(residual, std::abs(js.l_lo - old) / js.m_axis * js.size);
        }
        if (js.has_max) {
          const double vr = glm::dot((B != nullptr ? B->w_W : Vec3{0.0}) - A.w_W, js.axis);
          const double target = js.c_max > 0.0 ? js.c_max * inv_dt : 0.0;
          const double old = js.l_hi;
          js.l_hi = std::min(0.0, old + js.m_axis * (target - vr));
          applyAngular(js.axis * (js.l_hi - old));
          if (js.m_axis > 0.0)
            residual = std::max(residual, std::abs(js.l_hi - old) / js.m_axis * js.size);
        }
      }
      // the point row
      const Vec3 vb = B != nullptr ? B->velocityAt(js.rb) : Vec3{0.0};
      const Vec3 verr = vb - A.velocityAt(js.ra);
      const Vec3 J = js.point_mass * (-verr);
      if (js.point_mass[0][0] + js.point_mass[1][1] + js.point_mass[2][2] > 0.0) {
        residual = std::max(residual, glm::length(verr));
      }
      A.applyImpulse(-J, js.ra);
      if (B != nullptr)
        B->applyImpulse(J, js.rb);
      js.total_J += J;
    }
    for (ContactPoint& cp : points_) {
      if (!cp.active && !cp.speculative)
        continue;
      BodyState& A = bodies_[cp.a];
      BodyState& B = bodies_[cp.b];
      // relative velocity along a row, and an impulse along it (infinite bodies have zero
      // coefficients, so their velocities stay)
      const auto rel = [&](const Vec3& u, const Row& r) {
        return glm::dot(u, B.v_W - A.v_W) + glm::dot(r.cb, B.w_W) - glm::dot(r.ca, A.w_W);
      };
      const auto push = [&](const Vec3& u, const Row& r, double l) {
        A.v_W -= (cp.ima * l) * u;
        A.w_W -= r.ia * l;
        B.v_W += (cp.imb * l) * u;
        B.w_W += r.ib * l;
      };
      // friction first, limited by this episode's normal impulse (Coulomb, isotropic)
      if (cp.mu > 0.0) {
        const double o1 = cp.lt1, o2 = cp.lt2;
        double l1 = o1 - cp.rt1.mass * rel(cp.t1, cp.rt1);
        double l2 = o2 - cp.rt2.mass * rel(cp.t2, cp.rt2);
        const double lim = cp.mu * cp.ln;
        const double mag2 = l1 * l1 + l2 * l2;
        if (mag2 > lim * lim) {
          const double s = lim > 0.0 ? lim / std::sqrt(mag2) : 0.0;
          l1 *= s;
          l2 *= s;
        }
        cp.lt1 = l1;
        cp.lt2 = l2;
        push(cp.t1, cp.rt1, l1 - o1);
        push(cp.t2, cp.rt2, l2 - o2);
        if (cp.rt1.mass > 0.0)
          residual = std::max(residual, std::abs(l1 - o1) / cp.rt1.mass);
        if (cp.rt2.mass > 0.0)
          residual = std::max(residual, std::abs(l2 - o2) / cp.rt2.mass);
      }
      const double vn = rel(cp.n, cp.rn);
      const double target = cp.speculative ? cp.min_vn : 0.0;
      const double old = cp.ln;
      cp.ln = std::max(0.0, old + cp.rn.mass * (target - vn));
      if (cp.ln_max > 0.0)
        cp.ln = std::min(cp.ln, cp.ln_max);
      push(cp.n, cp.rn, cp.ln - old);
      if (cp.rn.mass > 0.0)
        residual = std::max(residual, std::abs(cp.ln - old) / cp.rn.mass);
    }
    if (it + 1 >= kMinIterations && residual < velocity_tolerance_)
      break;
  }
  // restitution (Poisson's hypothesis): the points that struck get e times their compression
  // impulse back. With the compression solved, this changes the kinetic energy by
  // -(1 - e^2) / 2 lambda^T A lambda <= 0 however many points struck at once (Newton's rule,
  // a target velocity of -e v_n per point, can add energy when several points of a spinning
  // body strike together)
  // The solve is iterative: when it has not converged, the restitution impulses are scaled
  // down (never up) so that the kinetic energy does not end above where the episode began.
  bool any_bounce = false;
  for (const ContactPoint& cp : points_)
    any_bounce = any_bounce || (cp.bounce > 0.0 && cp.active && cp.ln > 0.0);
  if (any_bounce) {
    for (std::size_t i = 0; i < bodies_.size(); ++i)
      dv_[i] = dw_[i] = Vec3{0.0};
    for (const ContactPoint& cp : points_) {
      if (cp.bounce <= 0.0 || !cp.active)
        continue;
      const double l = cp.bounce * cp.ln;
      dv_[cp.a] -= (cp.ima * l) * cp.n;
      dw_[cp.a] -= cp.rn.ia * l;
      dv_[cp.b] += (cp.imb * l) * cp.n;
      dw_[cp.b] += cp.rn.ib * l;
    }
    // KE(s) = KE_c + s a + s^2 b for the restitution scaled by s
    double a = 0.0, b = 0.0;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const BodyState& body = bodies_[i];
      if (body.infinite)
        continue;
      const Mat3 I_W = body.R * body.inertia_B * glm::transpose(body.R);
      const double m = 1.0 / body.inv_mass;
      a += m * glm::dot(body.v_W, dv_[i]) + glm::dot(body.w_W, I_W * dw_[i]);
      b += 0.5 * (m * glm::dot(dv_[i], dv_[i]) + glm::dot(dw_[i], I_W * dw_[i]));
    }
    const double room = ke_episode_start_ - kineticEnergy();  // >= 0: compression dissipates
    double scale = 1.0;
    if (a + b > room) {
      // largest s in [0, 1] with s a + s^2 b <= room
      const double disc = a * a + 4.0 * b * std::max(room, 0.0);
      scale = b > 0.0 ? std::clamp((-a + std::sqrt(disc)) / (2.0 * b), 0.0, 1.0) : 0.0;
    }
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      if (bodies_[i].infinite)
        continue;
      bodies_[i].v_W += scale * dv_[i];
      bodies_[i].w_W += scale * dw_[i];
    }
    for (ContactPoint& cp : points_) {
      if (cp.bounce > 0.0 && cp.active)
        cp.ln += scale * cp.bounce * cp.ln;
    }
  }
  for (ContactPoint& cp : points_) {
    if (!cp.active && !cp.speculative)
      continue;
    cp.total_n += cp.ln;
    cp.total_t += cp.t1 * cp.lt1 + cp.t2 * cp.lt2;
    cp.bounce = 0.0;  // restitution acts once: later episodes only keep the points apart
  }
  for (JointState& js : joints_) {
    if (js.off)
      continue;
    js.tot_lo += js.l_lo;
    js.tot_hi += js.l_hi;
  }
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

// split impulses: pseudo-velocities that remove penetration beyond the slop and joint error,
// applied to the poses only (no energy enters the velocities)
void Dynamics::correctPositions(double dt) {
  const double beta = options_.position_correction;
  if (beta <= 0.0 || options_.position_iterations == 0)
    return;
  const double inv_dt = 1.0 / dt;
  bool any = false;
  for (ContactPoint& cp : points_) {
    cp.lp = 0.0;
    any = any || cp.gap < -options_.slop_fraction * cp.size;
  }
  // joint errors at the end of the tick
  for (JointState& js : joints_) {
    if (js.off)
      continue;
    const scene::Joint& j = *js.joint;
    const BodyState& A = bodies_[js.a];
    js.ra = A.R * (j.X_AJ.translation - A.com_B);
    const Quat qa = A.q * j.X_AJ.rotation;
    // b's attachment frame in the world: on body b, or fixed in the scene frame
    Quat qb = j.X_BJ.rotation;
    if (js.b >= 0) {
      const BodyState& B = bodies_[static_cast<std::size_t>(js.b)];
      js.rb = B.R * (j.X_BJ.translation - B.com_B);
      js.err_point = (B.x_W + js.rb) - (A.x_W + js.ra);  // error, b's anchor from a's
      qb = B.q * j.X_BJ.rotation;
    } else {
      js.rb = Vec3{0.0};
      js.err_point = j.X_BJ.translation - (A.x_W + js.ra);
    }
    js.err_ang = geom::rotationVector(qb * glm::conjugate(qa));
    if (j.kind == scene::JointKind::kHinge) {
      Vec3 e{0.0};
      e[j.hinge_axis] = 1.0;
      js.err_ang = glm::cross(qa * e, qb * e);
      const Quat rel = glm::conjugate(qa) * qb;
      const double theta =
          std::remainder(2.0 * std::atan2(rel[j.hinge_axis], rel.w), 2.0 * std::numbers::pi);
      js.c_min = js.has_min ? theta - *j.hinge_min : 0.0;
      js.c_max = js.has_max ? *j.hinge_max - theta : 0.0;
      js.axis = glm::normalize(qa * e);
    }
    any = true;
  }
  if (!any)
    return;
  for (std::uint32_t it = 0; it < options_.position_iterations; ++it) {
    for (JointState& js : joints_) {
      if (js.off)
        continue;
      BodyState& A = bodies_[js.a];
      BodyState* B = js.b >= 0 ? &bodies_[static_cast<std::size_t>(js.b)] : nullptr;
      const Vec3 pwb = B != nullptr ? B->pw : Vec3{0.0};
      const Mat3 ib = B != nullptr && !B->infinite ? B->inv_inertia_W : Mat3{0.0};
      const Mat3 Ka = A.inv_inertia_W + ib;
      const auto applyAngular = [&](const Vec3& L) {
        if (!A.infinite)
          A.pw -= A.inv_inertia_W * L;
        if (B != nullptr && !B->infinite)
          B->pw += ib * L;
      };
      // angular error: drive the relative pseudo angular velocity to -beta * error / dt
      Vec3 wrel = pwb - A.pw;
      const Vec3 goal = -beta * inv_dt * js.err_ang;
      if (js.joint->kind == scene::JointKind::kFixed) {
        if (glm::determinant(Ka) > 0.0)
          applyAngular(glm::inverse(Ka) * (goal - wrel));
      } else {
        // only the two directions across the axis
        Vec3 u1, u2;
        tangents(js.axis, &u1, &u2);
        for (const Vec3& u : {u1, u2}) {
          const double k = glm::dot(u, Ka * u);
          wrel = (B != nullptr ? B->pw : Vec3{0.0}) - A.pw;
          if (k > 0.0)
            applyAngular(u * (glm::dot(goal - wrel, u) / k));
        }
        const double k = glm::dot(js.axis, Ka * js.axis);
        if (k > 0.0) {
          const double vr = glm::dot((B != nullptr ? B->pw : Vec3{0.0}) - A.pw, js.axis);
          if (js.has_min && js.c_min < 0.0) {
            const double want = -beta * inv_dt * js.c_min;  // > 0
            if (vr < want)
              applyAngular(js.axis * ((want - vr) / k));
          }
          if (js.has_max && js.c_max < 0.0) {
            const double want = beta * inv_dt * js.c_max;  // < 0
            if (vr > want)
              applyAngular(js.axis * ((want - vr) / k));
          }
        }
      }
      // point error
      const Mat3 Sa = skew(js.ra), Sb = skew(js.rb);
      const double mb = B != nullptr ? B->invMass() : 0.0;
      const Mat3 K = (A.invMass() + mb) * Mat3{1.0} - Sa * A.inv_inertia_W * Sa - Sb * ib * Sb;
      if (glm::determinant(K) > 0.0) {
        const Vec3 vb = B != nullptr ? B->pseudoAt(js.rb) : Vec3{0.0};
        const Vec3 vrel = vb - A.pseudoAt(js.ra);
        const Vec3 J = glm::inverse(K) * (-beta * inv_dt * js.err_point - vrel);
        A.applyPseudo(-J, js.ra);
        if (B != nullptr)
          B->applyPseudo(J, js.rb);
      }
    }
    for (ContactPoint& cp : points_) {
      const double excess = -cp.gap - options_.slop_fraction * cp.size;
      if (excess <= 0.0 && cp.lp == 0.0)
        continue;
      BodyState& A = bodies_[cp.a];
      BodyState& B = bodies_[cp.b];
      const double vn = glm::dot(B.pseudoAt(cp.rb) - A.pseudoAt(cp.ra), cp.n);
      const double target = beta * inv_dt * std::max(excess, 0.0);
      double m = cp.mass_n;
      if (!cp.active && !cp.speculative) {
        const Vec3 ca = glm::cross(cp.ra, cp.n), cb = glm::cross(cp.rb, cp.n);
        const double k = A.invMass() + B.invMass() + glm::dot(ca, A.inv_inertia_W * ca) +
                         glm::dot(cb, B.inv_inertia_W * cb);
        m = cp.mass_n = k > 0.0 ? 1.0 / k : 0.0;
        cp.speculative = false;
        cp.active = true;  // its mass is now known; it stays a position-only point
      }
      const double old = cp.lp;
      cp.lp = std::max(0.0, old + m * (target - vn));
      const Vec3 J = cp.n * (cp.lp - old);
      A.applyPseudo(-J, cp.ra);
      B.applyPseudo(J, cp.rb);
    }
  }
  for (BodyState& b : bodies_) {
    if (b.infinite)
      continue;
    b.x_W += b.pv * dt;
    b.q = glm::normalize(geom::quatFromRotationVector(b.pw * dt) * b.q);
    b.updateInertia();
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
      // the whole scene rests: nothing moves until something pushes; impulses still in the
      // spreader's window are delivered
      ++counters_.ticks_asleep;
      if (held_ >= 0) {
        // a kinematically held body that touches nothing moves on while the scene sleeps
        // (taken straight to its target: it pushes nothing), so that it does not jump on waking
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

  // restitution and friction thresholds, relative to the tick's gravity and the bodies' size
  const double v_gravity = options_.restitution_threshold_ticks * accel_scale_ * dt;
  velocity_tolerance_ = options_.velocity_tolerance_fraction *
                        std::max(v_gravity, options_.restitution_threshold_fraction * min_size_);
  for (ContactPoint& cp : points_) {
    const double size = std::isfinite(cp.size) ? cp.size : scene_->length_scale;
    cp.size = size;
  }
  const auto threshold = [&](const ContactPoint& cp) {
    return std::max(v_gravity, options_.restitution_threshold_fraction * cp.size);
  };
  const auto activate = [&](ContactPoint& cp) {
    const BodyState& A = bodies_[cp.a];
    const BodyState& B = bodies_[cp.b];
    const Vec3 vrel = B.velocityAt(cp.rb) - A.velocityAt(cp.ra);
    const double vn = glm::dot(vrel, cp.n);
    const double thr = threshold(cp);
    cp.active = true;
    cp.bounce = vn < -thr ? cp.e : 0.0;
    const double vt = glm::length(vrel - cp.n * vn);
    cp.mu = vt < options_.static_friction_speed_fraction * thr ? cp.mu_s : cp.mu_d;
  };
  const auto touchTolerance = [&](const ContactPoint& cp) {
    // a point whose gap closes counts as touching from here (never zero: a gap that closes
    // exactly at its time of impact may be left at +1e-18 by rounding)
    return std::max(0.25 * options_.slop_fraction, 1e-9) * cp.size;
  };

  // the first solve at the start of the tick: points touching now (and the joints)
  warm_pending_ = true;
  bool any_active = !joints_.empty();
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

  // §6.1: advance to the earliest time of impact, apply the impulses there, go on
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

  // held body feedback: what the contacts and joints gave it this tick
  HeldFeedback fb;
  if (held_ >= 0 && static_cast<std::size_t>(held_) < bodies_.size()) {
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
    spreader_.add(fb.impulse_W_ns, fb.angular_impulse_W_nms);
    spreader_.pop(&fb.force_W_n, &fb.torque_W_nm);
  }
  held_feedback_ = fb;

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
  // sleep: once every moving body has been still for sleep_time_s
  if (options_.sleep_time_s > 0.0) {
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
  report.flags = step_flags_;
  return report;
}

// anything that could move a resting scene: the held body's input, a kinematic target, an
// external wrench
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
