// One tick of the dynamics (§6.1 of Gregory et al. 2000): forces, contacts gathered from the
// collision world with their warm starts, the solves through the times of impact, drift
// correction, the held body's feedback, poses back to the world, sleep.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>

#include "core/dynamics/dynamics_internal.h"
#include "core/dynamics/scene_world.h"
#include "core/geometry/rotation.h"

namespace hapticd::dynamics {

using collision::Manifold;
using detail::kInf;
using detail::pairKey;
using detail::tangents;

namespace {

constexpr std::size_t kNoSlot = ~std::size_t{0};

// one primitive pair's point this tick: fresh from the collision manifold or kept from last tick
// (no default values: a contact's array of them is not zeroed on every tick, each candidate
// is written whole when it is made)
struct Candidate {
  Vec3 n;
  double gap;
  Vec3 sa_B, sb_B;  // on each surface, body frames (from the centres of mass)
  bool warm;        // last tick's impulses found
  // its place in the solve order: last tick's nearest point of the pair (kNoSlot: none), then
  // its distance from it and its place on a's surface, in grains of 1e-9 of the size
  std::size_t slot;
  std::array<double, 4> order;
  // its warm start: last tick's point whose impulses it takes (kNoSlot: none) and them
  std::size_t source;
  double ln;
  Vec3 lt;
};

// the Simulation's own probe sphere (extra_probe_body): frictionless, inelastic (built before
// main, never on the servo thread)
const scene::Material kProbeSphereMaterial = [] {
  scene::Material m;
  m.name = "probe sphere";
  return m;
}();

// a kept point's normal (in either body) within about 0.25 degrees of this tick's
constexpr double kSameNormalCos = 0.99999;

// std::round of a value within +-1e15 (|v| < 2^53; NaN passed to std::round), inline: libm's
// round, called three or four times per point, was 4% of a resting stack's step. The same
// result bit for bit: the truncation and the fraction v - t are exact in this range, t +- 1 too,
// and the sign is v's (as std::round's, -0.0 for -0.3)
double roundClamped(double v) {
  if (!(std::abs(v) <= 1e15))
    return std::round(v);
  const double t = static_cast<double>(static_cast<std::int64_t>(v));
  const double f = v - t;
  return std::copysign(f >= 0.5 ? t + 1.0 : f <= -0.5 ? t - 1.0 : t, v);
}

// a manifold's points plus as many kept ones
constexpr std::size_t kMaxCandidates = 2 * Manifold::kMaxPoints;

// the four of `n` candidates that support best (the collision manifold's rule, manifold.cpp:
// the deepest, the farthest from it, the largest triangle, the point farthest outside it),
// moved to the front; returns 4
std::size_t reduceCandidates(Candidate* c, std::size_t n, const auto& A, double size) {
  const auto at = [&](std::size_t i) { return A.R * c[i].sa_B; };
  // ties (equally deep points of a body resting flat, equally far corners of a symmetric
  // contact) are rounding's: within them a point that continues one of last tick's wins, so
  // that the kept four do not swap for a new, cold one from one tick to the next
  const auto continues = [&](std::size_t i) { return c[i].slot != kNoSlot; };
  const auto better = [&](double v, double best, std::size_t i, std::size_t b, double tol) {
    return v > best + tol || (v >= best - tol && continues(i) && !continues(b));
  };
  const double tl = 1e-9 * size, ta = 1e-9 * size * size;
  std::array<std::size_t, 4> pick{};
  for (std::size_t i = 1; i < n; ++i) {
    if (better(-c[i].gap, -c[pick[0]].gap, i, pick[0], tl))
      pick[0] = i;
  }
  double best = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 d = at(i) - at(pick[0]);
    if (best < 0.0 || better(glm::dot(d, d), best, i, pick[1], ta))
      best = glm::dot(d, d), pick[1] = i;
  }
  const Vec3 nrm = c[pick[0]].n;
  best = -1.0;
  double sign = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double area = glm::dot(glm::cross(at(pick[1]) - at(pick[0]), at(i) - at(pick[0])), nrm);
    if (best < 0.0 || better(std::abs(area), best, i, pick[2], ta))
      best = std::abs(area), pick[2] = i, sign = area >= 0.0 ? 1.0 : -1.0;
  }
  best = -1.0;
  pick[3] = pick[0];
  for (std::size_t i = 0; i < n; ++i) {
    if (i == pick[0] || i == pick[1] || i == pick[2])
      continue;
    double out = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3 p0 = at(pick[k]), p1 = at(pick[(k + 1) % 3]);
      out = std::max(out, -sign * glm::dot(glm::cross(p1 - p0, at(i) - p0), nrm));
    }
    if (best < 0.0 || better(out, best, i, pick[3], ta))
      best = out, pick[3] = i;
  }
  std::array<Candidate, 4> kept;
  std::size_t m = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    bool dup = false;
    for (std::size_t j = 0; j < k; ++j)
      dup = dup || pick[j] == pick[k];
    if (!dup)
      kept[m++] = c[pick[k]];
  }
  std::copy(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(m), c);
  return m;
}

