// hapticbench, narrow phase: distance and penetration between convex hulls, coherent and
// incoherent, ours and the peers', each also checked for wrong answers against the brute-force
// reference. Names as in docs/architecture.md: Distance/Coherent/<N>, ...,
// Peer/<lib>-<method>/<name>. The NearContact path brings B within 0.05-5 mm of A.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "bench/peers.h"
#include "core/collision/pair_query.h"
#include "tests/core/geometry_helpers.h"
#include "tests/reference/reference.h"

namespace hapticd::bench {
namespace {

using collision::PairCache;
using geom::Polytope;
using geom::Pose;
using geom::Transform;
using geom::Vec3;

constexpr double kWrong = 1e-9;  // of the object size
constexpr std::size_t kChecks = 20;

// N points on the ellipsoid with semi-axes 25, 18, 12 mm (in metres), moved so that the mean of
// the hull's vertices is the origin (a coarse hull need not contain the ellipsoid's centre).
Polytope ellipsoidHull(std::size_t n, std::uint64_t seed, double scale) {
  auto pts = reference::ellipsoidPoints(n, 0.025 * scale, 0.018 * scale, 0.012 * scale, seed);
  const Vec3 c = Polytope::fromPoints(pts).value().centroid();
  for (Vec3& p : pts)
    p -= c;
  return Polytope::fromPoints(pts).value();
}

Transform scaledTransform(const Transform& X, double s) {
  return {X.R, X.t * s};
}

struct Scenario {
  std::size_t n = 0;
  bool overlap = false;
  std::unique_ptr<Polytope> a, b;        // metres
  std::unique_ptr<Polytope> a_mm, b_mm;  // the same in millimetres
  std::vector<Transform> coherent, incoherent, check;
  std::vector<double> ref;  // reference signed distance of each check pose (metres)
  double size = 0.0;
};

// B's pose relative to A: centre at distance `r` along a slowly turning direction, B turning.
Transform orbit(double r, double k, const Vec3& axis) {
  const double t = k * 0.1e-3 / r;  // 0.1 mm per step along the orbit
  const Vec3 c{r * std::cos(t), r * std::sin(t) * 0.8, r * std::sin(t) * 0.6};
  return Pose{c, glm::angleAxis(k * 0.1 * M_PI / 180.0, axis)}.toTransform();  // 0.1 deg per step
}

Scenario& scenario(std::size_t n, bool overlap) {
  static std::map<std::pair<std::size_t, bool>, Scenario> all;
  auto [it, fresh] = all.try_emplace({n, overlap});
  Scenario& s = it->second;
  if (!fresh)
    return s;
  s.n = n;
  s.overlap = overlap;
  s.a = std::make_unique<Polytope>(ellipsoidHull(n, 1, 1.0));
  s.b = std::make_unique<Polytope>(ellipsoidHull(n, 2, 1.0));
  s.a_mm = std::make_unique<Polytope>(ellipsoidHull(n, 1, 1000.0));
  s.b_mm = std::make_unique<Polytope>(ellipsoidHull(n, 2, 1000.0));
  s.size = std::max(s.a->radius(), s.b->radius());
  // apart: centres 60 mm apart (radii <= 25 mm); overlapping: centres closer than the sum of the
  // radii of the balls inscribed about the origin (coarse hulls have small ones)
  auto inscribed = [](const Polytope& p) {
    double r = 1e300;
    for (const auto& f : p.faces())
      r = std::min(r, f.offset);
    return r;
  };
  const double r = overlap ? 0.7 * (inscribed(*s.a) + inscribed(*s.b)) : 0.060;
  const Vec3 axis = glm::normalize(Vec3{1, 2, 3});
  for (int k = 0; k < 20000; ++k)
    s.coherent.push_back(orbit(r, k, axis));
  std::mt19937_64 rng(n * 7 + overlap);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < 1024; ++k) {
    const Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
    s.incoherent.push_back(Pose{dir * r, reference::randomRotation(rng)}.toTransform());
  }
  for (std::size_t k = 0; k < kChecks; ++k) {
    s.check.push_back(k % 2 ? s.incoherent[k * 37 % s.incoherent.size()]
                            : s.coherent[k * 997 % s.coherent.size()]);
    s.ref.push_back(overlap ? -reference::bruteMinkowskiDepth(*s.a, *s.b, s.check.back(), nullptr)
                            : reference::bruteSeparatedDistance(*s.a, *s.b, s.check.back()));
  }
  return s;
}

// The near-contact path: B's centre along a slowly turning direction u, B spinning 0.1 degree
// per step about a seeded axis, at the centre distance that leaves a gap g between the hulls; g
// goes from 5 mm down to 0.05 mm and back (geometrically) every 1 000 steps (B approaching A,
// then backing off). Each pose's centre distance is solved on our own closest features (Newton
// on the gap along u); the check poses' distances come from the brute-force reference.
constexpr std::size_t kNearSteps = 20000;
constexpr double kGapMin = 0.05e-3, kGapMax = 5e-3;

// The k-th check pose of the near-contact path: the first at the closest approach, the others
// spread over the approach's phases (0.05 to 5 mm) and over the path.
std::size_t nearCheckIndex(std::size_t k) {
  return (500 + k * 1049) % kNearSteps;
}

Scenario& nearScenario(std::size_t n) {
  static std::map<std::size_t, Scenario> all;
  auto [it, fresh] = all.try_emplace(n);
  Scenario& s = it->second;
  if (!fresh)
    return s;
  s.n = n;
  s.a = std::make_unique<Polytope>(ellipsoidHull(n, 1, 1.0));
  s.b = std::make_unique<Polytope>(ellipsoidHull(n, 2, 1.0));
  s.a_mm = std::make_unique<Polytope>(ellipsoidHull(n, 1, 1000.0));
  s.b_mm = std::make_unique<Polytope>(ellipsoidHull(n, 2, 1000.0));
  s.size = std::max(s.a->radius(), s.b->radius());
  std::mt19937_64 rng(1800 + n);
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec3 axis = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
  const geom::Quat q0 = reference::randomRotation(rng);
  const double t0 = 2.0 * M_PI * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  collision::FeatureCache cache;
  for (std::size_t k = 0; k < kNearSteps; ++k) {
    const double t = t0 + static_cast<double>(k) * 2e-4;  // the approach direction turns slowly
    const Vec3 u = glm::normalize(Vec3{std::cos(t), 0.8 * std::sin(t), 0.6 * std::sin(2.0 * t)});
    const double phase = 0.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(k % 1000) / 1000.0);
    const double gap = kGapMax * std::pow(kGapMin / kGapMax, phase);
    const geom::Quat q = glm::angleAxis(static_cast<double>(k) * 0.1 * M_PI / 180.0, axis) * q0;
    // start where the gap along u is `gap` (a lower bound of the distance), then Newton
    const Vec3 u_b = glm::inverse(q) * -u;
    double r = glm::dot(s.a->vertices()[s.a->support(u, 0)].p, u) +
               glm::dot(s.b->vertices()[s.b->support(u_b, 0)].p, u_b) + gap;
    Transform X = Pose{u * r, q}.toTransform();
    for (int step = 0; step < 30; ++step) {
      const auto c = collision::closestFeatures(*s.a, *s.b, X, cache);
      const double err = c.distance - gap;
      if (std::abs(err) <= 1e-4 * gap)
        break;
      r -= err / std::max(glm::dot(c.normal, u), 0.2);
      X = Pose{u * r, q}.toTransform();
    }
    s.coherent.push_back(X);
  }
  for (std::size_t k = 0; k < kChecks; ++k) {
    s.check.push_back(s.coherent[nearCheckIndex(k)]);
    s.ref.push_back(reference::bruteSeparatedDistance(*s.a, *s.b, s.check.back()));
  }
  return s;
}

