// The coherent exact depth (penetrationDepthCoherent) against the full method
// (penetrationDepthExact) on random paths, in metres and millimetres, at 8 to 512 vertices, and
// on near-degenerate poses (aligned boxes, equal cubes, exits and re-entries) also against the
// brute-force reference; each answer the tracked state certifies equals the full method's (depth,
// normal, features), and every fallback is counted. No allocation once reserved.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include "core/collision/pair_query.h"
#include "core/collision/penetration.h"
#include "tests/core/alloc_counter.h"
#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers

// Witnesses of `d`: point_a in A's support set along the normal, point_b in B's against it (B
// placed by X), point_a - point_b = depth * normal.
bool witnessesValid(const Polytope& a,
                    const Polytope& b,
                    const Transform& X,
                    const DepthResult& d,
                    double size) {
  double ha = -1e300, hb = -1e300;
  for (const auto& v : a.vertices())
    ha = std::max(ha, glm::dot(d.normal, v.p));
  for (const auto& v : b.vertices())
    hb = std::max(hb, -glm::dot(d.normal, X.apply(v.p)));
  const double tol = 1e-9 * size;
  return std::abs(glm::dot(d.normal, d.point_a) - ha) <= tol &&
         std::abs(-glm::dot(d.normal, d.point_b) - hb) <= tol &&
         glm::length(d.point_a - d.point_b - d.normal * d.depth) <= tol;
}

// One step's comparison: the coherent answer `c` against the full method's `f`. Depth always
// (to rounding); normal, features and witnesses when the step was certified (then the answer is
// unique by the certificate's margin, so the full method must pick the same feature).
std::string compare(const Polytope& a,
                    const Polytope& b,
                    const Transform& X,
                    const DepthResult& c,
                    const DepthResult& f,
                    bool certified,
                    double size) {
  std::ostringstream err;
  if (!(std::abs(c.depth - f.depth) <= 1e-12 * size)) {
    err << "depth " << c.depth << " != full " << f.depth << " (certified " << certified << ")";
  } else if (certified && (c.kind != f.kind || c.ia != f.ia || c.ib != f.ib)) {
    err << "feature (" << static_cast<int>(c.kind) << ", " << c.ia << ", " << c.ib << ") != full ("
        << static_cast<int>(f.kind) << ", " << f.ia << ", " << f.ib << ")";
  } else if (certified && !(glm::length(c.normal - f.normal) <= 1e-12)) {
    err << "normal differs from the full method's by " << glm::length(c.normal - f.normal);
  } else if (certified &&
             !(glm::length(c.point_a - f.point_a) <= 1e-9 * size &&
               glm::length(c.point_b - f.point_b) <= 1e-9 * size) &&
             !witnessesValid(a, b, X, c, size)) {
    // (tied support vertices may give another witness of the same support sets)
    err << "witnesses differ from the full method's and are not in the support sets";
  }
  return err.str();
}

double inscribed(const Polytope& p) {
  double r = 1e300;
  for (const auto& f : p.faces())
    r = std::min(r, f.offset);
  return r;
}

struct PathFigures {
  std::uint64_t steps = 0, certified = 0, fallbacks = 0, cold = 0, evaluated = 0;
};

// A random path of B about A: small random turns and moves (up to 0.2 degree and 0.2 % of the
// size per step), a jump (5 degrees, 10 % of the size) every 97 steps, the centre distance
// swinging so that the pair overlaps most of the time and comes apart now and then.
PathFigures runPath(const Polytope& a,
                    const Polytope& b,
                    std::uint64_t seed,
                    std::size_t steps,
                    Failures& fails,
                    const std::string& what) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double size = pairSize(a, b);
  const double r_in = inscribed(a) + inscribed(b);
  geom::Quat q = reference::randomRotation(rng);
  Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
  DepthTracker tracker;
  tracker.reserve(a, b);
  DepthScratch scratch;
  scratch.reserve(std::max(a.faces().size(), b.faces().size()));
  DepthCache cache;
  for (std::size_t k = 0; k < steps; ++k) {
    const bool jump = k % 97 == 96;
    const double turn = (jump ? 5.0 : 0.2) * M_PI / 180.0 * std::abs(g(rng));
    q = glm::normalize(glm::angleAxis(turn, glm::normalize(Vec3{g(rng), g(rng), g(rng)})) * q);
    dir = glm::normalize(dir + Vec3{g(rng), g(rng), g(rng)} * (jump ? 0.1 : 0.002));
    const double dist = r_in * (0.75 + 0.45 * std::sin(static_cast<double>(k) * 0.02));
    const Transform X = geom::Pose{dir * dist, q}.toTransform();
    const std::uint64_t before = tracker.stats.certified;
    const DepthResult c = penetrationDepthCoherent(a, b, X, tracker, cache, scratch);
    DepthCache fresh;
    const DepthResult f = penetrationDepthExact(a, b, X, fresh, scratch);
    fails.add(what + " step " + std::to_string(k) + ": ",
              compare(a, b, X, c, f, tracker.stats.certified != before, size));
  }
  return {tracker.stats.queries, tracker.stats.certified, tracker.stats.fallbacks,
          tracker.stats.cold, tracker.stats.evaluated};
}

