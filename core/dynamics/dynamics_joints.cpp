// The general joint of KHR_physics_rigid_bodies: every joint the fixed-joint and hinge rows of
// dynamics_solver.cpp do not take (sliders, ball joints, cones, ranged, one-sided and soft limits,
// drives). Each limit and drive becomes one-dimensional rows (Catto, "Iterative dynamics with
// temporal coherence", GDC 2005) along an axis of body a's attachment frame:
//  - linear: b's anchor from a's along an axis (one axis), or its distance from a line (two axes)
//    or from a's anchor (three axes);
//  - angular: Tait-Bryan angles of b's attachment frame in a's about a cyclic order of the axes
//    chosen per joint so that the singular middle axis is a locked one (the rates of the three
//    angles are the dual basis of a's first axis, the line of nodes and b's last axis), or for a
//    limit on two axes the angle between the frames' third axes (a cone about it).
// Hard rows are velocity constraints (limits speculative, as the hinge's) with their drift removed
// by split impulses; soft limits and drives are implicit spring-dampers (Catto, "Soft step", GDC
// 2011: for a stiffness k, damping c and tick h the row solves v + bias + gamma * impulse = 0 with
// gamma = 1 / (h (c + h k)); the spring acts on the position at the end of the tick, so the row
// is stable at any k and the static deflection is exactly F / k). Drives in "acceleration" mode
// scale k and c by the row's effective mass; maxForce bounds the row's impulse by maxForce * h.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>

#include "core/dynamics/dynamics_internal.h"