// Wrong answers on the check poses, in metres and in millimetres.
struct Wrong {
  int m = 0, mm = 0;
  double max_rel = 0.0;
};

template <class F>  // F(bool mm, const Transform&, bool& ok) -> signed distance in that unit
Wrong countWrong(const Scenario& s, F&& f) {
  Wrong w;
  for (std::size_t k = 0; k < s.check.size(); ++k) {
    for (const bool mm : {false, true}) {
      const double unit = mm ? 1000.0 : 1.0;
      bool ok = true;
      const double d = f(mm, scaledTransform(s.check[k], unit), ok) / unit;
      const double err = ok ? std::abs(d - s.ref[k]) / s.size : 1.0;
      if (!mm)
        w.max_rel = std::max(w.max_rel, err);
      if (!ok || !(err <= kWrong))
        ++(mm ? w.mm : w.m);
    }
  }
  return w;
}

void setCounters(benchmark::State& state, const Wrong& w, const Scenario& s) {
  state.counters["checked"] = static_cast<double>(s.check.size());
  state.counters["wrong_m"] = w.m;
  state.counters["wrong_mm"] = w.mm;
  state.counters["max_rel_err"] = w.max_rel;
}

// The tracked depth's counters: fallbacks (the certificate failed, the full method ran) and
// cold queries per query, candidates evaluated per certified answer.
void setTrackerCounters(benchmark::State& state, const collision::DepthTracker::Stats& t) {
  const double q = std::max<double>(1.0, static_cast<double>(t.queries));
  state.counters["fallbacks"] = static_cast<double>(t.fallbacks) / q;
  state.counters["cold"] = static_cast<double>(t.cold) / q;
  state.counters["evaluated"] =
      static_cast<double>(t.evaluated) / std::max<double>(1.0, static_cast<double>(t.certified));
}

