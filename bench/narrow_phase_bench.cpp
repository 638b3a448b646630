// hapticbench, narrow phase: distance and penetration between convex hulls, coherent and
// incoherent, ours and the peers', each also checked for wrong answers against the brute-force
// reference. Names as in docs/architecture.md: Distance/Coherent/<N>, ...,
// Peer/<lib>-<method>/<name>.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>

#include "bench/peers.h"
#include "core/collision/pair_query.h"
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

// ---------------------------------------------------------------- peers
void peer(benchmark::State& state, std::string name, std::size_t n, bool overlap, bool coherent) {
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

void registerAll() {
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
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace hapticd::bench
