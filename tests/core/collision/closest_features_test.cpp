// closestFeatures (the V-Clip walk) against the brute-force reference: random pairs of every shape
// family, every start feature, 4 to 2000 vertices. The walk must never reach its iteration cap.
#include "core/collision/closest_features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtx/quaternion.hpp>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers

void tally(const ClosestResult& c, Figures& fig) {
  ++fig.pairs;
  fig.countStatus(c.status);
}

// Every vertex-vertex and every edge-edge pair of a and b: start features for the walk.
std::vector<std::pair<Feature, Feature>> vertexAndEdgePairs(const Polytope& a, const Polytope& b) {
  std::vector<std::pair<Feature, Feature>> starts;
  for (std::uint32_t i = 0; i < a.vertices().size(); ++i) {
    for (std::uint32_t j = 0; j < b.vertices().size(); ++j)
      starts.emplace_back(Feature::vertex(i), Feature::vertex(j));
  }
  for (std::uint32_t i = 0; i < a.edges().size(); ++i) {
    for (std::uint32_t j = 0; j < b.edges().size(); ++j)
      starts.emplace_back(Feature::edge(i), Feature::edge(j));
  }
  return starts;
}

// Small hulls of every family at three unit scales, poses spread so that about a third overlap.
TEST(ClosestFeatures, RandomPairsAgainstBruteForce) {
  std::mt19937_64 rng(101);
  std::uniform_int_distribution<std::size_t> count(4, 12);
  Figures fig;
  Failures fails;
  std::size_t overlapping = 0;
  const int kPairs = 25000;
  for (int i = 0; i < kPairs; ++i) {
    const double scale = std::pow(10.0, 3.0 * static_cast<double>(i % 3) - 3.0);
    auto ra = Polytope::fromPoints(reference::randomPointSet(rng, count(rng), scale));
    auto rb = Polytope::fromPoints(reference::randomPointSet(rng, count(rng), scale));
    ASSERT_TRUE(ra.ok() && rb.ok()) << "pair " << i;
    const Transform X = randomTransform(rng, 1.0 * scale);
    const auto ref = reference::bruteForce(ra.value(), rb.value(), X);
    overlapping += ref.overlapping;
    FeatureCache cache;
    const ClosestResult c = closestFeatures(ra.value(), rb.value(), X, cache);
    const std::string err = checkClosest({ra.value(), rb.value(), X, ref}, c, fig);
    fails.add(label("pair ", i, ": "), err);
    tally(c, fig);
    // the cache holds the final pair
    ASSERT_TRUE(cache.a == c.fa && cache.b == c.fb) << "pair " << i;
  }
  fig.print("closestFeatures, random small pairs");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  std::printf("[figures] closestFeatures: %zu of %d pairs overlapping\n", overlapping, kPairs);
  EXPECT_GT(overlapping, static_cast<std::size_t>(kPairs) / 10);
  EXPECT_LT(overlapping, static_cast<std::size_t>(kPairs) * 9 / 10);
}

Feature randomFeature(std::mt19937_64& rng, const Polytope& p) {
  switch (rng() % 3) {
    case 0:
      return Feature::vertex(static_cast<std::uint32_t>(rng() % p.vertices().size()));
    case 1:
      return Feature::edge(static_cast<std::uint32_t>(rng() % p.edges().size()));
    default:
      return Feature::face(static_cast<std::uint32_t>(rng() % p.faces().size()));
  }
}

// A warm start from any feature pair (a stale cache) ends where the cold start ends.
TEST(ClosestFeatures, EveryStartGivesTheSameAnswer) {
  std::mt19937_64 rng(202);
  Figures fig;
  Failures fails;
  std::size_t starts = 0;
  for (int i = 0; i < 3000; ++i) {
    const Polytope a = hullOf(reference::randomPointSet(rng, 4 + rng() % 30, 1.0));
    const Polytope b = hullOf(reference::randomPointSet(rng, 4 + rng() % 30, 1.0));
    const Transform X = randomTransform(rng, 1.5);
    const auto ref = reference::bruteForce(a, b, X);
    for (int k = 0; k < 6; ++k) {
      FeatureCache cache{randomFeature(rng, a), randomFeature(rng, b)};
      const FeatureCache start = cache;
      const ClosestResult c = closestFeatures(a, b, X, cache);
      const std::string err = checkClosest({a, b, X, ref}, c, fig);
      fails.add(label("pair ", i, ", start ", start.a.name(), " ", start.b.name(), ": "), err);
      tally(c, fig);
      ++starts;
    }
  }
  fig.print("closestFeatures from random start features");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  std::printf("[figures] closestFeatures: %zu random starts\n", starts);
}