// ---------------------------------------------------------------- ours
void ours(benchmark::State& state, std::size_t n, bool overlap, bool coherent) {
  Scenario& s = scenario(n, overlap);
  const Wrong w = countWrong(s, [&](bool mm, const Transform& X, bool& ok) {
    PairCache c;
    const auto r = collision::queryPair(mm ? *s.a_mm : *s.a, mm ? *s.b_mm : *s.b, X, c);
    ok = (r.status == collision::ContactStatus::kPenetrating) == overlap;
    return r.distance;
  });
  const auto& poses = coherent ? s.coherent : s.incoherent;
  std::size_t i = 0;
  PairCache warm;
  // the coherent path tracks the depth (penetrationDepthCoherent) where tracking pays (up to
  // 128 vertices here; Depth/Coherent/<N> gives it at every N); a fresh cache per query has
  // nothing to track
  collision::DepthTracker tracker;
  tracker.reserve(*s.a, *s.b);
  const bool tracked = overlap && coherent && collision::DepthTracker::pays(*s.a, *s.b);
  if (tracked)
    warm.tracker = &tracker;
  collision::FeatureCache warm_features;
  for (auto _ : state) {
    const Transform& X = poses[i];
    if (++i == poses.size())
      i = 0;
    if (!overlap) {
      // the distance query: closest features (V-Clip), witness points, normal
      collision::FeatureCache cold;
      auto r = collision::closestFeatures(*s.a, *s.b, X, coherent ? warm_features : cold);
      benchmark::DoNotOptimize(r);
    } else {
      PairCache cold;
      auto r = collision::queryPair(*s.a, *s.b, X, coherent ? warm : cold);
      benchmark::DoNotOptimize(r);
    }
  }
  setCounters(state, w, s);
  if (tracked)
    setTrackerCounters(state, tracker.stats);
}

