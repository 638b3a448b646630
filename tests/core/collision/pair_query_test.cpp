// queryPair against the brute-force reference: the bulk of the random pairs (small hulls of every
// shape family at three unit scales), larger hulls, 1000 and 2000 vertices, stale caches, and the
// same relative answer at any unit scale.
#include "core/collision/pair_query.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers

// The bulk: small hulls (4..12 input points) of every family, random poses, about a third
// overlapping. Each pair: closestFeatures and queryPair, every property (pair_checks.h).
TEST(PairQuery, RandomSmallPairsAgainstBruteForce) {
  std::mt19937_64 rng(20261124);
  std::uniform_int_distribution<std::size_t> count(4, 12);
  Figures fig;
  Failures fails;
  const int kPairs = 60000;
  for (int i = 0; i < kPairs; ++i) {
    const double scale = std::pow(10.0, 3.0 * static_cast<double>(i % 3) - 3.0);  // 1e-3, 1, 1e3
    const Polytope a = hullOf(reference::randomPointSet(rng, count(rng), scale));
    const Polytope b = hullOf(reference::randomPointSet(rng, count(rng), scale));
    const Transform X = randomTransform(rng, 1.0 * scale);
    const std::string err = checkPair(a, b, X, fig);
    fails.add(label("random pair ", i, " (seed 20261124): "), err);
  }
  fig.print("queryPair, random small pairs");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  EXPECT_EQ(fig.pairs, static_cast<std::size_t>(kPairs));
  EXPECT_GT(fig.separated, static_cast<std::size_t>(kPairs) / 10);
  EXPECT_GT(fig.penetrating, static_cast<std::size_t>(kPairs) / 10);
}

