// The solvers of the dynamics (Catto, "Iterative dynamics with temporal coherence", GDC 2005):
// joint rows from the poses at the start of the tick, sequential impulses with accumulated
// clamping and warm starts, restitution by Poisson's hypothesis scaled so that no solve adds
// energy, and split-impulse drift correction.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/dynamics/dynamics_internal.h"
#include "core/geometry/rotation.h"

namespace hapticd::dynamics {

using detail::kInf;
using detail::kMinIterations;
using detail::skew;
using detail::tangents;

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
  for (JointState& js : joints_) {
    js.l_point = js.l_ang = Vec3{0.0};
    js.l1 = js.l2 = js.l_lo = js.l_hi = 0.0;
  }
  // warm start (the first episode of a tick): last tick's impulses, applied again, the joints'
  // first, then the contact points' in their order as their rows are made
  const bool warm = warm_pending_;
  warm_pending_ = false;
  if (warm)
    applyJointWarmStart();
  const bool bounces = prepareRows(remaining, warm);
  const double inv_dt = 1.0 / tick_dt_;
  if (bounces)
    ke_episode_start_ = kineticEnergy();
  // settling iterations (DynamicsOptions::velocity_iterations_max): beyond the fixed count while
  // the residual falls and still moves a body by more than the settle tolerance in a tick, within
  // the tick's row budget
  const std::uint32_t cap =
      std::max(options_.velocity_iterations, options_.velocity_iterations_max);
  // the tolerance divided by the mass ratio across a resting contact, as the early stop's (an
  // iteration's corrections underestimate the error left by about the ratio)
  const double settle = options_.settle_tolerance_fraction * min_size_ / tick_dt_ / mass_ratio_;
  const auto rows = static_cast<std::uint32_t>(points_.size() + joints_.size() + general_.size());
  double last = kInf;
  for (std::uint32_t it = 0; it < cap; ++it) {
    if (it >= options_.velocity_iterations) {
      if (!(last > settle) || settle_rows_ + rows > options_.settle_row_budget)
        break;
      settle_rows_ += rows;
    }
    // the largest velocity error any row corrected in this iteration: below the tolerance the
    // episode has converged and stops early. The settling's is each contact's relative to the
    // slop's length of its island (as min_size_ to it): a bead lying beside a stack a hundred
    // times larger made the settling go on to the row budget for the stack's rows, and the
    // tick's first solve spent it (a frictionless 5 mm wall with a cube of 1% of its edge beside
    // it then fell)
    double residual = 0.0;
    for (JointState& js : joints_) {
      if (js.off)
        continue;
      solveJoint(js, inv_dt, residual);
    }
    for (GeneralJoint& gj : general_) {
      if (!gj.off)
        solveGeneralJoint(gj, residual);
    }
    double settling = residual;
    for (std::size_t i = 0; i < points_.size();) {
      const std::size_t group = std::max<std::size_t>(points_[i].group, 1);
      double pair = 0.0;
      if (blocks_[i].ok) {
        solveBlock(blocks_[i], pair);
      } else {
        for (std::size_t k = i; k < i + group; ++k) {
          ContactPoint& cp = points_[k];
          if (cp.active || cp.speculative)
            solveContact(cp, pair);
        }
      }
      residual = std::max(residual, pair);
      settling = std::max(settling, one_size_ ? pair : pair * min_size_ / slopSize(points_[i]));
      i += group;
    }
    ++iterations_run_;
    if (it + 1 >= kMinIterations && residual < velocity_tolerance_)
      break;
    // settling goes on only while the residual falls; with unequal masses resting on each
    // other it goes on whatever the residual does (to the tolerance, the cap or the row
    // budget): sequential impulses pass a heavy body's load through a light one a fraction per
    // iteration and the residual of ten cubes alternating 1:100 rises and falls on its way
    // down, so the settling stopped after a few iterations and the tower leant over from
    // rounding (thrown apart at 5 mm and 2 cm; Stack.AlternatingHeavyLightTowerStands)
    last = it + 1 < options_.velocity_iterations || settling < last || mass_ratio_ > 1.0 ? settling
                                                                                         : 0.0;
  }
  if (bounces)
    applyRestitution();
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

// the rows of every active point at the current orientations, this episode's impulses zero;
// with `warm` (the first episode of a tick) each point's warm start applied once its rows are
// made (the joints' were applied before: the same order of the impulses as applied after all
// rows); each primitive pair's block once its points' rows are made: one pass over the points.
// True when an active point strikes (its restitution is to be applied)
bool Dynamics::prepareRows(double remaining, bool warm) {
  bool bounces = false;
  for (std::size_t first = 0; first < points_.size();) {
    const std::size_t group = std::max<std::size_t>(points_[first].group, 1);
    for (std::size_t k = first; k < first + group; ++k) {
      ContactPoint& cp = points_[k];
      if (cp.active || cp.speculative) {
        prepareRow(cp, remaining);
        bounces = bounces || (cp.bounce > 0.0 && cp.active);
      }
      if (warm)
        warmStartPoint(cp);
    }
    prepareBlock(first);
    first += group;
  }
  return bounces;
}

// one active point's rows (prepareRows)
void Dynamics::prepareRow(ContactPoint& cp, double remaining) {
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
  // a frictionless resting point may close toward the slop, position_correction of the way
  // per tick (a speculative one down to touching): every such point of a body settles at the
  // same depth, so a box rests flat on its support instead of keeping whatever tilt its first
  // impact gave it, which without friction would make it slide for ever (the split impulses
  // push out what is deeper, at the same rate; Box2D v3's soft step closes to its linear
  // slop the same way). It closes no faster than the restitution threshold (slower would
  // be no impact): boxes placed touching otherwise fell into the slop freely and landed at
  // up to sqrt(2 g slop) (0.18 m/s for 1 m boxes), and a frictionless offset tower rocked on
  // landing and kept the sideways speeds its tilted normals gave it (levelSweep)
  if (cp.speculative) {
    cp.min_vn = -std::max(cp.gap, 0.0) / remaining;
  } else if (cp.bounce > 0.0 || !cp.resting || cp.mu_s > 0.0 || cp.mu_d > 0.0) {
    // an impact: its whole compression impulse, for the restitution; a sliding contact (a
    // gear's teeth) is no resting support; with friction a tilt within the slop is held by
    // static friction (and the closing made tall towers with friction creep)
    cp.min_vn = 0.0;
  } else {
    cp.min_vn =
        -std::min(options_.position_correction * std::max(cp.gap + slop(cp), 0.0) / tick_dt_,
                  restitutionThreshold(cp));
  }
}

// a primitive pair's normal rows as one block, when it has three points or more in the solve,
// one normal, a plane's worth of them (not in a line) and no force cap (the held body's). A
// flat contact's four normal rows span only three directions (the push at the centroid and the
// turns about the two tangents): with them solved together the points of a symmetric contact
// get equal impulses whatever the order, where the sequential impulses, until converged, give
// the first point more and turn the body (a frictionless stack of small boxes then slides
// apart: nothing takes the sideways speed that the turn gives back)
void Dynamics::prepareBlock(std::size_t first) {
  NormalBlock& blk = blocks_[first];
  blk.ok = false;
  blk.count = 0;
  const std::size_t group = std::max<std::size_t>(points_[first].group, 1);
  if (group < 3)
    return;
  for (std::size_t k = first; k < first + group; ++k) {
    const ContactPoint& cp = points_[k];
    if (!cp.active && !cp.speculative)
      continue;
    if (cp.ln_max > 0.0)
      return;
    blk.idx[blk.count++] = static_cast<std::uint32_t>(k);
  }
  if (blk.count < 3)
    return;
  const ContactPoint& c0 = points_[blk.idx[0]];
  const Vec3 n = c0.n;
  Vec3 ca{0.0}, cb{0.0};  // the centroid from each centre of mass
  for (std::size_t k = 0; k < blk.count; ++k) {
    const ContactPoint& cp = points_[blk.idx[k]];
    if (glm::dot(cp.n, n) < 1.0 - 1e-12)
      return;
    ca += cp.ra;
    cb += cp.rb;
  }
  ca /= static_cast<double>(blk.count);
  cb /= static_cast<double>(blk.count);
  Mat3 g{0.0};
  for (std::size_t k = 0; k < blk.count; ++k) {
    const ContactPoint& cp = points_[blk.idx[k]];
    const Vec3 p = 0.5 * ((cp.ra - ca) + (cp.rb - cb));
    blk.phi[k] = Vec3{1.0, glm::dot(p, c0.t1), glm::dot(p, c0.t2)};
    g += glm::outerProduct(blk.phi[k], blk.phi[k]);
  }
  // points in a line (or one): not a plane's worth
  const double dg = glm::determinant(g);
  if (!(dg > 1e-9 * g[0][0] * g[1][1] * g[2][2]))
    return;
  // the centroid's rows: (linear part on b, angular part on a, angular part on b); a gets the
  // opposite
  const BodyState& A = bodies_[c0.a];
  const BodyState& B = bodies_[c0.b];
  const std::array<Vec3, 3> aa{glm::cross(ca, n), glm::cross(c0.t1, n), glm::cross(c0.t2, n)};
  const std::array<Vec3, 3> ab{glm::cross(cb, n), aa[1], aa[2]};
  // the inverse inertias times the angular parts, once per column
  std::array<Vec3, 3> ia{}, ib{};
  for (std::size_t q = 0; q < 3; ++q) {
    ia[q] = A.inv_inertia_W * aa[q];
    ib[q] = B.inv_inertia_W * ab[q];
  }
  Mat3 kc{0.0};
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t q = 0; q < 3; ++q) {
      kc[static_cast<int>(q)][static_cast<int>(r)] = (r == 0 && q == 0 ? c0.ima + c0.imb : 0.0) +
                                                     glm::dot(aa[r], ia[q]) +
                                                     glm::dot(ab[r], ib[q]);
    }
  }
  const double dk = glm::determinant(kc);
  if (!(dk > 1e-9 * kc[0][0] * kc[1][1] * kc[2][2]))
    return;
  blk.kc_inv = glm::inverse(kc);
  blk.g_inv = glm::inverse(g);
  blk.z = {0.0, 0.0, 0.0, 0.0};
  if (blk.count == 4) {
    // Phi z = 0: the cofactors of the 3x4 matrix whose columns are the phis
    for (std::size_t j = 0; j < 4; ++j) {
      std::array<Vec3, 3> m{};
      std::size_t c = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        if (k != j)
          m[c++] = blk.phi[k];
      }
      blk.z[j] = (j % 2 == 0 ? 1.0 : -1.0) * glm::determinant(Mat3{m[0], m[1], m[2]});
    }
  }
  blk.ok = true;
}