// Depth/Coherent/<N>: the depth alone along the Penetration/Coherent path, tracked
// (penetrationDepthCoherent, `tracked`) or by the untracked call the pair query made before it
// (penetrationDepth: EPA warm-started from last tick for large hulls, the separating axes for
// small ones). Wrong answers: the tracked depth along the whole path against the reference at
// the check poses of the path, and every tracked answer against the full method
// (penetrationDepthExact) on the first 2 000 poses (`differ_from_full`: not as good as the full
// method's answer, reference::depthAgreesWithFull, to 1e-12 of the size).
void oursDepth(benchmark::State& state, std::size_t n, bool tracked) {
  Scenario& s = scenario(n, true);
  const Polytope& a = *s.a;
  const Polytope& b = *s.b;
  Wrong w;
  double differ = 0.0;
  for (const bool mm : {false, true}) {
    const double unit = mm ? 1000.0 : 1.0;
    const Polytope& pa = mm ? *s.a_mm : a;
    const Polytope& pb = mm ? *s.b_mm : b;
    collision::DepthTracker t;
    t.reserve(pa, pb);
    collision::DepthCache c;
    for (std::size_t i = 0; i < s.coherent.size(); ++i) {
      const Transform X = scaledTransform(s.coherent[i], unit);
      const auto d = tracked ? collision::penetrationDepthCoherent(pa, pb, X, t, c)
                             : collision::penetrationDepth(pa, pb, X, c);
      if (i < 2000) {
        collision::DepthCache fresh;
        const auto f = collision::penetrationDepthExact(pa, pb, X, fresh);
        if (!reference::depthAgreesWithFull(pa, pb, X, d.depth, d.normal, f.depth,
                                            1e-12 * s.size * unit))
          differ += 1.0;
      }
      for (std::size_t k = 0; k < kChecks; k += 2) {  // the even check poses are on the path
        if (k * 997 % s.coherent.size() != i)
          continue;
        const double err = std::abs(-d.depth / unit - s.ref[k]) / s.size;
        if (!mm)
          w.max_rel = std::max(w.max_rel, err);
        if (!(err <= kWrong))
          ++(mm ? w.mm : w.m);
      }
    }
  }
  std::size_t i = 0;
  collision::DepthTracker tracker;
  tracker.reserve(a, b);
  collision::DepthCache cache;
  for (auto _ : state) {
    auto d = tracked ? collision::penetrationDepthCoherent(a, b, s.coherent[i], tracker, cache)
                     : collision::penetrationDepth(a, b, s.coherent[i], cache);
    if (++i == s.coherent.size())
      i = 0;
    benchmark::DoNotOptimize(d);
  }
  const std::size_t on_path = (kChecks + 1) / 2;  // the even check poses
  state.counters["checked"] = static_cast<double>(on_path);
  state.counters["wrong_m"] = w.m;
  state.counters["wrong_mm"] = w.mm;
  state.counters["max_rel_err"] = w.max_rel;
  state.counters["differ_from_full"] = differ;
  if (tracked)
    setTrackerCounters(state, tracker.stats);
}