// Random paths at N = 8, 32, 128, 512 (the benchmark's ellipsoid hulls) and small random
// hulls, in metres and millimetres: every answer equals the full method's; on these smooth paths
// most answers are certified from the tracked state.
TEST(PenetrationCoherent, RandomPathsEqualTheFullMethod) {
  Failures fails;
  for (const std::size_t n : {8u, 32u, 128u, 512u}) {
    for (const double unit : {1.0, 1000.0}) {
      const Polytope a =
          hullOf(reference::ellipsoidPoints(n, 0.025 * unit, 0.018 * unit, 0.012 * unit, 11 + n));
      const Polytope b =
          hullOf(reference::ellipsoidPoints(n, 0.025 * unit, 0.018 * unit, 0.012 * unit, 12 + n));
      const std::string what = "N " + std::to_string(n) + (unit > 1.0 ? " mm" : " m");
      const PathFigures p = runPath(a, b, 1800 + n, n >= 512 ? 300 : 600, fails, what);
      std::printf(
          "[figures] coherent depth, %s: %llu queries, %llu certified, %llu fallbacks, %llu "
          "cold, %.1f candidates evaluated per certified answer\n",
          what.c_str(), static_cast<unsigned long long>(p.steps),
          static_cast<unsigned long long>(p.certified),
          static_cast<unsigned long long>(p.fallbacks), static_cast<unsigned long long>(p.cold),
          p.certified > 0 ? static_cast<double>(p.evaluated) / static_cast<double>(p.certified)
                          : 0.0);
      EXPECT_GT(p.certified, p.steps / 2) << what << ": the certificate fails too often";
    }
  }
  std::mt19937_64 rng(77);
  for (int pair = 0; pair < 30; ++pair) {
    const double unit = pair % 2 ? 1000.0 : 1.0;
    const Polytope a = hullOf(reference::randomPointSet(rng, 4 + rng() % 40, 0.02 * unit));
    const Polytope b = hullOf(reference::randomPointSet(rng, 4 + rng() % 40, 0.02 * unit));
    runPath(a, b, 900 + static_cast<std::uint64_t>(pair), 200, fails,
            "random pair " + std::to_string(pair));
  }
  std::fflush(stdout);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// Near-degenerate poses: aligned boxes and equal cubes turned by 1e-12 to 1e-4 rad (ties between
// faces and parallel edges everywhere), a thin slab, tetrahedra; the pair also moved apart and
// back. Every answer equals the full method's and the brute-force depth.
TEST(PenetrationCoherent, NearDegeneratePoses) {
  Failures fails;
  std::uint64_t certified = 0, steps = 0;
  for (const double unit : {1.0, 1000.0}) {
    const Polytope cube = hullOf(box(0.01 * unit, 0.01 * unit, 0.01 * unit));
    const Polytope slab = hullOf(box(0.02 * unit, 0.015 * unit, 0.001 * unit));
    const Polytope tet = hullOf(
        std::vector<Vec3>{Vec3{0.01, 0.0, -0.004} * unit, Vec3{-0.005, 0.009, -0.004} * unit,
                          Vec3{-0.005, -0.009, -0.004} * unit, Vec3{0.0, 0.0, 0.012} * unit});
    const Polytope* shapes[3] = {&cube, &slab, &tet};
    for (int ia = 0; ia < 3; ++ia) {
      for (int ib = 0; ib < 3; ++ib) {
        const Polytope& a = *shapes[ia];
        const Polytope& b = *shapes[ib];
        const double size = pairSize(a, b);
        DepthTracker tracker;
        tracker.reserve(a, b);
        DepthScratch scratch;
        scratch.reserve(std::max(a.faces().size(), b.faces().size()));
        DepthCache cache;
        for (int k = 0; k < 120; ++k) {
          // turn about a fixed axis by angles from 1e-12 to 1e-4 rad, back to exactly aligned
          // every 10 steps; the centre moves along x, from deep to apart and back
          const double angle = k % 10 == 0 ? 0.0 : std::pow(10.0, -12.0 + (k % 9));
          const Vec3 axis = glm::normalize(Vec3{1.0, 0.3 * (k % 3), 0.1});
          const double x =
              0.018 * unit * (0.3 + 0.9 * std::abs(std::sin(static_cast<double>(k) * 0.05)));
          const Transform X =
              geom::Pose{Vec3{x, 0.0005 * unit * (k % 4), 0.0}, glm::angleAxis(angle, axis)}
                  .toTransform();
          const std::uint64_t before = tracker.stats.certified;
          const DepthResult c = penetrationDepthCoherent(a, b, X, tracker, cache, scratch);
          DepthCache fresh;
          const DepthResult f = penetrationDepthExact(a, b, X, fresh, scratch);
          const std::string what = "unit " + std::to_string(unit) + " shapes " +
                                   std::to_string(ia) + "," + std::to_string(ib) + " step " +
                                   std::to_string(k) + ": ";
          fails.add(what, compare(a, b, X, c, f, tracker.stats.certified != before, size));
          if (f.depth > 1e-9 * size) {
            const double ref = reference::bruteMinkowskiDepth(a, b, X, nullptr);
            if (!(std::abs(c.depth - ref) <= kDistTol * size)) {
              fails.add(what, "depth " + std::to_string(c.depth) + " != brute force " +
                                  std::to_string(ref));
            }
          }
        }
        certified += tracker.stats.certified;
        steps += tracker.stats.queries;
      }
    }
  }
  std::printf("[figures] coherent depth, near-degenerate poses: %llu queries, %llu certified\n",
              static_cast<unsigned long long>(steps), static_cast<unsigned long long>(certified));
  std::fflush(stdout);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// Resting stacks: B on A with their facing faces exactly parallel (A's top face and B's bottom
// face give one direction and one depth: a tie), B turned about the vertical by 0, 30 and 45
// degrees (a rotated stack) and shifted sideways, the overlap breathing between 1e-6 and 1e-3 of
// the edge as a solver's resting contact does, in metres and millimetres. Every tracked query
// after the first is certified but for the few whose depths lie near an edge of the tie grid, and
// every answer equals the full method's (feature, normal, depth and witnesses within 1e-12 of
// the size) and the brute-force depth.
TEST(PenetrationCoherent, TiedStacksAreCertifiedAndEqualTheFullMethod) {
  Failures fails;
  std::uint64_t queries = 0, certified = 0, cold = 0, evaluated = 0;
  for (const double unit : {1.0, 1000.0}) {
    const Polytope cube = hullOf(box(0.05 * unit, 0.05 * unit, 0.05 * unit));
    const Polytope plank = hullOf(box(0.1 * unit, 0.03 * unit, 0.02 * unit));
    const Polytope* shapes[2] = {&cube, &plank};
    for (int ia = 0; ia < 2; ++ia) {
      for (int ib = 0; ib < 2; ++ib) {
        for (const double yaw_deg : {0.0, 30.0, 45.0}) {
          const Polytope& a = *shapes[ia];
          const Polytope& b = *shapes[ib];
          const double size = pairSize(a, b);
          // half heights: the boxes' z extents
          double ha = 0.0, hb = 0.0;
          for (const auto& v : a.vertices())
            ha = std::max(ha, v.p.z);
          for (const auto& v : b.vertices())
            hb = std::max(hb, v.p.z);
          DepthTracker tracker;
          tracker.reserve(a, b);
          DepthScratch scratch;
          scratch.reserve(std::max(a.faces().size(), b.faces().size()));
          DepthCache cache;
          const geom::Quat q = glm::angleAxis(yaw_deg * M_PI / 180.0, Vec3{0.0, 0.0, 1.0});
          for (int k = 0; k < 200; ++k) {
            const double t = static_cast<double>(k);
            const double overlap = 0.05 * unit * (1e-6 + 1e-3 * (0.5 + 0.5 * std::sin(t * 0.07)));
            const Vec3 side{0.004 * unit * std::sin(t * 0.031), 0.003 * unit * std::cos(t * 0.023),
                            0.0};
            const Transform X =
                geom::Pose{side + Vec3{0.0, 0.0, ha + hb - overlap}, q}.toTransform();
            const std::uint64_t before = tracker.stats.certified;
            const DepthResult c = penetrationDepthCoherent(a, b, X, tracker, cache, scratch);
            DepthCache fresh;
            const DepthResult f = penetrationDepthExact(a, b, X, fresh, scratch);
            const std::string what = "unit " + std::to_string(unit) + " shapes " +
                                     std::to_string(ia) + "," + std::to_string(ib) + " yaw " +
                                     std::to_string(yaw_deg) + " step " + std::to_string(k) + ": ";
            const bool cert = tracker.stats.certified != before;
            fails.add(what, compare(a, b, X, c, f, cert, size));
            if (cert && !(glm::length(c.point_a - f.point_a) <= 1e-12 * size &&
                          glm::length(c.point_b - f.point_b) <= 1e-12 * size)) {
              fails.add(what, "certified witnesses differ from the full method's");
            }
            if (!(std::abs(c.depth - overlap) <= 1e-12 * size))
              fails.add(what, "depth " + std::to_string(c.depth) + " != the overlap");
            if (!(glm::length(c.normal - Vec3{0.0, 0.0, 1.0}) <= 1e-12))
              fails.add(what, "the normal is not the stack's vertical");
          }
          queries += tracker.stats.queries;
          certified += tracker.stats.certified;
          cold += tracker.stats.cold;
          evaluated += tracker.stats.evaluated;
        }
      }
    }
  }
  std::printf(
      "[figures] coherent depth, tied stacks: %llu queries, %llu certified, %llu cold, %.1f "
      "candidates evaluated per certified answer\n",
      static_cast<unsigned long long>(queries), static_cast<unsigned long long>(certified),
      static_cast<unsigned long long>(cold),
      static_cast<double>(evaluated) / static_cast<double>(std::max<std::uint64_t>(certified, 1)));
  std::fflush(stdout);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  // the tie grid's guard band is 4 % of its cells: allow twice that
  EXPECT_GE(certified, (queries - cold) * 92 / 100);
}

// The full method breaks a tie the same way whatever its warm start: two stacked equal cubes
// (A's top face and B's bottom face at one depth) give A's face, from a cold cache and from
// caches left by other poses.
TEST(PenetrationCoherent, TheFullMethodBreaksTiesByTheGrid) {
  for (const double unit : {1.0, 1000.0}) {
    const Polytope cube = hullOf(box(0.05 * unit, 0.05 * unit, 0.05 * unit));
    DepthScratch scratch;
    DepthCache warm;
    for (int k = 0; k < 50; ++k) {
      const double t = static_cast<double>(k);
      const Transform X =
          geom::Pose{Vec3{0.01 * unit * std::sin(t), 0.01 * unit * std::cos(t * 1.3),
                          0.1 * unit - 1e-4 * unit * (1.0 + t)},
                     glm::angleAxis(0.2 * t, Vec3{0.0, 0.0, 1.0})}
              .toTransform();
      DepthCache cold;
      const DepthResult c = penetrationDepthExact(cube, cube, X, cold, scratch);
      const DepthResult w = penetrationDepthExact(cube, cube, X, warm, scratch);
      for (const DepthResult* r : {&c, &w}) {
        ASSERT_EQ(r->kind, DepthFeature::kFaceA) << "unit " << unit << " step " << k;
        EXPECT_EQ(r->ia, c.ia);
        EXPECT_NEAR(r->depth, 1e-4 * unit * (1.0 + t), 1e-12 * 0.1 * unit);
        EXPECT_NEAR(r->normal.z, 1.0, 1e-15);
      }
    }
  }
}

// A pair at rest (the same pose bit for bit, query after query) is answered with its last answer,
// which is the full method's, counted as certified and repeated; a pose one rounding step away
// is evaluated again. Two stacked equal cubes aligned (every face and edge of the contact tied)
// and turned boxes, in metres and millimetres.
TEST(PenetrationCoherent, APoseRepeatedBitForBitGetsTheSameAnswer) {
  Failures fails;
  for (const double unit : {1.0, 1000.0}) {
    const Polytope cube = hullOf(box(0.05 * unit, 0.05 * unit, 0.05 * unit));
    const Polytope plank = hullOf(box(0.1 * unit, 0.03 * unit, 0.02 * unit));
    for (const Polytope* b : {&cube, &plank}) {
      const double size = pairSize(cube, *b);
      double hb = 0.0;  // B's half height (z)
      for (const auto& v : b->vertices())
        hb = std::max(hb, v.p.z);
      const Transform poses[] = {
          // B on A, aligned, 6e-6 of the size deep: every face and edge of the contact tied
          geom::Pose{Vec3{0.0, 0.0, 0.05 * unit + hb - 6e-6 * size}, geom::Quat{1, 0, 0, 0}}
              .toTransform(),
          // turned, deep
          geom::Pose{Vec3{0.01 * unit, -0.02 * unit, 0.03 * unit},
                     glm::normalize(geom::Quat{0.9, 0.1, -0.2, 0.3})}
              .toTransform()};
      for (const Transform& X : poses) {
        const std::string what = "unit " + std::to_string(unit) +
                                 (b == &cube ? " cube" : " plank") + " z " +
                                 std::to_string(X.t.z / unit) + ": ";
        DepthTracker tracker;
        tracker.reserve(cube, *b);
        DepthScratch scratch;
        scratch.reserve(8);
        DepthCache cache;
        DepthCache fresh;
        const DepthResult f = penetrationDepthExact(cube, *b, X, fresh, scratch);
        if (!(f.depth > 0.0))
          fails.add(what, "not overlapping");
        for (int k = 0; k < 5; ++k) {
          const std::uint64_t before = tracker.stats.repeated;
          const DepthResult c = penetrationDepthCoherent(cube, *b, X, tracker, cache, scratch);
          fails.add(what + "query " + std::to_string(k) + ": ",
                    compare(cube, *b, X, c, f, true, size));
          // the first query is cold; every later one at the same pose is the last answer again
          if ((tracker.stats.repeated != before) != (k > 0))
            fails.add(what + "query " + std::to_string(k) + ": ",
                      "repeated is not counted as it should");
        }
        // a pose one rounding step away: evaluated (certified or in full), not repeated
        Transform Y = X;
        Y.t.z = std::nextafter(Y.t.z, 0.0);
        const std::uint64_t before = tracker.stats.repeated;
        const DepthResult c = penetrationDepthCoherent(cube, *b, Y, tracker, cache, scratch);
        const DepthResult g = penetrationDepthExact(cube, *b, Y, fresh, scratch);
        fails.add(what + "moved: ", compare(cube, *b, Y, c, g, false, size));
        if (tracker.stats.repeated != before)
          fails.add(what + "moved: ", "answered as repeated");
        if (tracker.stats.queries != 6 || tracker.stats.cold != 1)
          fails.add(what, "queries " + std::to_string(tracker.stats.queries) + ", cold " +
                              std::to_string(tracker.stats.cold));
      }
    }
  }
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// A reserved tracker and scratch: queries along a path allocate nothing, through the pair query
// too (PairCache::tracker).
TEST(PenetrationCoherent, NoAllocationOnceReserved) {
  const Polytope a = hullOf(reference::ellipsoidPoints(128, 0.025, 0.018, 0.012, 1));
  const Polytope b = hullOf(reference::ellipsoidPoints(128, 0.025, 0.018, 0.012, 2));
  DepthTracker tracker;
  tracker.reserve(a, b);
  DepthScratch scratch;
  scratch.reserve(std::max(a.faces().size(), b.faces().size()));
  PairCache cache;
  cache.tracker = &tracker;
  const Vec3 axis = glm::normalize(Vec3{1, 2, 3});
  std::uint64_t allocations = 0;
  for (int k = 0; k < 300; ++k) {
    const Transform X =
        geom::Pose{Vec3{0.012 * std::cos(k * 0.003), 0.008 * std::sin(k * 0.003), 0.002},
                   glm::angleAxis(k * 0.1 * M_PI / 180.0, axis)}
            .toTransform();
    const std::uint64_t before = testing_alloc::count();
    const PairResult r = queryPair(a, b, X, cache, scratch);
    allocations += testing_alloc::count() - before;
    ASSERT_EQ(r.status, ContactStatus::kPenetrating) << "step " << k;
    DepthCache fresh;
    const DepthResult f = penetrationDepthExact(a, b, X, fresh, scratch);
    ASSERT_NEAR(-r.distance, f.depth, 1e-12 * pairSize(a, b)) << "step " << k;
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(tracker.stats.certified, 150u);
}

}  // namespace
}  // namespace hapticd::collision