TEST(PairQuery, LargerHullsAgainstBruteForce) {
  std::mt19937_64 rng(7);
  Figures fig;
  Failures fails;
  for (const std::size_t n : {16u, 32u, 64u}) {
    for (int i = 0; i < 100; ++i) {
      const Polytope a = hullOf(reference::randomPointSet(rng, n, 0.025));
      const Polytope b = hullOf(reference::randomPointSet(rng, n, 0.02));
      const Transform X = randomTransform(rng, 0.03);
      const std::string err = checkPair(a, b, X, fig);
      fails.add(label("n=", n, " pair ", i, ": "), err);
    }
  }
  fig.print("queryPair, 16..64 input points");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// 1000 and 2000 vertices against the large-hull references: apart, the distance and a normal
// along which the gap is the distance; overlapping, the depth and a normal along which it is.
TEST(PairQuery, ThousandsOfVertices) {
  std::mt19937_64 rng(3);
  double max_err = 0.0;
  for (const std::size_t n : {1000u, 2000u}) {
    const Polytope a = hullOf(reference::ellipsoidPoints(n, 1.0, 0.7, 0.5, 1));
    const Polytope b = hullOf(reference::ellipsoidPoints(n, 0.8, 0.8, 0.4, 2));
    ASSERT_GT(a.vertices().size(), n * 9 / 10);
    const double size = pairSize(a, b);
    const double tol = kDistTol * size;
    for (int i = 0; i < 3; ++i) {
      const Vec3 dir = glm::normalize(Vec3{1.0, 0.4 * i - 0.3, 0.2 * i});
      for (const bool apart : {true, false}) {
        const Transform X = geom::Pose{dir * (apart ? 1.85 + 0.05 * i : 0.9 - 0.2 * i),
                                       reference::randomRotation(rng)}
                                .toTransform();
        PairCache cache;
        const PairResult r = queryPair(a, b, X, cache);
        ASSERT_TRUE(std::isfinite(r.distance) && finite(r.normal) && finite(r.point_a) &&
                    finite(r.point_b));
        const double ref = apart ? reference::bruteSeparatedDistance(a, b, X)
                                 : -reference::bruteMinkowskiDepth(a, b, X, nullptr);
        ASSERT_EQ(r.status, statusOf(ref, size)) << "n=" << n << " pose " << i;
        max_err = std::max(max_err, std::abs(r.distance - ref) / size);
        ASSERT_NEAR(r.distance, ref, tol) << "n=" << n << " pose " << i;
        ASSERT_NEAR(reference::bruteDepthAlong(a, b, X, r.normal), -r.distance, tol);
        ASSERT_LE(glm::length(r.point_b - r.point_a - r.normal * r.distance), tol);
        ASSERT_LE(std::abs(outside(a, Transform{}, r.point_a)), tol);
        ASSERT_LE(std::abs(outside(b, X, r.point_b)), tol);
        FeatureCache fc;
        ASSERT_NE(closestFeatures(a, b, X, fc).end, WalkEnd::kIterationCap);
      }
    }
  }
  std::printf(
      "[figures] queryPair, 1000 and 2000 vertices: 12 pairs, max distance error %.3g of "
      "size\n",
      max_err);
}

// A cache left by an unrelated pose (a teleport) gives the cold answer.
TEST(PairQuery, StaleCacheGivesTheColdAnswer) {
  std::mt19937_64 rng(44);
  Figures fig;
  Failures fails;
  std::size_t compared = 0;
  for (int i = 0; i < 1500; ++i) {
    const Polytope a = hullOf(reference::randomPointSet(rng, 4 + rng() % 30, 1.0));
    const Polytope b = hullOf(reference::randomPointSet(rng, 4 + rng() % 30, 1.0));
    const double size = pairSize(a, b);
    PairCache warm;
    for (int k = 0; k < 5; ++k) {
      const Transform X = randomTransform(rng, 1.0);
      const PairResult w = queryPair(a, b, X, warm);
      PairCache fresh;
      const PairResult c = queryPair(a, b, X, fresh);
      ASSERT_EQ(w.status, c.status) << "pair " << i << " pose " << k << "\n" << describe(a, b, X);
      ASSERT_NEAR(w.distance, c.distance, kDistTol * size) << "pair " << i << " pose " << k;
      if (w.status == ContactStatus::kSeparated) {
        ASSERT_LE(angle(w.normal, c.normal), kAngleTol) << "pair " << i << " pose " << k;
      }
      if (k == 4) {
        const std::string err = checkPairResult({a, b, X, reference::bruteForce(a, b, X)}, w, fig);
        fails.add(label("pair ", i, ": "), err);
      }
      ++compared;
    }
  }
  fig.print("queryPair with stale caches (last pose vs reference)");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  std::printf("[figures] stale caches: %zu answers equal to cold starts\n", compared);
}

// The same pair in millimetres, metres and kilometres: the same answer relative to size.
TEST(PairQuery, UnitScaleInvariance) {
  std::mt19937_64 rng(12);
  double max_dev = 0.0;
  for (int i = 0; i < 600; ++i) {
    const auto pa = reference::randomPointSet(rng, 4 + rng() % 20, 1.0);
    const auto pb = reference::randomPointSet(rng, 4 + rng() % 20, 1.0);
    const Transform X = randomTransform(rng, 1.0);
    PairResult base;
    double base_size = 1.0;
    for (const double s : {1.0, 1e-3, 1e3}) {
      const Polytope a = hullOf(scaled(pa, s)), b = hullOf(scaled(pb, s));
      PairCache c;
      const PairResult r = queryPair(a, b, Transform{X.R, X.t * s}, c);
      if (s == 1.0) {
        base = r;
        base_size = pairSize(a, b);
        continue;
      }
      max_dev = std::max(max_dev, std::abs(r.distance / s - base.distance) / base_size);
      ASSERT_EQ(r.status, base.status) << "pair " << i << " scale " << s;
      ASSERT_NEAR(r.distance / s, base.distance, kDistTol * base_size)
          << "pair " << i << " scale " << s;
      if (r.status == ContactStatus::kSeparated) {
        ASSERT_LE(angle(r.normal, base.normal), kAngleTol) << "pair " << i << " scale " << s;
      }
      ASSERT_EQ(r.manifold.count, base.manifold.count) << "pair " << i << " scale " << s;
    }
  }
  std::printf("[figures] unit scales 1e-3, 1e3 vs 1: 600 pairs, max relative deviation %.3g\n",
              max_dev);
}

}  // namespace
}  // namespace hapticd::collision