// Depth/Resting/<k>, Depth/RestingUntracked/<k>: a resting contact, as a solver keeps a stack:
// two prisms over k-gons (k = 4: boxes) of 50 mm, B on A turned 30 degrees about the vertical,
// the overlap breathing between 1e-6 and 1e-3 of the size, B swaying sideways and tilting by up
// to 1e-6 rad (the solver's jitter). The depth tracked (penetrationDepthCoherent) against
// untracked (penetrationDepth, warm-started: what CollisionWorld does for a pair
// DepthTracker::pays rejects): where these cross is where a pair should stop being tracked.
// `wrong_m`, `wrong_mm`: answers of the whole path (`checked` poses), in metres and again in
// millimetres, not as good as the full method's (reference::depthAgreesWithFull, to 1e-12 of
// the size); `differ_from_full` their sum, as before. Not |depth - full| <= 1e-12
// of the size: the full method's tie grid puts its own answer up to 1e-12 of the coordinates'
// magnitude (here 3.4e-12 of the size) above the least, and the untracked EPA's least depth at
// pose 3397 of 32 sides, 1.1e-12 of the size below the full method's cap face, is correct
// (Penetration.UntrackedDepthOnRestingPrismsIsTheLeastOneBelowTheTieGridsPick).
void oursDepthResting(benchmark::State& state, int k, bool tracked) {
  const auto corners = hapticd::testing::prism(k, 0.025, 0.025);
  const Polytope a = Polytope::fromPoints(corners).value();
  const Polytope b = Polytope::fromPoints(corners).value();
  const auto corners_mm = hapticd::testing::prism(k, 25.0, 25.0);
  const Polytope a_mm = Polytope::fromPoints(corners_mm).value();
  const Polytope b_mm = Polytope::fromPoints(corners_mm).value();
  std::vector<Transform> path(4096);
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double t = static_cast<double>(i);
    const double overlap = 0.025 * (1e-6 + 1e-3 * (0.5 + 0.5 * std::sin(t * 0.07)));
    const Vec3 side{0.004 * std::sin(t * 0.031), 0.003 * std::cos(t * 0.023), 0.0};
    const geom::Quat wobble = glm::angleAxis(1e-6 * std::sin(t * 0.05),
                                             glm::normalize(Vec3{std::cos(t * 0.011), 1.0, 0.0}));
    const geom::Quat yaw = glm::angleAxis(30.0 * M_PI / 180.0, Vec3{0.0, 0.0, 1.0});
    path[i] = Pose{side + Vec3{0.0, 0.0, 0.05 - overlap}, wobble * yaw}.toTransform();
  }
  // every answer against the full method's, in metres and in millimetres
  Wrong w;
  for (const bool mm : {false, true}) {
    const double unit = mm ? 1000.0 : 1.0;
    const Polytope& pa = mm ? a_mm : a;
    const Polytope& pb = mm ? b_mm : b;
    collision::DepthTracker t;
    t.reserve(pa, pb);
    collision::DepthCache c;
    for (const Transform& X_m : path) {
      const Transform X = scaledTransform(X_m, unit);
      const auto d = tracked ? collision::penetrationDepthCoherent(pa, pb, X, t, c)
                             : collision::penetrationDepth(pa, pb, X, c);
      collision::DepthCache fresh;
      const auto f = collision::penetrationDepthExact(pa, pb, X, fresh);
      if (!reference::depthAgreesWithFull(pa, pb, X, d.depth, d.normal, f.depth,
                                          1e-12 * pa.radius()))
        ++(mm ? w.mm : w.m);
    }
  }
  std::size_t i = 0;
  collision::DepthTracker tracker;
  tracker.reserve(a, b);
  collision::DepthCache cache;
  collision::DepthScratch scratch;
  scratch.reserve(a.faces().size());
  for (auto _ : state) {
    auto d = tracked ? collision::penetrationDepthCoherent(a, b, path[i], tracker, cache, scratch)
                     : collision::penetrationDepth(a, b, path[i], cache, scratch);
    if (++i == path.size())
      i = 0;
    benchmark::DoNotOptimize(d);
  }
  state.counters["edges"] = static_cast<double>(a.edges().size());
  state.counters["checked"] = static_cast<double>(path.size());
  state.counters["wrong_m"] = w.m;
  state.counters["wrong_mm"] = w.mm;
  state.counters["differ_from_full"] = w.m + w.mm;
  if (tracked)
    setTrackerCounters(state, tracker.stats);
}

// The whole pair query on separated poses: closest features and the contact manifold.
void oursPairQuery(benchmark::State& state, std::size_t n) {
  Scenario& s = scenario(n, false);
  std::size_t i = 0;
  PairCache warm;
  for (auto _ : state) {
    auto r = collision::queryPair(*s.a, *s.b, s.coherent[i], warm);
    if (++i == s.coherent.size())
      i = 0;
    benchmark::DoNotOptimize(r);
  }
}