// the block's normal rows solved together: the centroid's velocity error (the least-squares fit
// of the points' errors, exact for a flat contact) removed by the wrench Kc^-1 err, the block's
// total wrench then shared among its points as evenly as it can be (the least-norm share; with
// four points, moved along the share that is no wrench when that keeps every point pushing).
// False when some point would have to pull: the points are then solved one by one.
bool Dynamics::solveNormalBlock(const NormalBlock& blk, PairVelocity& v, double& residual) {
  std::array<double, 4> old{}, lnew{}, err{};
  for (std::size_t k = 0; k < blk.count; ++k) {
    const ContactPoint& cp = points_[blk.idx[k]];
    const double vn =
        glm::dot(cp.n, v.vb - v.va) + glm::dot(cp.rn.cb, v.wb) - glm::dot(cp.rn.ca, v.wa);
    err[k] = cp.min_vn - vn;
    old[k] = cp.ln;
  }
  if (!shareBlock(blk, err.data(), old.data(), lnew.data()))
    return false;
  for (std::size_t k = 0; k < blk.count; ++k) {
    ContactPoint& cp = points_[blk.idx[k]];
    if (cp.rn.mass > 0.0)
      residual = std::max(residual, std::abs(lnew[k] - old[k]) / cp.rn.mass);
    const double d = lnew[k] - old[k];
    cp.ln = lnew[k];
    v.va -= (cp.ima * d) * cp.n;
    v.wa -= cp.rn.ia * d;
    v.vb += (cp.imb * d) * cp.n;
    v.wb += cp.rn.ib * d;
  }
  return true;
}