namespace hapticd::dynamics {

using detail::kInf;
using detail::pairKey;

// the two attachment frames at the bodies' current poses
struct Dynamics::JointFrames {
  Mat3 Aw{1.0}, Bw{1.0};  // columns: the frames' axes in the scene frame
  Vec3 ra{0.0}, rb{0.0};  // b's anchor from a's centre of mass, and from b's
  Vec3 d_J{0.0};          // b's anchor from a's, in a's attachment frame
  Vec3 euler{0.0};  // Tait-Bryan angles of b's frame in a's, by axis (GeneralJoint::euler_shift)
  std::array<Vec3, 3> rate{};  // the angles' rates are rate[k] . (w_b - w_a)
  bool euler_ok = false;       // false at the angles' singularity (the middle one at +-pi / 2)
};

Dynamics::JointFrames Dynamics::jointFrames(const GeneralJoint& gj) const {
  JointFrames f;
  const scene::Joint& j = *gj.joint;
  const BodyState& A = bodies_[gj.a];
  const Quat qa = A.q * j.X_AJ.rotation;
  const Vec3 pa = A.x_W + A.R * (j.X_AJ.translation - A.com_B);
  Quat qb = j.X_BJ.rotation;
  Vec3 pb = j.X_BJ.translation;
  if (gj.b >= 0) {
    const BodyState& B = bodies_[static_cast<std::size_t>(gj.b)];
    qb = B.q * j.X_BJ.rotation;
    pb = B.x_W + B.R * (j.X_BJ.translation - B.com_B);
    f.rb = pb - B.x_W;
  }
  f.ra = pb - A.x_W;  // a's lever reaches b's anchor: the linear rates are exact
  f.Aw = glm::mat3_cast(glm::normalize(qa));
  f.Bw = glm::mat3_cast(glm::normalize(qb));
  f.d_J = glm::transpose(f.Aw) * (pb - pa);
  // Tait-Bryan angles about the axes i, j, k (a cyclic shift of x, y, z, so R = Ri Rj Rk in a
  // right-handed relabelling): the middle one is singular at +-pi/2, so the shift chosen at load
  // puts a locked axis (or one without angular rows) there
  const int i = gj.euler_shift, m = (i + 1) % 3, k = (i + 2) % 3;
  const Mat3 R = glm::transpose(f.Aw) * f.Bw;  // R[col][row]
  f.euler[m] = std::asin(std::clamp(R[k][i], -1.0, 1.0));
  f.euler[i] = std::atan2(-R[k][m], R[k][k]);
  f.euler[k] = std::atan2(-R[m][i], R[i][i]);
  // w_b - w_a = i' e1 + j' e2 + k' e3 with e1 a's i axis, e3 b's k axis, e2 the line of nodes;
  // the rates are the dual basis
  const Vec3 e1 = f.Aw[i], e3 = f.Bw[k];
  const Vec3 c = glm::cross(e3, e1);
  const double v = glm::length(c);  // cos of the middle angle
  if (v > 1e-6) {
    const Vec3 e2 = c / v;
    f.rate[static_cast<std::size_t>(i)] = glm::cross(e2, e3) / v;
    f.rate[static_cast<std::size_t>(m)] = e2;
    f.rate[static_cast<std::size_t>(k)] = glm::cross(e1, e2) / v;
    f.euler_ok = true;
  }
  return f;
}

// a row's measure and Jacobian at the frames f; false where its direction is not defined (a
// distance or cone angle of 0, the Euler angles' singularity)
bool Dynamics::measureRow(const JointFrames& f, const JointRowSpec& spec, JointRow& row) const {
  switch (spec.measure) {
    case JointRowSpec::Measure::kLinear:
      row.u = f.Aw[spec.axis];
      row.position = f.d_J[spec.axis];
      break;
    case JointRowSpec::Measure::kRadial: {
      Vec3 d{0.0};
      for (int k = 0; k < 3; ++k) {
        if ((spec.mask >> k) & 1u)
          d += f.Aw[k] * f.d_J[k];
      }
      row.position = glm::length(d);
      if (!(row.position > 0.0))
        return false;
      row.u = d / row.position;
      break;
    }
    case JointRowSpec::Measure::kAngular:
      if (!f.euler_ok)
        return false;
      row.u = Vec3{0.0};
      row.ca = row.cb = f.rate[spec.axis];
      row.position = f.euler[spec.axis];
      return true;
    case JointRowSpec::Measure::kCone: {
      const Vec3 at = f.Aw[spec.axis], bt = f.Bw[spec.axis];
      const Vec3 c = glm::cross(at, bt);
      const double s = glm::length(c);
      row.position = std::atan2(s, glm::dot(at, bt));
      if (!(s > 1e-12))
        return false;
      row.u = Vec3{0.0};
      row.ca = row.cb = c / s;
      return true;
    }
  }
  row.ca = glm::cross(f.ra, row.u);
  row.cb = glm::cross(f.rb, row.u);
  return true;
}

// the rows of one joint from its limits (or, for a joint built without limits, from its kind)
// and drives
Result<bool> Dynamics::initGeneralJoint(const scene::Joint& j) {
  GeneralJoint gj;
  gj.joint = &j;
  gj.a = static_cast<std::uint32_t>(j.body_a);
  gj.b = j.body_b;
  gj.size =
      std::max(bodies_[gj.a].size, gj.b >= 0 ? bodies_[static_cast<std::size_t>(gj.b)].size : 0.0);
  std::vector<scene::JointLimit> limits = j.limits;
  if (limits.empty()) {
    // built by code with a kind only: its locks (and a hinge's limits)
    const auto lock = [&](std::uint8_t lin, std::uint8_t ang) {
      scene::JointLimit l;
      l.linear_axes = lin;
      l.angular_axes = ang;
      l.min = l.max = 0.0;
      limits.push_back(l);
    };
    const auto free_bit = static_cast<std::uint8_t>(1u << (j.hinge_axis % 3));
    switch (j.kind) {
      case scene::JointKind::kFixed:
        lock(7, 0), lock(0, 7);
        break;
      case scene::JointKind::kHinge: {
        lock(7, 0), lock(0, static_cast<std::uint8_t>(7u & ~free_bit));
        if (j.hinge_min || j.hinge_max) {
          scene::JointLimit l;
          l.angular_axes = free_bit;
          l.min = j.hinge_min;
          l.max = j.hinge_max;
          limits.push_back(l);
        }
        break;
      }
      case scene::JointKind::kSlider:
        lock(static_cast<std::uint8_t>(7u & ~free_bit), 0), lock(0, 7);
        break;
      case scene::JointKind::kBall:
        lock(7, 0);
        break;
      case scene::JointKind::kGeneric:
        break;
    }
  }
  const auto finite = [](const std::optional<double>& x) { return !x || std::isfinite(*x); };
  for (const scene::JointLimit& lim : limits) {
    const bool linear = lim.linear_axes != 0;
    const std::uint8_t mask = linear ? lim.linear_axes : lim.angular_axes;
    if (mask == 0 || mask > 7 || (lim.linear_axes != 0 && lim.angular_axes != 0) ||
        !finite(lim.min) || !finite(lim.max) || !finite(lim.stiffness) ||
        (lim.stiffness && !(*lim.stiffness >= 0.0)) || !(lim.damping >= 0.0) ||
        !std::isfinite(lim.damping)) {
      return Error{
          "dynamics: a joint limit has no axes, both kinds of axes, or a value that is "
          "not finite (or a negative stiffness or damping)"};
    }
    JointRowSpec base;
    base.soft = lim.stiffness.has_value();
    base.stiffness = lim.stiffness.value_or(0.0);
    base.damping = lim.damping;
    base.mask = mask;
    const auto add = [&](JointRowSpec::Measure m, JointRowSpec::Bound b, int axis, double value) {
      JointRowSpec s = base;
      s.measure = m;
      s.bound = b;
      s.axis = static_cast<std::uint8_t>(axis);
      s.value = value;
      if (b == JointRowSpec::Bound::kLock)
        s.soft = false;
      gj.specs.push_back(s);
    };
    // each axis of the mask: a lock (min == max, hard) or a bound each side
    const auto perAxis = [&](JointRowSpec::Measure m) {
      for (int k = 0; k < 3; ++k) {
        if (!((mask >> k) & 1u))
          continue;
        if (!base.soft && lim.min && lim.max && *lim.min == *lim.max) {
          add(m, JointRowSpec::Bound::kLock, k, *lim.min);
          continue;
        }
        if (lim.min)
          add(m, JointRowSpec::Bound::kMin, k, *lim.min);
        if (lim.max)
          add(m, JointRowSpec::Bound::kMax, k, *lim.max);
      }
    };
    const JointRowSpec::Measure one =
        linear ? JointRowSpec::Measure::kLinear : JointRowSpec::Measure::kAngular;
    const int axes = std::popcount(static_cast<unsigned>(mask));
    if (axes > 1 && !base.soft && lim.max && *lim.max <= 0.0) {
      // a distance (or cone angle) of at most 0: every axis locked
      for (int k = 0; k < 3; ++k) {
        if ((mask >> k) & 1u)
          add(one, JointRowSpec::Bound::kLock, k, 0.0);
      }
    } else if (axes == 1 || (!linear && axes == 3)) {
      perAxis(one);  // one axis, or three angles: each Euler angle within the range
    } else {
      // from a line or a point (linear), or within a cone about the remaining axis (angular)
      const JointRowSpec::Measure m =
          linear ? JointRowSpec::Measure::kRadial : JointRowSpec::Measure::kCone;
      const int axis = linear ? 0 : std::countr_zero(~static_cast<unsigned>(mask) & 7u);
      if (lim.min && *lim.min > 0.0)
        add(m, JointRowSpec::Bound::kMin, axis, *lim.min);
      if (lim.max)
        add(m, JointRowSpec::Bound::kMax, axis, *lim.max);
    }
  }
  for (const scene::JointDrive& d : j.drives) {
    if (d.axis > 2 || !finite(d.max_force) || !finite(d.position_target) ||
        !finite(d.velocity_target) || !(d.stiffness >= 0.0) || !(d.damping >= 0.0) ||
        !std::isfinite(d.stiffness) || !std::isfinite(d.damping) ||
        (d.max_force && !(*d.max_force >= 0.0))) {
      return Error{
          "dynamics: a joint drive has an axis > 2, a value that is not finite or a "
          "negative stiffness, damping or maxForce"};
    }
    JointRowSpec s;
    s.measure = d.angular ? JointRowSpec::Measure::kAngular : JointRowSpec::Measure::kLinear;
    s.bound = JointRowSpec::Bound::kDrive;
    s.axis = d.axis;
    s.stiffness = d.stiffness;
    s.damping = d.damping;
    s.acceleration = d.acceleration;
    s.has_position = d.position_target.has_value();
    s.has_velocity = d.velocity_target.has_value();
    s.position_target = d.position_target.value_or(0.0);
    s.velocity_target = d.velocity_target.value_or(0.0);
    // a maxForce of 0 holds nothing: a tiny bound rather than "unlimited"
    s.max_impulse_rate = d.max_force ? std::max(*d.max_force, 1e-300) : 0.0;
    gj.specs.push_back(s);
  }
  // the middle Euler axis (singular at +-pi/2): a locked one if any, else one without angular
  // rows, never one with a range or a drive if avoidable (a hinge about y keeps its full turn)
  int best = 3;
  for (std::uint8_t shift = 0; shift < 3; ++shift) {
    const int middle = (shift + 1) % 3;
    bool locked = false, ranged = false;
    for (const JointRowSpec& sp : gj.specs) {
      if (sp.measure != JointRowSpec::Measure::kAngular || sp.axis != middle)
        continue;
      (sp.bound == JointRowSpec::Bound::kLock ? locked : ranged) = true;
    }
    const int score = ranged ? 2 : locked ? 0 : 1;
    if (score < best) {
      best = score;
      gj.euler_shift = shift;
    }
  }
  gj.rows.resize(gj.specs.size());
  general_.push_back(std::move(gj));
  if (!j.enable_collision && j.body_b >= 0)
    no_collide_.push_back(
        pairKey(static_cast<std::uint32_t>(j.body_a), static_cast<std::uint32_t>(j.body_b)));
  return true;
}

// every row at the start of the tick: its Jacobian, effective mass, bias and bounds; last tick's
// impulse kept for the warm start
void Dynamics::prepareGeneralJoints() {
  const double h = tick_dt_;
  for (GeneralJoint& gj : general_) {
    gj.off =
        !bodies_[gj.a].enabled || (gj.b >= 0 && !bodies_[static_cast<std::size_t>(gj.b)].enabled);
    const JointFrames f = jointFrames(gj);
    const BodyState& A = bodies_[gj.a];
    const BodyState* B = gj.b >= 0 ? &bodies_[static_cast<std::size_t>(gj.b)] : nullptr;
    const double im = A.invMass() + (B != nullptr ? B->invMass() : 0.0);
    for (std::size_t r = 0; r < gj.rows.size(); ++r) {
      JointRow& row = gj.rows[r];
      const JointRowSpec& spec = gj.specs[r];
      row.was_active = row.active;
      row.warm = row.active ? row.acc : 0.0;
      row.acc = 0.0;
      row.active = false;
      if (gj.off || !measureRow(f, spec, row))
        continue;
      row.ia = A.inv_inertia_W * row.ca;
      row.ib = B != nullptr ? B->inv_inertia_W * row.cb : Vec3{0.0};
      const double k =
          im * glm::dot(row.u, row.u) + glm::dot(row.ca, row.ia) + glm::dot(row.cb, row.ib);
      if (!(k > 0.0))
        continue;  // both ends of infinite mass (or a direction neither body can move along)
      row.mass = 1.0 / k;
      row.gamma = 0.0;
      row.bias = 0.0;
      row.lo = -kInf;
      row.hi = kInf;
      // the spring-damper of a soft limit or a drive: v + bias + gamma * impulse = 0
      const auto spring = [&](double stiffness, double damping, double stretch, double v_target) {
        const double c_hk = damping + h * stiffness;
        if (!(c_hk > 0.0))
          return false;
        row.gamma = 1.0 / (h * c_hk);
        row.bias = (stiffness * stretch - damping * v_target) / c_hk;
        return true;
      };
      const bool angular = spec.measure == JointRowSpec::Measure::kAngular ||
                           spec.measure == JointRowSpec::Measure::kCone;
      switch (spec.bound) {
        case JointRowSpec::Bound::kLock:
          row.active = true;
          break;
        case JointRowSpec::Bound::kMin: {
          const double c = row.position - spec.value;  // > 0 inside
          row.lo = 0.0;
          if (spec.soft) {
            row.active = c < 0.0 && spring(spec.stiffness, spec.damping, c, 0.0);
          } else {
            row.active = true;
            row.bias = c > 0.0 ? c / h : 0.0;  // speculative: it may approach the bound
          }
          break;
        }
        case JointRowSpec::Bound::kMax: {
          const double c = spec.value - row.position;  // > 0 inside
          row.hi = 0.0;
          if (spec.soft) {
            row.active = c < 0.0 && spring(spec.stiffness, spec.damping, -c, 0.0);
          } else {
            row.active = true;
            row.bias = c > 0.0 ? -c / h : 0.0;
          }
          break;
        }
        case JointRowSpec::Bound::kDrive: {
          const double scale = spec.acceleration ? row.mass : 1.0;
          const double stiffness = spec.has_position ? spec.stiffness * scale : 0.0;
          double err = spec.position_target - row.position;
          if (angular)
            err = std::remainder(err, 2.0 * std::numbers::pi);
          // stretch = position - target: the spring pulls back towards the target
          row.active = spring(stiffness, spec.damping * scale, spec.has_position ? -err : 0.0,
                              spec.has_velocity ? spec.velocity_target : 0.0);
          if (spec.max_impulse_rate > 0.0) {
            row.hi = spec.max_impulse_rate * h;
            row.lo = -row.hi;
          }
          break;
        }
      }
      row.soft_mass = 1.0 / (k + row.gamma);
    }
  }
}

// last tick's impulses applied again (the first solve of a tick), within this tick's bounds
void Dynamics::warmStartGeneralJoints() {
  for (GeneralJoint& gj : general_) {
    if (gj.off)
      continue;
    BodyState& A = bodies_[gj.a];
    BodyState* B = gj.b >= 0 ? &bodies_[static_cast<std::size_t>(gj.b)] : nullptr;
    for (JointRow& row : gj.rows) {
      if (!row.active || !row.was_active)
        continue;
      row.acc = std::clamp(row.warm, row.lo, row.hi);
      A.v_W -= A.invMass() * row.acc * row.u;
      A.w_W -= row.ia * row.acc;
      if (B != nullptr) {
        B->v_W += B->invMass() * row.acc * row.u;
        B->w_W += row.ib * row.acc;
      }
    }
  }
}

// one iteration over a joint's rows (sequential impulses, accumulated over the whole tick)
void Dynamics::solveGeneralJoint(GeneralJoint& gj, double& residual) {
  BodyState& A = bodies_[gj.a];
  BodyState* B = gj.b >= 0 ? &bodies_[static_cast<std::size_t>(gj.b)] : nullptr;
  const double ima = A.invMass(), imb = B != nullptr ? B->invMass() : 0.0;
  for (std::size_t r = 0; r < gj.rows.size(); ++r) {
    JointRow& row = gj.rows[r];
    if (!row.active)
      continue;
    double v = -glm::dot(row.u, A.v_W) - glm::dot(row.ca, A.w_W);
    if (B != nullptr)
      v += glm::dot(row.u, B->v_W) + glm::dot(row.cb, B->w_W);
    const double old = row.acc;
    row.acc = std::clamp(old - row.soft_mass * (v + row.bias + row.gamma * old), row.lo, row.hi);
    const double d = row.acc - old;
    A.v_W -= ima * d * row.u;
    A.w_W -= row.ia * d;
    if (B != nullptr) {
      B->v_W += imb * d * row.u;
      B->w_W += row.ib * d;
    }
    const bool angular = gj.specs[r].measure == JointRowSpec::Measure::kAngular ||
                         gj.specs[r].measure == JointRowSpec::Measure::kCone;
    residual = std::max(residual, std::abs(d) / row.mass * (angular ? gj.size : 1.0));
  }
}

// the hard rows' errors at the end of the tick, for the drift correction; true when one acts
bool Dynamics::measureGeneralErrors() {
  bool any = false;
  for (GeneralJoint& gj : general_) {
    if (gj.off)
      continue;
    const JointFrames f = jointFrames(gj);
    const BodyState& A = bodies_[gj.a];
    const BodyState* B = gj.b >= 0 ? &bodies_[static_cast<std::size_t>(gj.b)] : nullptr;
    const double im = A.invMass() + (B != nullptr ? B->invMass() : 0.0);
    for (std::size_t r = 0; r < gj.rows.size(); ++r) {
      JointRow& row = gj.rows[r];
      const JointRowSpec& spec = gj.specs[r];
      row.pos_on = false;
      row.lp = 0.0;
      if (spec.soft || spec.bound == JointRowSpec::Bound::kDrive)
        continue;
      // the end-of-tick Jacobian replaces this tick's (the impulses are summed already);
      // the feedback reads the impulse along it
      const Vec3 u = row.u, ca = row.ca, cb = row.cb;
      if (!measureRow(f, spec, row)) {
        row.u = u;
        row.ca = ca;
        row.cb = cb;
        continue;
      }
      double err = 0.0;
      if (spec.bound == JointRowSpec::Bound::kLock)
        err = row.position - spec.value;
      else if (spec.bound == JointRowSpec::Bound::kMin)
        err = std::min(row.position - spec.value, 0.0);
      else
        err = std::max(row.position - spec.value, 0.0);
      row.ia = A.inv_inertia_W * row.ca;
      row.ib = B != nullptr ? B->inv_inertia_W * row.cb : Vec3{0.0};
      const double k =
          im * glm::dot(row.u, row.u) + glm::dot(row.ca, row.ia) + glm::dot(row.cb, row.ib);
      if (!(k > 0.0) || err == 0.0)
        continue;
      row.mass = 1.0 / k;
      row.pos_err = err;
      row.pos_on = true;
      any = true;
    }
  }
  return any;
}

// one iteration of split impulses over a joint's hard rows: each error removed at beta per tick
void Dynamics::correctGeneralJoint(GeneralJoint& gj, double beta, double inv_dt) {
  BodyState& A = bodies_[gj.a];
  BodyState* B = gj.b >= 0 ? &bodies_[static_cast<std::size_t>(gj.b)] : nullptr;
  const double ima = A.invMass(), imb = B != nullptr ? B->invMass() : 0.0;
  for (std::size_t r = 0; r < gj.rows.size(); ++r) {
    JointRow& row = gj.rows[r];
    if (!row.pos_on)
      continue;
    double v = -glm::dot(row.u, A.pv) - glm::dot(row.ca, A.pw);
    if (B != nullptr)
      v += glm::dot(row.u, B->pv) + glm::dot(row.cb, B->pw);
    const double target = -beta * inv_dt * row.pos_err;
    const double old = row.lp;
    double l = old + row.mass * (target - v);
    const JointRowSpec::Bound bound = gj.specs[r].bound;
    if (bound == JointRowSpec::Bound::kMin)
      l = std::max(l, 0.0);
    else if (bound == JointRowSpec::Bound::kMax)
      l = std::min(l, 0.0);
    row.lp = l;
    const double d = l - old;
    A.pv -= ima * d * row.u;
    A.pw -= row.ia * d;
    if (B != nullptr) {
      B->pv += imb * d * row.u;
      B->pw += row.ib * d;
    }
  }
}

// the general joints' impulses on the held body this tick
void Dynamics::generalFeedback(HeldFeedback& fb) const {
  for (const GeneralJoint& gj : general_) {
    if (gj.off)
      continue;
    const bool a_held = static_cast<std::int32_t>(gj.a) == held_;
    const bool b_held = gj.b >= 0 && gj.b == held_;
    if (!a_held && !b_held)
      continue;
    for (const JointRow& row : gj.rows) {
      if (!row.active)
        continue;
      if (a_held) {
        fb.impulse_W_ns -= row.u * row.acc;
        fb.angular_impulse_W_nms -= row.ca * row.acc;
      } else {
        fb.impulse_W_ns += row.u * row.acc;
        fb.angular_impulse_W_nms += row.cb * row.acc;
      }
    }
  }
}

}  // namespace hapticd::dynamics