// On the near-contact path: the wrong answers are counted on the warm answers of a walk along the
// whole path (what the timed loop computes), at the check poses, in metres and in millimetres.
template <class F>  // F(bool mm, const Transform&, Cache&, bool& ok) -> distance in that unit
Wrong countWrongAlongPath(const Scenario& s, F&& f) {
  Wrong w;
  for (const bool mm : {false, true}) {
    const double unit = mm ? 1000.0 : 1.0;
    PairCache cache;
    std::size_t next = 0;
    std::vector<std::size_t> at;
    for (std::size_t k = 0; k < s.check.size(); ++k)
      at.push_back(nearCheckIndex(k));
    for (std::size_t i = 0; i < s.coherent.size(); ++i) {
      bool ok = true;
      const double d = f(mm, scaledTransform(s.coherent[i], unit), cache, ok) / unit;
      for (std::size_t k = 0; k < at.size(); ++k) {
        if (at[k] != i)
          continue;
        ++next;
        const double err = ok ? std::abs(d - s.ref[k]) / s.size : 1.0;
        if (!mm)
          w.max_rel = std::max(w.max_rel, err);
        if (!ok || !(err <= kWrong))
          ++(mm ? w.mm : w.m);
      }
    }
    if (next != at.size())
      ++(mm ? w.mm : w.m);  // a check pose not reached: count it
  }
  return w;
}

void setNearCounters(benchmark::State& state, const Scenario& s) {
  double lo = 1e300, hi = 0.0;
  for (const double r : s.ref)
    lo = std::min(lo, r), hi = std::max(hi, r);
  state.counters["gap_min_mm"] = lo * 1e3;  // of the check poses
  state.counters["gap_max_mm"] = hi * 1e3;
}

// Distance/NearContact/<N>: the warm distance query (closest features, witnesses, normal).
void oursNearDistance(benchmark::State& state, std::size_t n) {
  Scenario& s = nearScenario(n);
  const Wrong w = countWrongAlongPath(s, [&](bool mm, const Transform& X, PairCache& c, bool& ok) {
    const auto r =
        collision::closestFeatures(mm ? *s.a_mm : *s.a, mm ? *s.b_mm : *s.b, X, c.features);
    ok = r.status == collision::ContactStatus::kSeparated;
    return r.distance;
  });
  {
    // walk steps per query along the path (untimed)
    collision::FeatureCache c;
    double steps = 0.0;
    for (const Transform& X : s.coherent) {
      const auto r = collision::closestFeatures(*s.a, *s.b, X, c);
      steps += r.iterations;
    }
    state.counters["walk_steps"] = steps / static_cast<double>(s.coherent.size());
  }
  std::size_t i = 0;
  collision::FeatureCache warm;
  for (auto _ : state) {
    auto r = collision::closestFeatures(*s.a, *s.b, s.coherent[i], warm);
    if (++i == s.coherent.size())
      i = 0;
    benchmark::DoNotOptimize(r);
  }
  setCounters(state, w, s);
  setNearCounters(state, s);
}

// PairQuery/NearContact/<N>: the whole pair query (closest features and the contact manifold),
// its result returned by value. PairQueryInto/NearContact/<N>: the same query written into one
// PairResult kept from query to query, with its own scratch, as a CollisionWorld calls it.
void oursNearPairQuery(benchmark::State& state, std::size_t n, bool into) {
  Scenario& s = nearScenario(n);
  const Wrong w = countWrongAlongPath(s, [&](bool mm, const Transform& X, PairCache& c, bool& ok) {
    const auto r = collision::queryPair(mm ? *s.a_mm : *s.a, mm ? *s.b_mm : *s.b, X, c);
    // separated, and the manifold's deepest point is the pair's distance
    double deepest = -1e300;
    for (std::size_t k = 0; k < r.manifold.count; ++k)
      deepest = std::max(deepest, r.manifold.points[k].depth);
    ok = r.status == collision::ContactStatus::kSeparated && r.manifold.count > 0 &&
         std::abs(deepest + r.distance) <= kWrong * (mm ? 1000.0 : 1.0) * s.size;
    return r.distance;
  });
  std::size_t i = 0;
  PairCache warm;
  if (into) {
    // as a CollisionWorld calls it: one result and one scratch kept from query to query
    collision::PairResult r;
    collision::DepthScratch scratch;
    scratch.reserve(std::max(s.a->faces().size(), s.b->faces().size()));
    for (auto _ : state) {
      collision::queryPair(*s.a, *s.b, s.coherent[i], warm, scratch, {}, r);
      if (++i == s.coherent.size())
        i = 0;
      benchmark::DoNotOptimize(r);
    }
  } else {
    for (auto _ : state) {
      auto r = collision::queryPair(*s.a, *s.b, s.coherent[i], warm);
      if (++i == s.coherent.size())
        i = 0;
      benchmark::DoNotOptimize(r);
    }
  }
  setCounters(state, w, s);
  setNearCounters(state, s);
}