// the block's new impulses from its points' velocity errors (target - v_n) and their impulses
// so far; false when some point would have to pull
bool Dynamics::shareBlock(const NormalBlock& blk,
                          const double* err,
                          const double* old,
                          double* lnew) {
  Vec3 fit{0.0}, w_old{0.0};
  for (std::size_t k = 0; k < blk.count; ++k) {
    fit += blk.phi[k] * err[k];
    w_old += blk.phi[k] * old[k];
  }
  const Vec3 w_new = w_old + blk.kc_inv * (blk.g_inv * fit);
  const Vec3 share = blk.g_inv * w_new;
  double lo = -kInf, hi = kInf;
  bool pulls = false;
  for (std::size_t k = 0; k < blk.count; ++k) {
    lnew[k] = glm::dot(blk.phi[k], share);
    pulls = pulls || lnew[k] < 0.0;
    // lnew + t z >= 0
    if (blk.z[k] > 0.0)
      lo = std::max(lo, -lnew[k] / blk.z[k]);
    else if (blk.z[k] < 0.0)
      hi = std::min(hi, -lnew[k] / blk.z[k]);
  }
  if (pulls) {
    if (blk.count != 4 || !(lo <= hi))
      return false;
    const double t = std::clamp(0.0, lo, hi);
    for (std::size_t k = 0; k < blk.count; ++k)
      lnew[k] = std::max(lnew[k] + t * blk.z[k], 0.0);
  }
  return true;
}

// last tick's joint impulses applied again (the first episode of a tick)
void Dynamics::applyJointWarmStart() {
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
  warmStartGeneralJoints();
}