// a point of last tick whose impulses several of this tick's take (fresh points near it, or
// it kept and a fresh one near it) shares them among those equally: the warm start carries
// last tick's impulses over, never more. Taken whole by each, a point's impulse was
// multiplied; where the solve balanced the excess with the contact's other side (a body's
// pieces pushed up and down through a thin floor) the impulses of the two sides grew together
// from tick to tick (to 1e8 times the body's weight per tick) until a point left and their
// unbalance threw the body off at a kilometre a second
void shareWarmStarts(Candidate* c, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) {
    if (c[k].source == kNoSlot)
      continue;
    std::size_t takers = 0;
    for (std::size_t j = 0; j < n; ++j)
      takers += c[j].source == c[k].source ? 1u : 0u;
    if (takers > 1) {
      const double share = 1.0 / static_cast<double>(takers);
      c[k].ln *= share;
      c[k].lt *= share;
    }
  }
}

}  // namespace

// velocities first (semi-implicit Euler); the kinematic bodies' velocities that reach their
// targets; the speed clamp that keeps every body within its box margin in the world per tick
void Dynamics::integrateForces(double dt,
                               const collision::CollisionWorld& world,
                               const HeldInput* held) {
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
    b.infinite =
        b.motion != scene::Motion::kDynamic || held_here || b.driven || !b.enabled || b.asleep;
    b.pv = Vec3{0.0};
    b.pw = Vec3{0.0};
    if (!b.enabled || (b.asleep && !b.driven && !held_here)) {
      // out of the scene, or asleep: frozen where it is (no gravity, no velocity)
      b.inv_inertia_W = Mat3{0.0};
      b.inertia_made = false;
      b.v_W = b.w_W = Vec3{0.0};
      b.has_target = false;
      continue;
    }
    if (b.infinite) {
      b.inv_inertia_W = Mat3{0.0};
      b.inertia_made = false;
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
    b.updateInertiaIfTurned();
    b.w_W += dt * (b.inv_inertia_W * torque);
    if (!geom::finite(b.v_W) || !geom::finite(b.w_W)) {
      b.v_W = Vec3{0.0};
      b.w_W = Vec3{0.0};
    }
    {
      // no tunnelling: a body never travels more than this per tick
      const double limit = std::max(world.margin(static_cast<std::uint32_t>(i)),
                                    options_.max_travel_fraction * b.size);
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

// a contact the solve takes points of: answered, between bodies of which one at least has a
// finite mass, both in the scene and not kept apart by a joint
bool Dynamics::takes(const collision::Contact& c) const {
  if (!c.answered || c.body_a >= bodies_.size() || c.body_b >= bodies_.size())
    return false;
  const BodyState& A = bodies_[c.body_a];
  const BodyState& B = bodies_[c.body_b];
  if ((A.infinite && B.infinite) || !A.enabled || !B.enabled)
    return false;
  return no_collide_.empty() ||
         !std::binary_search(no_collide_.begin(), no_collide_.end(), pairKey(c.body_a, c.body_b));
}

// last tick's points of a contact's primitive pair: [first, second) of warm_. The contacts and
// warm_ are both sorted by pair, so a pair's usually begin where the last contact's ended
// (`cursor`; checked, else a search); `cursor` is left at the end of these
std::pair<std::size_t, std::size_t> Dynamics::warmRange(const collision::Contact& c,
                                                        std::size_t& cursor) const {
  const auto warmLess = [](const WarmPoint& x, const WarmPoint& y) { return x.key() < y.key(); };
  const WarmPoint probe{c.body_a, c.body_b, c.prim_a, c.prim_b};
  std::size_t end = cursor;
  const bool at_cursor = (end == 0 || warmLess(warm_[end - 1], probe)) &&
                         (end == warm_.size() || !warmLess(warm_[end], probe));
  if (!at_cursor) {
    end = static_cast<std::size_t>(std::lower_bound(warm_.begin(), warm_.end(), probe, warmLess) -
                                   warm_.begin());
  }
  const std::size_t begin = end;
  while (end < warm_.size() && warm_[end].key() == probe.key())
    ++end;
  cursor = end;
  return {begin, end};
}

// the largest gap of the contacts whose points fit in max_points_, nearest (deepest) first;
// kInf when every contact's fit. A contact has at most its manifold's points and last tick's
// points of its pair, and at most Manifold::kMaxPoints. Small bodies in a large scene are within
// the world's box margin (relative to the scene's size) of many others: two parts of 64 pieces
// each, 5 mm long on a 40 m floor, offered 4 096 piece pairs, and the floor's contacts, listed
// last, were the ones dropped: the parts fell through it
double Dynamics::gapThatFits(std::span<const collision::Contact> contacts) {
  if (contacts.size() * Manifold::kMaxPoints <= max_points_)
    return kInf;
  std::size_t offered = 0, n = 0, cursor = 0;
  for (const collision::Contact& c : contacts) {
    if (!takes(c))
      continue;
    const auto [first, last] = warmRange(c, cursor);
    const std::size_t warm = last - first;
    const std::size_t most = std::min<std::size_t>(
        std::max<std::size_t>(c.manifold.count, 1) + warm, Manifold::kMaxPoints);
    offered += most;
    // (a distance that is no number last: the order must be strict)
    if (n < gap_points_.size())
      gap_points_[n] = {std::isfinite(c.distance) ? c.distance : kInf, most};
    ++n;
  }
  // (a world grown past what it reserved at creation: the contacts in their order)
  if (offered <= max_points_ || n > gap_points_.size())
    return kInf;
  std::sort(gap_points_.begin(), gap_points_.begin() + static_cast<std::ptrdiff_t>(n));
  // (at least the nearest: a capacity below one contact's points keeps what it can of it)
  double below = gap_points_[0].first;
  std::size_t total = 0;
  for (std::size_t k = 0; k < n; ++k) {
    total += gap_points_[k].second;
    if (total > max_points_)
      break;
    below = gap_points_[k].first;
  }
  return below;
}

void Dynamics::gatherContacts(std::span<const collision::Contact> contacts, StepReport& report) {
  points_.clear();
  warm_next_.clear();
  const std::size_t cap = max_points_;
  const double take_below = gapThatFits(contacts);
  std::size_t warm_cursor = 0;  // where the last contact's warm points ended (warmRange)
  for (const collision::Contact& c : contacts) {
    if (!takes(c))
      continue;
    if (c.distance > take_below) {
      counters_.points_dropped += std::max<std::size_t>(c.manifold.count, 1);
      step_flags_ |= kStepCapacityFull;
      continue;
    }
    BodyState& A = bodies_[c.body_a];
    BodyState& B = bodies_[c.body_b];
    if (c.age > 0)
      step_flags_ |= kStepStaleContacts;
    // materials of the two primitives (none declared: scene::defaultMaterial()); a body after
    // the scene's, the probe sphere the Simulation adds from its config, is no collider of the
    // scene and pushes without friction (what the hand feels of friction is the response's)
    // (from create()'s table of scene::materialOf of each primitive)
    const auto material = [&](std::uint32_t body, std::uint32_t prim) -> const scene::Material& {
      if (body + 1 >= prim_first_.size())
        return kProbeSphereMaterial;
      const std::uint32_t first = prim_first_[body];
      return prim < prim_first_[body + 1] - first ? *prim_material_[first + prim]
                                                  : *default_material_;
    };
    const scene::Material& ma = material(c.body_a, c.prim_a);
    const scene::Material& mb = material(c.body_b, c.prim_b);
    // KHR_physics_rigid_bodies' combine rule, the one implementation the plan uses too
    const double e = scene::combineMaterials(ma, mb, scene::MaterialValue::kRestitution);
    const double mu_s = scene::combineMaterials(ma, mb, scene::MaterialValue::kStaticFriction);
    const double mu_d = scene::combineMaterials(ma, mb, scene::MaterialValue::kDynamicFriction);
    const double size = std::min(A.infinite ? kInf : A.size, B.infinite ? kInf : B.size);

    // last tick's points of this primitive pair
    const auto [warm_begin, warm_end] = warmRange(c, warm_cursor);

    // this tick's candidates: the manifold's points, then last tick's that are still in contact
    // and were not found again (persistent points: a resting box keeps its four corners even on
    // a tick whose manifold names one)
    std::array<Candidate, kMaxCandidates> cand;
    std::size_t nc = 0;
    const std::size_t count = c.manifold.count;
    Vec3 n_pair{0.0};
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
      if (!(nl > 0.5) || !geom::finite(p) || !std::isfinite(gap) || nc == Manifold::kMaxPoints)
        continue;
      n /= nl;
      n_pair = n;
      Candidate& cd = cand[nc++];
      cd.n = n;
      cd.gap = gap;
      cd.sa_B = glm::transpose(A.R) * (p - n * (0.5 * gap) - A.x_W);
      cd.sb_B = glm::transpose(B.R) * (p + n * (0.5 * gap) - B.x_W);
      cd.warm = false;
      cd.slot = kNoSlot;
      cd.order = {};
      cd.source = kNoSlot;
      cd.ln = 0.0;
      cd.lt = Vec3{0.0};
    }
    if (nc == 0)
      continue;
    const double keep = options_.contact_persist_fraction * size;
    const std::size_t fresh = nc;
    // warm start: each fresh point takes the impulses of last tick's nearest point of the pair
    // that pushed, within 0.05 of the size (a sliding contact's points move a little every tick)
    const double reach2 = (0.05 * size) * (0.05 * size);
    std::array<double, Manifold::kMaxPoints> nearest{};
    for (std::size_t k = 0; k < fresh; ++k) {
      double best = reach2;
      nearest[k] = reach2;
      for (std::size_t w = warm_begin; w < warm_end; ++w) {
        const Vec3 d = cand[k].sa_B - warm_[w].sa_B;
        if (glm::dot(d, d) < nearest[k]) {
          nearest[k] = glm::dot(d, d);
          cand[k].slot = w;
        }
        if (warm_[w].ln > 0.0 && glm::dot(d, d) < best) {
          best = glm::dot(d, d);
          cand[k].ln = warm_[w].ln;
          cand[k].lt = warm_[w].lt;
          cand[k].warm = true;
          cand[k].source = w;
        }
      }
    }
    // the solve order (sequential impulses: the result depends on it) is the geometry's, not
    // the collision manifold's: a point that continues one of last tick's (the nearest within
    // the warm start's reach, or a kept one) takes its place, new ones follow by their place
    // on a's surface (in grains of 1e-9 of the size). The manifold's order and count are
    // rounding's where its points are equally deep (a body resting flat, as the settling
    // leaves it): with them the same scene in another length unit gave other forces
    // (Demo/ProxyScale.*, Stack.SameRelativeAnswerInMillimetresMetresAndKilometres)
    const double grain = 1e-9 * size;
    const auto grains = [&](double v) { return roundClamped(std::clamp(v / grain, -1e15, 1e15)); };
    for (std::size_t k = 0; k < fresh; ++k) {
      Candidate& cd = cand[k];
      cd.order = {cd.slot == kNoSlot ? 0.0 : grains(std::sqrt(nearest[k])), grains(cd.sa_B.x),
                  grains(cd.sa_B.y), grains(cd.sa_B.z)};
    }
    for (std::size_t w = warm_begin; w < warm_end; ++w) {
      const WarmPoint& wp = warm_[w];
      bool found = false;  // named again by the manifold this tick
      for (std::size_t k = 0; k < fresh && !found; ++k) {
        const Vec3 d = cand[k].sa_B - wp.sa_B;
        found = glm::dot(d, d) < keep * keep;
      }
      if (found)
        continue;
      // not found again: kept while its two surface points stay together along the contact
      // plane and apart by less than `keep` across it
      const Vec3 pa = A.x_W + A.R * wp.sa_B, pb = B.x_W + B.R * wp.sb_B;
      const Vec3 d = pb - pa;
      const double gap = glm::dot(d, n_pair);
      const Vec3 slide = d - n_pair * gap;
      // and while the contact keeps its normal in both bodies (the same pair of features:
      // a turning or rolling contact has new points every tick, never stale ones)
      const bool same_normal = glm::dot(A.R * wp.na_B, n_pair) >= kSameNormalCos &&
                               glm::dot(B.R * wp.nb_B, n_pair) >= kSameNormalCos;
      if (gap > keep || glm::dot(slide, slide) > keep * keep || !same_normal ||
          nc == kMaxCandidates)
        continue;
      Candidate& cd = cand[nc++];
      cd.n = n_pair;
      cd.gap = gap;
      cd.sa_B = wp.sa_B;
      cd.sb_B = wp.sb_B;
      cd.ln = wp.ln;
      cd.lt = wp.lt;
      cd.warm = true;
      cd.slot = w;
      cd.source = w;
      cd.order = {0.0, grains(cd.sa_B.x), grains(cd.sa_B.y), grains(cd.sa_B.z)};
    }
    shareWarmStarts(cand.data(), nc);
    if (nc > Manifold::kMaxPoints)
      nc = reduceCandidates(cand.data(), nc, A, size);
    // insertion sort (at most Manifold::kMaxPoints; std::stable_sort may allocate)
    for (std::size_t k = 1; k < nc; ++k) {
      for (std::size_t j = k; j > 0 && std::tie(cand[j].slot, cand[j].order) <
                                           std::tie(cand[j - 1].slot, cand[j - 1].order);
           --j) {
        std::swap(cand[j], cand[j - 1]);
      }
    }
    const std::size_t first = points_.size();
    for (std::size_t k = 0; k < nc; ++k) {
      const Candidate& cd = cand[k];
      if (points_.size() == cap) {
        ++counters_.points_dropped;
        step_flags_ |= kStepCapacityFull;
        continue;
      }
      ContactPoint& cp = points_.emplace_back();
      // the next tick's warm point: its pair and surface points now, its normal in the bodies'
      // frames and its impulses at the end of the tick (storeWarmStart)
      // (made whole and in place: a default-made one was zeroed first by a string store, slow
      // to start, and a temporary copied in stalled on its store forwarding)
      warm_next_.emplace_back(c.body_a, c.body_b, c.prim_a, c.prim_b, cd.sa_B, cd.sb_B);
      cp.a = c.body_a;
      cp.b = c.body_b;
      cp.n = cd.n;
      // a flat contact's points share their normal: its tangents once
      // (compared with the candidate's: the point's was just stored and is not read back)
      if (points_.size() > first + 1 && points_[points_.size() - 2].n == cd.n) {
        cp.t1 = points_[points_.size() - 2].t1;
        cp.t2 = points_[points_.size() - 2].t2;
      } else {
        tangents(cp.n, &cp.t1, &cp.t2);
      }
      // impulses act midway between the two surface points
      const Vec3 mid = 0.5 * (A.x_W + A.R * cd.sa_B + B.x_W + B.R * cd.sb_B);
      cp.ra = mid - A.x_W;
      cp.rb = mid - B.x_W;
      cp.ra_B = glm::transpose(A.R) * cp.ra;
      cp.rb_B = glm::transpose(B.R) * cp.rb;
      cp.gap = cd.gap;
      cp.size = size;
      cp.e = e;
      cp.mu_s = mu_s;
      cp.mu_d = mu_d;
      if (cd.warm) {
        cp.total_n = cd.ln;
        cp.total_t = cd.lt;
      }
    }
    if (points_.size() > first)
      points_[first].group = static_cast<std::uint8_t>(points_.size() - first);
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
    if (b.isotropic) {
      // a sphere-like body turns about its constant w: exact
      b.q = glm::normalize(geom::quatFromRotationVector(b.w_W * h) * b.q);
      b.updateInertia();
      continue;
    }
    const Vec3 L = b.R * (b.inertia_B * (glm::transpose(b.R) * b.w_W));
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
    asleep_ = false;  // the islands the input touches wake below (wakeIslands)
  }
  ++counters_.ticks;
  step_flags_ = 0;
  tick_dt_ = dt;
  // the world asked about what may move (a kinematic body given a target, an island woken by a
  // wrench or an edit), the islands that touches woken, and their own pairs listed again for
  // this step's solve
  if (syncSleep(world))
    world.relist();
  wakeIslands(world, held);
  if (syncSleep(world))
    world.relist();
  integrateForces(dt, world, held);
  gatherContacts(world.contacts(), report);
  islandSizes();
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
  target_given_ = false;  // every kinematic and driven body's target reached
  held_feedback_ = heldFeedbackOfTick();
  storeWarmStart(report);

  // poses back to the collision world, and the margins their boxes grow by: a free dynamic
  // body's as far as it may travel in the next tick (freeBodyMargin: the world's at most); the
  // held body's its base margin (a probe's: what the proxy reads) or twice its travel this tick,
  // that at most the world's, and so a driven body's (attached to the held one: the proxy reads
  // its contacts too); any other's the world's (a kinematic body follows its targets)
  const double box_margin = world.options().box_margin;
  const double held_base =
      held_ >= 0 ? world.baseMargin(static_cast<std::uint32_t>(held_)) : box_margin;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const BodyState& b = bodies_[i];
    if (b.motion == scene::Motion::kStatic || !b.enabled || b.asleep)
      continue;  // a sleeping body's pairs keep their answers (skip_unmoved_pairs)
    world.setPose(i, Pose{b.x_W - b.R * b.com_B, b.q});
    const bool is_held = static_cast<std::int32_t>(i) == held_;
    const double reach = (glm::length(b.v_W) + glm::length(b.w_W) * b.size) * dt +
                         glm::length(b.gravity_W) * dt * dt;
    double margin = box_margin;
    if (options_.body_margins && (is_held || b.driven))
      margin = reachMargin(held_base, reach, box_margin);
    else if (options_.body_margins && b.motion == scene::Motion::kDynamic && !b.coast)
      margin = freeBodyMargin(b.size, reach, box_margin);
    world.setMargin(i, margin);
  }
  updateSleep(dt);
  syncSleep(world);
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

// the penetration a resting point keeps: slop_fraction of the smallest dynamic size in its
// island (or of its smaller body's), and no more than gravity's slop_settle_time_s bound
// (DynamicsOptions)
double Dynamics::slop(const ContactPoint& cp) const {
  const double relative = options_.slop_fraction * slopSize(cp);
  const double t = options_.slop_settle_time_s;
  if (t > 0.0 && accel_scale_ > 0.0)
    return std::min(relative, accel_scale_ * t * t);
  return relative;
}

// the slop's length of a point: the smallest dynamic size of its island (islandSizes), or its
// smaller body's
double Dynamics::slopSize(const ContactPoint& cp) const {
  return one_size_ ? cp.size : std::min({cp.size, slop_size_[cp.a], slop_size_[cp.b]});
}

// a point whose gap closes counts as touching from here (never zero: a gap that closes exactly
// at its time of impact may be left at +1e-18 by rounding)
double Dynamics::touchTolerance(const ContactPoint& cp) const {
  return std::max(0.25 * slop(cp), 1e-9 * cp.size);
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
  cp.resting = vt < options_.static_friction_speed_fraction * thr;
  cp.mu = cp.resting ? cp.mu_s : cp.mu_d;
}

// the first solve at the start of the tick (the points touching now, the joints); then §6.1:
// advance to the earliest time of impact, apply the impulses there, go on; the rest of the tick
void Dynamics::solveThroughImpacts(double dt, StepReport& report) {
  const double v_gravity = options_.restitution_threshold_ticks * accel_scale_ * dt;
  velocity_tolerance_ = options_.velocity_tolerance_fraction *
                        std::max(v_gravity, options_.restitution_threshold_fraction * min_size_);
  warm_pending_ = true;
  iterations_run_ = 0;
  settle_rows_ = 0;
  bool any_active = !joints_.empty() || !general_.empty();
  // the points not yet in the solves (none: no time of impact to look for)
  std::size_t inactive = 0;
  // the largest mass ratio of two dynamic bodies in contact: the early stop's tolerance is
  // divided by it. An iteration's corrections underestimate the error left by about the ratio
  // (sequential impulses pass a heavy body's load through a light one a fraction of it per
  // iteration), and what they leave feeds the stack's tipping: two light 5 mm cubes under one
  // 100 times denser, with friction, stopped after 2 iterations a tick, leant over from
  // rounding (e-folding 60 ms, a top-heavy tower's own rate) until it fell at 1.3 s; with the
  // tolerance divided by 100 the lean stays below 1e-8 of the edge. Equal masses: unchanged.
  double ratio = 1.0;
  // the same over the resting contacts only: the settling iterations' rules (solveVelocities,
  // correctPositions). Sliding contacts (a gear's teeth) that rarely converge are left out, so
  // that their scenes do not run the settling iterations to the row budget every tick.
  double rest_ratio = 1.0;
  for (ContactPoint& cp : points_) {
    if (!std::isfinite(cp.size))
      cp.size = scene_->length_scale;
    cp.active = false;
    cp.speculative = false;
    if (cp.gap <= touchTolerance(cp)) {
      activate(cp);
      any_active = true;
      const BodyState& A = bodies_[cp.a];
      const BodyState& B = bodies_[cp.b];
      const double lo = std::min(A.inv_mass, B.inv_mass);
      if (!A.infinite && !B.infinite && lo > 0.0) {
        ratio = std::max(ratio, std::max(A.inv_mass, B.inv_mass) / lo);
        if (cp.resting)
          rest_ratio = std::max(rest_ratio, std::max(A.inv_mass, B.inv_mass) / lo);
      }
    } else {
      ++inactive;
    }
  }
  velocity_tolerance_ /= ratio;
  mass_ratio_ = rest_ratio;
  if (any_active) {
    solveVelocities(dt);
  } else {
    for (ContactPoint& cp : points_)
      cp.total_n = 0.0, cp.total_t = Vec3{0.0};
  }
  warm_pending_ = false;

  double t = 0.0;
  while (inactive > 0) {
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
      if (!cp.active && cp.gap <= touchTolerance(cp)) {
        activate(cp);
        --inactive;
      }
    }
    solveVelocities(dt - t);
  }
  advance(dt - t);
  report.velocity_iterations = iterations_run_;
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

std::uint32_t Dynamics::findRoot(std::uint32_t i) {
  while (parent_[i] != i) {
    parent_[i] = parent_[parent_[i]];  // path halving
    i = parent_[i];
  }
  return i;
}

void Dynamics::joinRoots(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t ra = findRoot(a), rb = findRoot(b);
  if (ra != rb)
    parent_[std::max(ra, rb)] = std::min(ra, rb);
}

// the slop's length per body (slop_size_): the smallest size among the dynamic bodies that this
// tick's contact points join to it (DynamicsOptions::slop_fraction). Nothing to do when every
// dynamic body has one size (then each contact's own smaller size is that size, or less).
void Dynamics::islandSizes() {
  if (one_size_)
    return;
  const auto n = static_cast<std::uint32_t>(bodies_.size());
  const auto joins = [&](std::uint32_t i) {
    return bodies_[i].motion == scene::Motion::kDynamic && !bodies_[i].infinite &&
           static_cast<std::int32_t>(i) != held_;
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    parent_[i] = i;
    slop_size_[i] = kInf;
  }
  for (const ContactPoint& cp : points_) {
    if (joins(cp.a) && joins(cp.b))
      joinRoots(cp.a, cp.b);
  }
  // each root's smallest size, then every body its root's (a root's own is final by then)
  for (std::uint32_t i = 0; i < n; ++i) {
    if (joins(i)) {
      double& m = slop_size_[findRoot(i)];
      m = std::min(m, bodies_[i].size);
    }
  }
  for (std::uint32_t i = 0; i < n; ++i)
    slop_size_[i] = slop_size_[findRoot(i)];
}

void Dynamics::wakeIsland(std::uint32_t island) {
  for (BodyState& b : bodies_) {
    if (b.asleep && b.island == island)
      b.asleep = false, b.rest_s = 0.0;
  }
}

// islands that something moving touches wake: an awake dynamic body that moves, the held body
// or a driven one moving, a kinematic body with a target or a velocity, within the box margin
void Dynamics::wakeIslands(const collision::CollisionWorld& world, const HeldInput* held) {
  bool any = false;
  for (const BodyState& b : bodies_)
    any = any || b.asleep;
  if (!any)
    return;
  const double margin = world.options().box_margin;
  const auto moving = [&](std::uint32_t i) {
    const BodyState& b = bodies_[i];
    if (!b.enabled || b.asleep || b.motion == scene::Motion::kStatic)
      return false;
    if (static_cast<std::int32_t>(i) == held_ && held != nullptr) {
      if (held->mode == HeldMode::kWrench)
        return true;
      if (held->mode == HeldMode::kKinematic) {
        const Vec3 x =
            held->X_WB_target.translation + glm::mat3_cast(held->X_WB_target.rotation) * b.com_B;
        return x != b.x_W || std::abs(glm::dot(held->X_WB_target.rotation, b.q)) < 1.0;
      }
    }
    if (b.has_target || (b.coast && (b.v_coast != Vec3{0.0} || b.w_coast != Vec3{0.0})))
      return true;
    if (b.motion != scene::Motion::kDynamic)
      return false;
    const double speed = glm::length(b.v_W) + glm::length(b.w_W) * b.size;
    return speed > options_.sleep_speed_fraction * b.size;
  };
  for (const collision::Contact& c : world.contacts()) {
    if (!c.answered || c.body_a >= bodies_.size() || c.body_b >= bodies_.size() ||
        c.distance > margin)
      continue;
    const BodyState& A = bodies_[c.body_a];
    const BodyState& B = bodies_[c.body_b];
    if (A.asleep && !B.asleep && moving(c.body_b))
      wakeIsland(A.island);
    else if (B.asleep && !A.asleep && moving(c.body_a))
      wakeIsland(B.island);
  }
}

// sleep per island: every body's rest timer; islands joined by touching contacts and joints
// between dynamic bodies; an island whose bodies have all rested for sleep_time_s sleeps; when
// all have, the scene does
void Dynamics::updateSleep(double dt) {
  if (!(options_.sleep_time_s > 0.0))
    return;
  const auto n = static_cast<std::uint32_t>(bodies_.size());
  const auto sleeper = [&](std::uint32_t i) {
    const BodyState& b = bodies_[i];
    return b.motion == scene::Motion::kDynamic && b.enabled && !b.driven && !b.asleep &&
           static_cast<std::int32_t>(i) != held_;
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    parent_[i] = i;
    BodyState& b = bodies_[i];
    if (!sleeper(i))
      continue;
    const double speed = glm::length(b.v_W) + glm::length(b.w_W) * b.size;
    b.rest_s = speed <= options_.sleep_speed_fraction * b.size ? b.rest_s + dt : 0.0;
  }
  const auto heldSet = [&](std::uint32_t i) {
    return static_cast<std::int32_t>(i) == held_ || bodies_[i].driven;
  };
  for (const ContactPoint& cp : points_) {
    if (cp.gap > touchTolerance(cp) && !(cp.active && cp.total_n > 0.0))
      continue;
    if (sleeper(cp.a) && sleeper(cp.b)) {
      joinRoots(cp.a, cp.b);
    } else if (held_kinematic_ && (heldSet(cp.a) || heldSet(cp.b))) {
      // the hand keeps what it touches awake
      bodies_[heldSet(cp.a) ? cp.b : cp.a].rest_s = 0.0;
    }
  }
  for (const JointState& js : joints_) {
    if (!js.off && js.b >= 0 && sleeper(js.a) && sleeper(static_cast<std::uint32_t>(js.b)))
      joinRoots(js.a, static_cast<std::uint32_t>(js.b));
  }
  for (const GeneralJoint& gj : general_) {
    if (gj.off)
      continue;
    bool driving = false;
    for (const JointRowSpec& spec : gj.specs) {
      driving = driving || (spec.bound == JointRowSpec::Bound::kDrive && spec.has_velocity &&
                            spec.velocity_target != 0.0);
    }
    if (driving) {
      bodies_[gj.a].rest_s = 0.0;
      if (gj.b >= 0)
        bodies_[static_cast<std::size_t>(gj.b)].rest_s = 0.0;
    }
    if (gj.b >= 0 && sleeper(gj.a) && sleeper(static_cast<std::uint32_t>(gj.b)))
      joinRoots(gj.a, static_cast<std::uint32_t>(gj.b));
  }
  for (std::uint32_t i = 0; i < n; ++i)
    island_rest_[i] = kInf;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (sleeper(i)) {
      const std::uint32_t r = findRoot(i);
      island_rest_[r] = std::min(island_rest_[r], bodies_[i].rest_s);
    }
  }
  bool all = true;
  for (std::uint32_t i = 0; i < n; ++i) {
    BodyState& b = bodies_[i];
    if (!sleeper(i))
      continue;
    const std::uint32_t r = findRoot(i);
    if (island_rest_[r] >= options_.sleep_time_s) {
      b.asleep = true;
      b.island = r;
      b.v_W = b.w_W = Vec3{0.0};
    } else {
      all = false;
    }
  }
  // the whole scene sleeps when every island does and nothing else moves
  for (std::uint32_t i = 0; i < n && all; ++i) {
    const BodyState& b = bodies_[i];
    if (b.enabled && b.motion == scene::Motion::kDynamic && b.driven)
      all = false;
    if (b.enabled && b.coast && (b.v_coast != Vec3{0.0} || b.w_coast != Vec3{0.0}))
      all = false;
  }
  if (all && held_kinematic_) {
    for (const ContactPoint& cp : points_) {
      if ((heldSet(cp.a) || heldSet(cp.b)) && cp.gap <= touchTolerance(cp))
        all = false;
    }
  }
  if (all)
    asleep_ = true;
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

// anything that could move a resting scene: the held body's input, a kinematic target
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
  if (!target_given_)
    return false;  // no target given since the last step: no walk over the bodies
  for (const BodyState& b : bodies_) {
    if (!b.enabled)
      continue;
    // (an external wrench wakes its island when it is set: setExternalWrench; one that was
    // there when the island fell asleep is balanced)
    if (b.has_target && (b.motion == scene::Motion::kKinematic || b.driven))
      return true;
  }
  return false;
}

// every point of the tick is kept for the next (gatherContacts drops those that came apart),
// with its impulses where it pushed; sorted by primitive pair. gatherContacts wrote each point's
// pair and surface points (warm_next_[i] is points_[i]'s); here its normal in the bodies' frames
// at the end of the tick and its impulses. The report's count of the points that touch and of
// those that pushed, in the same pass.
void Dynamics::storeWarmStart(StepReport& report) {
  std::uint32_t active_points = 0, impulse_points = 0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const ContactPoint& cp = points_[i];
    WarmPoint& w = warm_next_[i];
    // a pair's points usually share their normal: it is turned into the bodies' frames once
    const ContactPoint* prev = i > 0 ? &points_[i - 1] : nullptr;
    if (prev != nullptr && prev->a == cp.a && prev->b == cp.b && prev->n == cp.n) {
      w.na_B = warm_next_[i - 1].na_B;
      w.nb_B = warm_next_[i - 1].nb_B;
    } else {
      w.na_B = glm::transpose(bodies_[cp.a].R) * cp.n;
      w.nb_B = glm::transpose(bodies_[cp.b].R) * cp.n;
    }
    const bool pushed = cp.active && cp.total_n > 0.0;
    w.ln = pushed ? cp.total_n : 0.0;
    w.lt = pushed ? cp.total_t : Vec3{0.0};
    active_points += cp.active && cp.gap <= touchTolerance(cp) ? 1u : 0u;
    impulse_points += cp.total_n > 0.0 ? 1u : 0u;
  }
  report.active_points = active_points;
  report.impulse_points += impulse_points;
  // the contacts come sorted by body pair: usually already in order (no sort then)
  const auto less = [](const WarmPoint& x, const WarmPoint& y) { return x.key() < y.key(); };
  if (!std::is_sorted(warm_next_.begin(), warm_next_.end(), less))
    std::sort(warm_next_.begin(), warm_next_.end(), less);
  std::swap(warm_, warm_next_);
}

}  // namespace hapticd::dynamics