// The peers on the near-contact path (they keep no state between queries).
void peerNear(benchmark::State& state, const std::string& name, std::size_t n) {
  Scenario& s = nearScenario(n);
  auto m = makePeer(name, *s.a, *s.b);
  auto m_mm = makePeer(name, *s.a_mm, *s.b_mm);
  const Wrong w = countWrong(
      s, [&](bool mm, const Transform& X, bool& ok) { return (mm ? m_mm : m)->query(X, ok); });
  std::size_t i = 0;
  for (auto _ : state) {
    bool ok = true;
    const double d = m->query(s.coherent[i], ok);
    if (++i == s.coherent.size())
      i = 0;
    benchmark::DoNotOptimize(d);
    benchmark::DoNotOptimize(ok);
  }
  setCounters(state, w, s);
  setNearCounters(state, s);
}

// ---------------------------------------------------------------- peers
void peer(benchmark::State& state,
          const std::string& name,
          std::size_t n,
          bool overlap,
          bool coherent) {
  Scenario& s = scenario(n, overlap);
  auto m = makePeer(name, *s.a, *s.b);
  auto m_mm = makePeer(name, *s.a_mm, *s.b_mm);
  const Wrong w = countWrong(
      s, [&](bool mm, const Transform& X, bool& ok) { return (mm ? m_mm : m)->query(X, ok); });
  const auto& poses = coherent ? s.coherent : s.incoherent;
  std::size_t i = 0;
  for (auto _ : state) {
    bool ok = true;
    const double d = m->query(poses[i], ok);
    if (++i == poses.size())
      i = 0;
    benchmark::DoNotOptimize(d);
    benchmark::DoNotOptimize(ok);
  }
  setCounters(state, w, s);
}

// Depth/GearFlank/{exact,tracked}: the pair behind Tick/gears' slowest ticks, a gear tooth (a
// 10-gon prism 15 mm thick, as scenes/gears.glb's teeth) pressed by the scene's rod (a 16-gon
// prism of radius 3 mm, 36 mm long) against its flank, the axes parallel, the rod sliding 2 mm
// up and down the flank and turning 0.3 rad about its axis (the poses where they overlap). Parallel
// prisms put their Gauss maps' arcs through each other's vertices and along each other's arcs, so
// most of the exact method's edge walks are lost and sweep all of B's edges (penetration.cpp,
// edgeArc). `exact`: penetrationDepthExact at every pose (what a fallback, a cold or an untracked
// depth costs); `tracked`: penetrationDepthCoherent.
void oursDepthGearFlank(benchmark::State& state, bool tracked) {
  std::vector<Vec3> tooth;
  const double xy[10][2] = {{-2.0, 0.0}, {-2.1, 3.0}, {-1.9, 6.0}, {-1.5, 8.0}, {-0.9, 10.0},
                            {0.9, 10.0}, {1.5, 8.0},  {1.9, 6.0},  {2.1, 3.0},  {2.0, 0.0}};
  for (const auto& p : xy) {
    for (const double z : {-7.5, 7.5})
      tooth.push_back(Vec3{p[0], p[1], z} * 1e-3);
  }
  std::vector<Vec3> rod;
  for (int k = 0; k < 16; ++k) {
    const double t = 2.0 * M_PI * (k + 0.5) / 16.0;
    for (const double z : {-18.0, 18.0})
      rod.push_back(Vec3{3.0 * std::cos(t), 3.0 * std::sin(t), z} * 1e-3);
  }
  const Polytope a = Polytope::fromPoints(tooth).value();
  const Polytope b = Polytope::fromPoints(rod).value();
  // the poses of the rod's path where the two overlap (the others would stop the exact method
  // at a separating face of A)
  std::vector<Transform> path;
  for (int k = 0; k < 20000; ++k) {
    const double s = 1e-3 * k;
    Transform X;
    X.R = glm::mat3_cast(glm::angleAxis(0.3 * std::sin(s), Vec3{0.0, 0.0, 1.0}));
    // the rod's flat side (apothem 2.942 mm) at 0.03-0.09 mm from the flank near x = 2.03 mm
    X.t = Vec3{2.03 + 2.942 - 0.06 + 0.03 * std::sin(3.0 * s), 5.0 + 2.0 * std::sin(0.7 * s),
               0.3 * std::sin(1.3 * s)} *
          1e-3;
    collision::DepthCache fresh;
    if (collision::penetrationDepthExact(a, b, X, fresh).depth > 1e-9)
      path.push_back(X);
  }
  std::size_t i = 0;
  collision::DepthTracker tracker;
  tracker.reserve(a, b);
  collision::DepthCache cache;
  collision::DepthScratch scratch;
  scratch.reserve(std::max(a.faces().size(), b.faces().size()));
  for (auto _ : state) {
    auto d = tracked ? collision::penetrationDepthCoherent(a, b, path[i], tracker, cache, scratch)
                     : collision::penetrationDepthExact(a, b, path[i], cache, scratch);
    if (++i == path.size())
      i = 0;
    benchmark::DoNotOptimize(d);
  }
  state.counters["poses"] = static_cast<double>(path.size());
  if (tracked)
    setTrackerCounters(state, tracker.stats);
}