// last tick's impulses of a contact point applied again (the first episode of a tick; its rows
// made)
void Dynamics::warmStartPoint(ContactPoint& cp) {
  if (!cp.active || cp.total_n <= 0.0) {
    cp.total_n = 0.0;
    cp.total_t = Vec3{0.0};
    return;
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

// one joint's rows in one iteration: angular (fixed: all three; hinge: across the axis, and its
// limits), then the point
void Dynamics::solveJoint(JointState& js, double inv_dt, double& residual) {
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

// one contact point's rows in one iteration: friction first, limited by this episode's normal
// impulse (Coulomb, isotropic), then the normal
void Dynamics::solveContact(ContactPoint& cp, double& residual) {
  BodyState& A = bodies_[cp.a];
  BodyState& B = bodies_[cp.b];
  PairVelocity v{A.v_W, A.w_W, B.v_W, B.w_W};
  solveFriction(cp, v, residual);
  solveNormal(cp, v, residual);
  A.v_W = v.va, A.w_W = v.wa;
  B.v_W = v.vb, B.w_W = v.wb;
}

// a flat contact's rows in one iteration: friction point by point, then the normals together
// (one by one when a point would have to pull); its two bodies' velocities (the same for every
// point of the pair) held in registers meanwhile, not stored and loaded again between the rows
void Dynamics::solveBlock(const NormalBlock& blk, double& residual) {
  const ContactPoint& c0 = points_[blk.idx[0]];
  BodyState& A = bodies_[c0.a];
  BodyState& B = bodies_[c0.b];
  PairVelocity v{A.v_W, A.w_W, B.v_W, B.w_W};
  for (std::size_t k = 0; k < blk.count; ++k)
    solveFriction(points_[blk.idx[k]], v, residual);
  if (!solveNormalBlock(blk, v, residual)) {
    for (std::size_t k = 0; k < blk.count; ++k)
      solveNormal(points_[blk.idx[k]], v, residual);
  }
  A.v_W = v.va, A.w_W = v.wa;
  B.v_W = v.vb, B.w_W = v.wb;
}

// a point's friction rows, limited by this episode's normal impulse (Coulomb, isotropic), on its
// two bodies' velocities v
void Dynamics::solveFriction(ContactPoint& cp, PairVelocity& v, double& residual) {
  if (!(cp.mu > 0.0))
    return;
  // relative velocity along a row, and an impulse along it (infinite bodies have zero
  // coefficients, so their velocities stay)
  const auto rel = [&](const Vec3& u, const Row& r) {
    return glm::dot(u, v.vb - v.va) + glm::dot(r.cb, v.wb) - glm::dot(r.ca, v.wa);
  };
  const auto push = [&](const Vec3& u, const Row& r, double l) {
    v.va -= (cp.ima * l) * u;
    v.wa -= r.ia * l;
    v.vb += (cp.imb * l) * u;
    v.wb += r.ib * l;
  };
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

// a point's normal row: closing no faster than its target, never pulling (on its two bodies'
// velocities v)
void Dynamics::solveNormal(ContactPoint& cp, PairVelocity& v, double& residual) {
  const double vn =
      glm::dot(cp.n, v.vb - v.va) + glm::dot(cp.rn.cb, v.wb) - glm::dot(cp.rn.ca, v.wa);
  const double target = cp.min_vn;
  const double old = cp.ln;
  cp.ln = std::max(0.0, old + cp.rn.mass * (target - vn));
  if (cp.ln_max > 0.0)
    cp.ln = std::min(cp.ln, cp.ln_max);
  const double d = cp.ln - old;
  v.va -= (cp.ima * d) * cp.n;
  v.wa -= cp.rn.ia * d;
  v.vb += (cp.imb * d) * cp.n;
  v.wb += cp.rn.ib * d;
  if (cp.rn.mass > 0.0)
    residual = std::max(residual, std::abs(cp.ln - old) / cp.rn.mass);
}

// restitution (Poisson's hypothesis): the points that struck get e times their compression
// impulse back. With the compression solved, this changes the kinetic energy by
// -(1 - e^2) / 2 lambda^T A lambda <= 0 however many points struck at once (Newton's rule,
// a target velocity of -e v_n per point, can add energy when several points of a spinning
// body strike together)
// The solve is iterative: when it has not converged, the restitution impulses are scaled
// down (never up) so that the kinetic energy does not end above where the episode began.
void Dynamics::applyRestitution() {
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
    // a point beyond the slop, or one that a frictionless flat contact may have to level
    // (correctBlock)
    any = any || cp.gap < -slop(cp) || levels(cp);
  }
  const bool joints = measureJointErrors();
  const bool general = measureGeneralErrors();
  any = any || joints || general;
  if (!any)
    return;
  // the flat contacts' blocks at the end of the tick's motion
  for (std::size_t i = 0; i < points_.size(); i += std::max<std::size_t>(points_[i].group, 1))
    prepareBlock(i);
  // settling iterations (DynamicsOptions::position_iterations_max): beyond the fixed count while
  // a levelling still changes less and less, within the tick's row budget
  const std::uint32_t cap =
      std::max(options_.position_iterations, options_.position_iterations_max);
  // with unequal masses in contact every iteration up to the cap is run: the split impulses
  // pass a heavy body's push-out through a light one a fraction of it per iteration (as the
  // velocity solve's impulses), and ten cubes alternating 1:100 took seconds to rise out of
  // the depth their landing pressed them to (0.002 of the edge a minute after 2 s at 5 mm)
  const std::uint32_t fixed = mass_ratio_ > 1.0 ? cap : options_.position_iterations;
  const auto rows = static_cast<std::uint32_t>(points_.size() + joints_.size() + general_.size());
  double last = kInf;
  level_residual_ = 0.0;
  for (std::uint32_t it = 0; it < cap; ++it) {
    if (it >= fixed) {
      // the levelling converged (or none left), or it stopped falling
      if (!(level_residual_ > 0.0 && level_residual_ < last) ||
          settle_rows_ + rows > options_.settle_row_budget)
        break;
      settle_rows_ += rows;
    }
    if (it > 0)
      last = level_residual_;
    level_residual_ = 0.0;
    for (JointState& js : joints_) {
      if (js.off)
        continue;
      correctJoint(js, beta, inv_dt);
    }
    for (GeneralJoint& gj : general_) {
      if (!gj.off)
        correctGeneralJoint(gj, beta, inv_dt);
    }
    for (std::size_t i = 0; i < points_.size();) {
      const std::size_t group = std::max<std::size_t>(points_[i].group, 1);
      // a flat contact's points together (as in the velocity solve: the split impulses of a
      // symmetric contact are then equal, and do not tilt the body), the others one by one
      const NormalBlock& blk = blocks_[i];
      const bool block = blk.ok && correctBlock(blk, beta, inv_dt);
      for (std::size_t k = i; k < i + group; ++k) {
        const bool in_block = block && std::find(blk.idx.begin(), blk.idx.begin() + blk.count, k) !=
                                           blk.idx.begin() + blk.count;
        if (!in_block)
          correctContact(points_[k], beta, inv_dt);
      }
      i += group;
    }
  }
  levelSweep(dt);
  for (BodyState& b : bodies_) {
    if (b.infinite)
      continue;
    b.x_W += b.pv * dt;
    b.q = glm::normalize(geom::quatFromRotationVector(b.pw * dt) * b.q);
    b.updateInertia();
  }
}

// joint errors at the end of the tick (b's anchor from a's; the rotation error; a hinge's
// distance to its limits); true when a joint is in the scene
bool Dynamics::measureJointErrors() {
  bool any = false;
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
  return any;
}

// one joint's pseudo-velocity rows: angular error driven to -beta * error / dt (a hinge: across
// its axis, and its limits), then the point error
void Dynamics::correctJoint(JointState& js, double beta, double inv_dt) {
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

// a point of a frictionless contact that penetrates and did not strike (resting, or sliding when
// it became active): its flat contact is levelled by the split impulses (correctBlock) and the
// levelling sweep. A sliding one too: the top box of a frictionless tower that the held probe
// pushed faster than the static-friction threshold (0.25 m/s at 1 m) was never levelled again,
// and its tilt pushed the box below sideways (3.5e-3 of the edge in 1.2 s)
bool Dynamics::levels(const ContactPoint& cp) {
  return cp.active && !cp.speculative && (cp.resting || cp.bounce == 0.0) && cp.mu_s == 0.0 &&
         cp.mu_d == 0.0 && cp.gap < 0.0;
}

// a flat contact's split impulses together: each point's penetration beyond the slop removed at
// beta per tick (a point within the slop: held where it is); false when a point would have to
// pull (then they are corrected one by one).
// A resting frictionless flat contact is also levelled: every point deeper than the shallowest
// is pushed out to its depth within the tick, so that no tilt of the body on its support is
// left for the next tick. Without friction a tilt of the support's face pushes the body on it
// sideways; the velocity solve, warm-started and stopped after a few iterations, lags behind
// the load's pressure centre when the bodies above slide (its share of the load follows them
// late), so it leaves each tick a turn towards the way they slide, and corrected at beta per
// tick that turn stood as a tilt proportional to the sliding speed: a force along the sliding,
// which grew a shear of a frictionless tower from rounding (e-folding 1.6 s for ten 2 cm boxes).
bool Dynamics::correctBlock(const NormalBlock& blk, double beta, double inv_dt) {
  std::array<double, 4> old{}, lnew{}, err{};
  bool any = false;
  bool level = true;
  double shallowest = kInf;
  for (std::size_t k = 0; k < blk.count; ++k) {
    const ContactPoint& cp = points_[blk.idx[k]];
    level = level && levels(cp);
    shallowest = std::min(shallowest, -cp.gap);
  }
  for (std::size_t k = 0; k < blk.count; ++k) {
    const ContactPoint& cp = points_[blk.idx[k]];
    const double excess = -cp.gap - slop(cp);
    // the pseudo-velocity along n that the point is to reach
    double target = beta * inv_dt * std::max(excess, 0.0);
    if (level)
      target = std::max(target, (-cp.gap - shallowest) * inv_dt);
    any = any || target > 0.0 || cp.lp != 0.0;
    const double vn = glm::dot(bodies_[cp.b].pseudoAt(cp.rb) - bodies_[cp.a].pseudoAt(cp.ra), cp.n);
    err[k] = target - vn;
    old[k] = cp.lp;
  }
  if (!any)
    return true;
  if (!shareBlock(blk, err.data(), old.data(), lnew.data()))
    return false;
  for (std::size_t k = 0; k < blk.count; ++k) {
    ContactPoint& cp = points_[blk.idx[k]];
    if (level && cp.rn.mass > 0.0)
      level_residual_ = std::max(level_residual_, std::abs(lnew[k] - cp.lp) / cp.rn.mass);
    const Vec3 J = cp.n * (lnew[k] - cp.lp);
    cp.lp = lnew[k];
    bodies_[cp.a].applyPseudo(-J, cp.ra);
    bodies_[cp.b].applyPseudo(J, cp.rb);
  }
  return true;
}

namespace {
// the directions of levelSweep's support extents: kLevelDirs evenly around the circle
constexpr std::array<double, 16> kLevelCos = {
    1.0,  0.92387953251128674,  0.70710678118654757,  0.38268343236508984,
    0.0,  -0.38268343236508984, -0.70710678118654757, -0.92387953251128674,
    -1.0, -0.92387953251128674, -0.70710678118654757, -0.38268343236508984,
    0.0,  0.38268343236508984,  0.70710678118654757,  0.92387953251128674};
constexpr std::array<double, 16> kLevelSin = {
    0.0,  0.38268343236508984,  0.70710678118654757,  0.92387953251128674,
    1.0,  0.92387953251128674,  0.70710678118654757,  0.38268343236508984,
    0.0,  -0.38268343236508984, -0.70710678118654757, -0.92387953251128674,
    -1.0, -0.92387953251128674, -0.70710678118654757, -0.38268343236508984};
// a normal within 45 degrees of gravity g (g not zero): a contact that can support along it
bool alongGravity(const Vec3& n, const Vec3& g) {
  const double gn = glm::dot(n, g);
  return gn * gn >= 0.5 * glm::dot(g, g);
}
// levelSweep's per-body flags (level_pinned_)
constexpr std::uint8_t kLevelPinned = 1;   // a contact that is no flat block: not turned
constexpr std::uint8_t kLevelReached = 2;  // level_reach_ holds this tick's supports
constexpr std::uint8_t kLevelLoaded = 4;   // level_load_ holds this tick's load from above
}  // namespace

// a push across gravity by a body of infinite mass (held, kinematic or static; its normal within
// 45 degrees of horizontal): it supports nothing, so levelling the pushed body's supporting
// contact (a turn about its centre of mass) moves it into that contact by no more than the turn
// times its lever (issue 17 F1: the held probe pushing the top box of a frictionless tower
// sideways pinned it, its tilt within the slop stood, and its tilted face, the contact's normal,
// pushed the box below)
bool Dynamics::sidewaysPush(const ContactPoint& cp) const {
  const BodyState& A = bodies_[cp.a];
  const BodyState& B = bodies_[cp.b];
  if (A.infinite == B.infinite)
    return false;
  const Vec3 g = A.infinite ? B.gravity_W : A.gravity_W;
  return glm::dot(g, g) > 0.0 && !alongGravity(cp.n, g);
}

const Vec3& Dynamics::contactGravity(const BodyState& A, const BodyState& B) {
  return glm::dot(B.gravity_W, B.gravity_W) > 0.0 ? B.gravity_W : A.gravity_W;
}

// the centre (world) of the load body u bears this tick: its own weight over the tick at its
// centre of mass, and what the bodies above passed to it (level_load_, passLoadsDown)
Vec3 Dynamics::loadCentre(std::uint32_t u, double dt) const {
  const BodyState& U = bodies_[u];
  if (U.infinite)
    return U.x_W;
  const double own = glm::length(U.gravity_W) / U.inv_mass * dt;
  Vec3 moment = own * U.x_W;
  double impulse = own;
  if ((level_pinned_[u] & kLevelLoaded) != 0) {
    moment += level_load_[u].moment;
    impulse += level_load_[u].impulse;
  }
  return impulse > 0.0 ? moment / impulse : U.x_W;
}

// levelSweep's loads, passed down from the top: every contact point along gravity that pressed
// this tick, taken from the highest down, gives the body below it its normal impulse at the
// centre of the load of the body above (loadCentre): the whole weight of what stands on a body,
// where it stands, in the share the solve gave each support. (The points where the bodies above
// pressed would do for a converged solve; but a contact pressed at some points only is what the
// sweep is asked about, and the points it was pressed at moved the load to its edge: a
// frictionless staircase of ten 1 km boxes, 8% steps, lost its levelling and drifted 2e-3 of the
// edge.) Never allocates (as many as points).
void Dynamics::passLoadsDown(double dt) {
  level_points_.clear();
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const ContactPoint& cp = points_[i];
    if (!(cp.total_n > 0.0))
      continue;
    const BodyState& A = bodies_[cp.a];
    const BodyState& B = bodies_[cp.b];
    const Vec3& g = contactGravity(A, B);
    if (!(glm::dot(g, g) > 0.0) || !alongGravity(cp.n, g))
      continue;
    if (level_points_.size() == level_points_.capacity())
      break;
    // the point's height, negated: the highest first
    level_points_.emplace_back(glm::dot(A.x_W + cp.ra, g), static_cast<std::uint32_t>(i));
  }
  std::sort(level_points_.begin(), level_points_.end());
  for (const auto& [h, i] : level_points_) {
    const ContactPoint& cp = points_[i];
    const Vec3& g = contactGravity(bodies_[cp.a], bodies_[cp.b]);
    const bool b_above = glm::dot(cp.n, g) < 0.0;  // n points from a to b
    const std::uint32_t lower = b_above ? cp.a : cp.b, upper = b_above ? cp.b : cp.a;
    if (bodies_[lower].infinite)
      continue;
    // a body of infinite mass above (held, kinematic) presses where it touches
    const Vec3 at = bodies_[upper].infinite ? bodies_[lower].x_W + (b_above ? cp.ra : cp.rb)
                                            : loadCentre(upper, dt);
    LevelLoad& load = level_load_[lower];
    if ((level_pinned_[lower] & kLevelLoaded) == 0) {
      load = LevelLoad{};
      level_pinned_[lower] |= kLevelLoaded;
    }
    load.moment += cp.total_n * at;
    load.impulse += cp.total_n;
  }
}

// Levelling by shock propagation: every resting frictionless flat contact that the velocity
// solve pressed at all its points (the load inside its support: nothing tips), taken from the
// bottom up (along gravity), has its upper body turned, as if the one below were immovable,
// so that the contact ends the tick level (no slope of the depths across it) whatever the
// iterations above left. One sweep levels a whole stack, where the split impulses' iterations
// pass a correction one body up per iteration (and stop at their cap): an offset load sank the
// loaded side of each contact of a frictionless staircase into the slop, the tilted normals of
// the next tick pushed the boxes sideways, and without friction nothing takes that back (ten
// boxes with 8% steps drifted 0.019 of the edge in a minute at 1 m and were thrown apart at
// 5 mm). A body that has a contact other than flat blocks is not turned. Only the poses move (a
// pseudo angular velocity of the upper body): no energy enters the velocities. The turn is about
// the upper body's centre of mass, so the contact's mean depth changes by the turn times the
// centroid's offset from it, left to the slop rule.
// A contact the solve pressed at some of its points only is levelled too when the centre of its
// upper body's load lies over its supports (inside, by 1% of its size, the polygon of kLevelDirs
// sides drawn around the points of all its resting frictionless supports along gravity; the load:
// its own weight at its centre of mass and what the bodies above passed to it this tick,
// passLoadsDown: with its own centre of mass alone, a frictionless staircase whose top two boxes
// together overhung the bottom one's edge was held level at 2 cm and 1 m): a box
// bridging two others carries its load through them in a share that the sequential impulses
// leave undetermined, and they pressed the dropped frictionless pyramid's boxes at the near
// edges of one support alone; left unlevelled, such a box tilted within the slop for some 40
// ticks, its own face became the contact's normal (the depth query's tie) and the load through
// it pushed the boxes apart (0.018 of the edge in a minute at 5 mm). A box whose centre of mass
// is beyond its supports' edge is pressed at that edge and tips (not levelled).
void Dynamics::levelSweep(double dt) {
  level_order_.clear();
  std::fill(level_pinned_.begin(), level_pinned_.end(), std::uint8_t{0});
  bool partial = false;  // a contact to level pressed at some of its points only
  for (std::size_t i = 0; i < points_.size(); i += std::max<std::size_t>(points_[i].group, 1)) {
    const std::size_t group = std::max<std::size_t>(points_[i].group, 1);
    const NormalBlock& blk = blocks_[i];
    // a resting frictionless flat contact that pushed somewhere
    bool rests = blk.ok;
    double pushed = 0.0;
    for (std::size_t k = 0; k < blk.count && rests; ++k) {
      const ContactPoint& cp = points_[blk.idx[k]];
      rests = levels(cp);
      pushed += cp.total_n;
    }
    if (!blk.ok) {
      // a body with a contact that is no flat block (a curved one, a point or an edge, the
      // held body's) is not turned by the sweep: the turn could push it into that contact (a
      // block the held sweeper of the stress demo pressed onto a pillar was turned into it,
      // and the sweeper 0.37 mm into the pillar); but a push across gravity by a body of
      // infinite mass (held, kinematic, static) pins nothing (sidewaysPush)
      for (std::size_t k = i; k < i + group; ++k) {
        const ContactPoint& cp = points_[k];
        if (!cp.active && !cp.speculative)
          continue;
        if (sidewaysPush(cp))
          continue;
        level_pinned_[cp.a] |= kLevelPinned, level_pinned_[cp.b] |= kLevelPinned;
      }
      continue;
    }
    if (!rests)
      continue;
    const ContactPoint& c0 = points_[blk.idx[0]];
    const BodyState& A = bodies_[c0.a];
    const BodyState& B = bodies_[c0.b];
    const Vec3& g = contactGravity(A, B);
    if (!(glm::dot(g, g) > 0.0))
      continue;  // no up: nothing to propagate from
    // the upper body's reach over its supports across gravity (only along it: a side contact
    // supports nothing)
    const bool b_up = A.infinite || (!B.infinite && glm::dot(c0.n, g) < 0.0);
    if (!(b_up ? B : A).infinite && alongGravity(c0.n, g)) {
      Vec3 u1, u2;
      tangents(glm::normalize(g), &u1, &u2);
      const std::uint32_t u = b_up ? c0.b : c0.a;
      auto& reach = level_reach_[u];
      if ((level_pinned_[u] & kLevelReached) == 0) {
        reach.fill(-kInf);
        level_pinned_[u] |= kLevelReached;
      }
      for (std::size_t k = 0; k < blk.count; ++k) {
        const ContactPoint& cp = points_[blk.idx[k]];
        const Vec3 r = b_up ? cp.rb : cp.ra;
        const double x = glm::dot(r, u1), y = glm::dot(r, u2);
        for (std::size_t d = 0; d < kLevelDirs; ++d)
          reach[d] = std::max(reach[d], kLevelCos[d] * x + kLevelSin[d] * y);
      }
    }
    if (!(pushed > 0.0))
      continue;
    for (std::size_t k = 0; k < blk.count; ++k)
      partial = partial || !(points_[blk.idx[k]].total_n > 0.0);
    // the height of the contact's first point against gravity
    const double h = -glm::dot(A.x_W + c0.ra, g);
    if (level_order_.size() == level_order_.capacity())
      break;  // never allocates (as many as blocks)
    level_order_.emplace_back(h, static_cast<std::uint32_t>(i));
  }
  if (level_order_.empty())
    return;
  std::sort(level_order_.begin(), level_order_.end());
  if (partial)
    passLoadsDown(dt);
  const double inv_dt = 1.0 / dt;
  for (const auto& [h, i] : level_order_) {
    const NormalBlock& blk = blocks_[i];
    const ContactPoint& c0 = points_[blk.idx[0]];
    BodyState& A = bodies_[c0.a];
    BodyState& B = bodies_[c0.b];
    // the upper body: the one gravity pulls onto the other (n points from a to b), or the
    // only one that can move
    const Vec3& g = contactGravity(A, B);
    const bool b_up = A.infinite || (!B.infinite && glm::dot(c0.n, g) < 0.0);
    BodyState& U = b_up ? B : A;
    if (U.infinite || (level_pinned_[b_up ? c0.b : c0.a] & kLevelPinned) != 0)
      continue;
    // pressed at every point (the load inside this support), or the centre of the upper body's
    // load over its supports (levelSweep's comment)
    bool pressed = true;
    for (std::size_t k = 0; k < blk.count && pressed; ++k)
      pressed = points_[blk.idx[k]].total_n > 0.0;
    if (!pressed) {
      const std::uint32_t u = b_up ? c0.b : c0.a;
      if ((level_pinned_[u] & kLevelReached) == 0)
        continue;
      const Vec3 q = loadCentre(u, dt) - U.x_W;
      Vec3 u1, u2;
      tangents(glm::normalize(g), &u1, &u2);
      const double qx = glm::dot(q, u1), qy = glm::dot(q, u2);
      const auto& reach = level_reach_[u];
      double inside = kInf;
      for (std::size_t d = 0; d < kLevelDirs; ++d)
        inside = std::min(inside, reach[d] - (kLevelCos[d] * qx + kLevelSin[d] * qy));
      if (!(inside > 0.01 * U.size))
        continue;
    }
    // the slopes, along t1 and t2, of the relative normal pseudo-velocity that would leave
    // every point at the same depth
    Vec3 fit{0.0};
    for (std::size_t k = 0; k < blk.count; ++k) {
      const ContactPoint& cp = points_[blk.idx[k]];
      const double vn = glm::dot(B.pseudoAt(cp.rb) - A.pseudoAt(cp.ra), c0.n);
      fit += blk.phi[k] * (-cp.gap * inv_dt - vn);
    }
    const Vec3 e = blk.g_inv * fit;
    // a relative turn w changes a point's normal velocity by w . (p x n) with p = u t1 + v t2
    const Vec3 s1 = glm::cross(c0.t1, c0.n), s2 = glm::cross(c0.t2, c0.n);
    const Vec3 dw = e.y * s1 + e.z * s2;
    U.pw += b_up ? dw : -dw;
    // and the real velocities agree: a contact pressed at every point has no relative turn
    // about its tangents (the solve's fixed point), whatever the iterations left; removed by
    // a couple between the two bodies (no linear momentum changes, the kinetic energy can
    // only fall: a plastic impulse, as the solve's own rows). Else a turn the solve
    // left, undone in the poses each tick, rocked the top of a 5 mm staircase at 4e-3 rad/s.
    const Mat3 ia = A.infinite ? Mat3{0.0} : A.inv_inertia_W;
    const Mat3 ib = B.infinite ? Mat3{0.0} : B.inv_inertia_W;
    const Mat3 k = ia + ib;
    const double k11 = glm::dot(s1, k * s1), k12 = glm::dot(s1, k * s2), k22 = glm::dot(s2, k * s2);
    const double det = k11 * k22 - k12 * k12;
    if (!(det > 0.0))
      continue;
    const Vec3 wrel = B.w_W - A.w_W;
    const double r1 = -glm::dot(wrel, s1), r2 = -glm::dot(wrel, s2);
    const Vec3 L = ((k22 * r1 - k12 * r2) / det) * s1 + ((k11 * r2 - k12 * r1) / det) * s2;
    A.w_W -= ia * L;
    B.w_W += ib * L;
  }
}

// one contact point's split impulse: its penetration beyond the slop removed at beta per tick
void Dynamics::correctContact(ContactPoint& cp, double beta, double inv_dt) {
  const double excess = -cp.gap - slop(cp);
  if (excess <= 0.0 && cp.lp == 0.0)
    return;
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

}  // namespace hapticd::dynamics