// Larger hulls against the full reference.
TEST(ClosestFeatures, LargerHullsAgainstBruteForce) {
  std::mt19937_64 rng(303);
  Figures fig;
  Failures fails;
  for (const std::size_t n : {16u, 32u, 64u, 150u}) {
    for (int i = 0; i < (n < 100 ? 60 : 6); ++i) {
      const Polytope a = hullOf(reference::randomPointSet(rng, n, 0.025));
      const Polytope b = hullOf(reference::randomPointSet(rng, n, 0.025));
      const Transform X = randomTransform(rng, 0.04);
      const auto ref = reference::bruteForce(a, b, X);
      FeatureCache cache;
      const ClosestResult c = closestFeatures(a, b, X, cache);
      const std::string err = checkClosest({a, b, X, ref}, c, fig);
      fails.add(label("n=", n, " pair ", i, ": "), err);
      tally(c, fig);
    }
  }
  fig.print("closestFeatures, 16..150 vertices");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// 1000 and 2000 vertices: apart (against the vertex-face/edge-edge distance) and overlapping
// (against the Minkowski-face depth: the walk must say penetration).
TEST(ClosestFeatures, ThousandsOfVertices) {
  std::mt19937_64 rng(404);
  double max_err = 0.0;
  std::uint32_t max_iter = 0;
  for (const std::size_t n : {1000u, 2000u}) {
    const Polytope a = hullOf(reference::ellipsoidPoints(n, 1.0, 0.7, 0.5, rng()));
    const Polytope b = hullOf(reference::ellipsoidPoints(n, 0.8, 0.6, 0.5, rng()));
    ASSERT_GT(a.vertices().size(), n * 9 / 10);
    ASSERT_GT(b.vertices().size(), n * 9 / 10);
    const double size = pairSize(a, b);
    for (int i = 0; i < 3; ++i) {
      // apart: B's centre beyond both radii
      const Vec3 dir = glm::normalize(Vec3{1.0, 0.3 * i, -0.2});
      const Transform far = geom::Pose{dir * (a.radius() + b.radius() + 0.01 + 0.1 * i),
                                       reference::randomRotation(rng)}
                                .toTransform();
      FeatureCache cache;
      const ClosestResult c = closestFeatures(a, b, far, cache);
      ASSERT_EQ(c.end, WalkEnd::kConverged);
      ASSERT_EQ(c.status, ContactStatus::kSeparated);
      const double ref = reference::bruteSeparatedDistance(a, b, far);
      max_err = std::max(max_err, std::abs(c.distance - ref) / size);
      ASSERT_NEAR(c.distance, ref, kDistTol * size) << "n=" << n << " pose " << i;
      max_iter = std::max(max_iter, c.iterations);
      // overlapping: centres 0.3 apart
      const Transform near = geom::Pose{dir * 0.3, reference::randomRotation(rng)}.toTransform();
      ASSERT_GT(reference::bruteMinkowskiDepth(a, b, near, nullptr), 0.0);
      FeatureCache c2;
      const ClosestResult p = closestFeatures(a, b, near, c2);
      ASSERT_EQ(p.end, WalkEnd::kPenetration) << "n=" << n << " pose " << i;
      max_iter = std::max(max_iter, p.iterations);
    }
  }
  std::printf(
      "[figures] closestFeatures, 1000 and 2000 vertices: max distance error %.3g of size, "
      "max walk iterations %u\n",
      max_err, max_iter);
}

// Touching edge pairs in the frames of the hard cases (hard_cases_test.cpp): the walk must end
// (the first of these reached its iteration cap when written).
TEST(ClosestFeatures, TouchingEdgesInEveryFrameEndBeforeTheCap) {
  const double kPi = std::numbers::pi;
  auto turned = [](std::vector<Vec3> pts, const geom::Quat& q) {
    for (auto& p : pts)
      p = q * p;
    return pts;
  };
  struct Case {
    const char* name;
    std::vector<Vec3> a, b;
    geom::Pose pose_b;
  };
  const std::vector<Case> cases = {
      {"crossed edges touching",
       turned(box(1, 1, 1), glm::angleAxis(kPi / 4, Vec3{0, 1, 0})),
       turned(box(1, 1, 1), glm::angleAxis(kPi / 4, Vec3{1, 0, 0})),
       {{0.1, 0.2, 2 * std::sqrt(2.0)}, geom::Quat{1, 0, 0, 0}}},
      {"prism side edge on side face, touching",
       prism(32, 1.0, 0.5),
       prism(32, 1.0, 0.5),
       {{1.0 + std::cos(kPi / 32), 0.0, 0.2}, glm::angleAxis(kPi / 32, Vec3{0, 0, 1})}},
  };
  const geom::Quat world_turn = glm::angleAxis(0.7, glm::normalize(Vec3{0.3, -0.5, 0.8}));
  Failures fails;
  std::uint32_t max_iter = 0;
  for (const Case& c : cases) {
    for (const double s : {1.0, 1e-3, 1e3}) {
      const Polytope a = hullOf(scaled(c.a, s)), b = hullOf(scaled(c.b, s));
      const double size = pairSize(a, b);
      for (const bool far : {false, true}) {
        for (const bool turn : {false, true}) {
          const Vec3 offset = far ? Vec3{1e4, -2e4, 0.7e4} * size : Vec3{0.0};
          const geom::Quat qa = turn ? world_turn : geom::Quat{1, 0, 0, 0};
          const Transform X = geom::relativeTransform(
              {offset, qa}, {offset + qa * (c.pose_b.translation * s), qa * c.pose_b.rotation});
          FeatureCache cache;
          const ClosestResult r = closestFeatures(a, b, X, cache);
          max_iter = std::max(max_iter, r.iterations);
          Figures fig;
          fails.add(label(c.name, ", scale ", s, far ? ", 1e4 sizes away" : ", at the origin",
                          turn ? ", turned frame" : ", axis-aligned frame"),
                    checkClosest({a, b, X, reference::bruteForce(a, b, X)}, r, fig));
        }
      }
    }
  }
  std::printf("[figures] touching edges in 24 frames: max walk iterations %u\n", max_iter);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// Two cubes with side edges parallel to within 1e-9 to 3e-6 rad, gaps from 1e-3 down to 1e-7 of
// the size (some of the tilts make them overlap), the walk started from every vertex pair and
// every edge pair (a warm cache may hold any of them): the distance falls along the edges at a
// slope too small for the derivative tests, and the walk must still end at the closest pair (it
// used to stop at the far end's vertex, 30% of a 1e-6 gap too far, or call an overlapping pair
// separated). The same starts through queryPair.
TEST(ClosestFeatures, NearlyParallelEdgesFromEveryStart) {
  const Polytope a = hullOf(box(1, 1, 1));
  Figures fig, pair_fig;
  Failures fails;
  for (const double tilt : {1e-9, 1e-8, 3e-8, 1e-7, 3e-7, 1e-6, 3e-6}) {
    for (const double gap : {1e-3, 1e-4, 1e-5, 1e-6, 3e-7, 1e-7}) {
      const double s = gap * std::sqrt(3.0) / std::sqrt(2.0);  // gap of the size, along (1, 1, 0)
      const Transform X =
          geom::Pose{{2 + s, 2 + s, 0.5}, glm::angleAxis(tilt, glm::normalize(Vec3{1, -1, 0}))}
              .toTransform();
      const reference::RefAnswer ref = reference::bruteForce(a, a, X);
      for (const auto& [fa, fb] : vertexAndEdgePairs(a, a)) {
        const std::string what =
            label("tilt ", tilt, ", gap ", gap, ", start ", fa.name(), " ", fb.name());
        FeatureCache fc{fa, fb};
        const ClosestResult c = closestFeatures(a, a, X, fc);
        tally(c, fig);
        if (fails.add(what, checkClosest({a, a, X, ref}, c, fig)))
          continue;
        PairCache pc;
        pc.features = {fa, fb};
        fails.add(what + " (queryPair)",
                  checkPairResult({a, a, X, ref}, queryPair(a, a, X, pc), pair_fig));
      }
    }
  }
  fig.print("closestFeatures, nearly parallel edges from every start");
  pair_fig.print("queryPair, nearly parallel edges from every start");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// A hexagonal prism's cap over a box's face, parallel to within 1e-9 to 1e-7 rad about a skew axis,
// gaps from 1e-3 down to 1e-7 of the size, the walk started from every vertex pair and every edge
// pair: the distance falls across the faces at a slope too small for the derivative tests, and
// the walk must still find the lowest corner of the overlap (it used to stop at an edge crossing
// elsewhere, 5.6e-10 of the size too far at a gap of 2e-4).
TEST(ClosestFeatures, NearlyParallelFacesFromEveryStart) {
  const Polytope a = hullOf(prism(6, 0.87, 1.11));
  const Polytope b = hullOf(box(0.98, 1.04, 0.42));
  const double size = pairSize(a, b);
  Figures fig;
  Failures fails;
  for (const double tilt : {1e-9, 1e-8, 1e-7}) {
    for (const double gap : {1e-3, 2e-4, 1e-5, 1e-7}) {
      const Transform X = geom::Pose{{-0.57, 0.18, -1.11 - 0.42 - gap * size},
                                     glm::angleAxis(tilt, glm::normalize(Vec3{0.35, 0.4, 0.86}))}
                              .toTransform();
      const reference::RefAnswer ref = reference::bruteForce(a, b, X);
      for (const auto& [fa, fb] : vertexAndEdgePairs(a, b)) {
        FeatureCache fc{fa, fb};
        const ClosestResult c = closestFeatures(a, b, X, fc);
        tally(c, fig);
        fails.add(label("tilt ", tilt, ", gap ", gap, ", start ", fa.name(), " ", fb.name()),
                  checkClosest({a, b, X, ref}, c, fig));
      }
    }
  }
  fig.print("closestFeatures, nearly parallel faces from every start");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

}  // namespace
}  // namespace hapticd::collision