void registerAll() {
  benchmark::RegisterBenchmark("Depth/GearFlank/exact", oursDepthGearFlank, false);
  benchmark::RegisterBenchmark("Depth/GearFlank/tracked", oursDepthGearFlank, true);
  for (const int k : {4, 6, 8, 12, 16, 24, 32}) {
    benchmark::RegisterBenchmark(("Depth/Resting/" + std::to_string(k)).c_str(), oursDepthResting,
                                 k, true);
    benchmark::RegisterBenchmark(("Depth/RestingUntracked/" + std::to_string(k)).c_str(),
                                 oursDepthResting, k, false);
  }
  for (const std::size_t n : {8u, 32u, 128u, 512u}) {
    for (const bool overlap : {false, true}) {
      for (const bool coherent : {true, false}) {
        const std::string name = std::string(overlap ? "Penetration/" : "Distance/") +
                                 (coherent ? "Coherent/" : "Incoherent/") + std::to_string(n);
        benchmark::RegisterBenchmark(name.c_str(), ours, n, overlap, coherent);
        for (const PeerInfo& p : peerList()) {
          if (overlap ? !p.penetration : !p.distance)
            continue;
          benchmark::RegisterBenchmark(("Peer/" + p.name + "/" + name).c_str(), peer, p.name, n,
                                       overlap, coherent);
        }
      }
    }
    benchmark::RegisterBenchmark(("PairQuery/Coherent/" + std::to_string(n)).c_str(), oursPairQuery,
                                 n);
    benchmark::RegisterBenchmark(("Depth/Coherent/" + std::to_string(n)).c_str(), oursDepth, n,
                                 true);
    benchmark::RegisterBenchmark(("Depth/CoherentUntracked/" + std::to_string(n)).c_str(),
                                 oursDepth, n, false);
    const std::string near = "NearContact/" + std::to_string(n);
    benchmark::RegisterBenchmark(("Distance/" + near).c_str(), oursNearDistance, n);
    benchmark::RegisterBenchmark(("PairQuery/" + near).c_str(), oursNearPairQuery, n, false);
    benchmark::RegisterBenchmark(("PairQueryInto/" + near).c_str(), oursNearPairQuery, n, true);
    for (const PeerInfo& p : peerList()) {
      if (p.distance) {
        benchmark::RegisterBenchmark(("Peer/" + p.name + "/Distance/" + near).c_str(), peerNear,
                                     p.name, n);
      }
    }
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace hapticd::bench
