// Contact manifolds: the shapes the issue names (face on face 4 points, edge on face 2, vertex on
// face 1, parallel edges their overlap segment, crossed edges 1), separated, touching and
// penetrating, with the points where they must be; at most kMaxPoints with the deepest kept; the
// invariants on random pairs of boxes and prisms (parallel features everywhere).
#include "core/collision/manifold.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtx/quaternion.hpp>
#include <numbers>
#include <random>

#include "core/collision/pair_query.h"
#include "core/collision/penetration.h"
#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers
using geom::Quat;

const Quat kIdentity{1.0, 0.0, 0.0, 0.0};
const double kSqrt2 = std::sqrt(2.0);
const double kSqrt3 = std::sqrt(3.0);

// queryPair's cold answer on (a, b, X), after every property of checkPair holds for it
PairResult checkedQuery(const Polytope& a, const Polytope& b, const Transform& X) {
  Figures fig;
  const std::string err = checkPair(a, b, X, fig);
  EXPECT_TRUE(err.empty()) << err;
  PairCache cache;
  return queryPair(a, b, X, cache);
}

struct Expected {
  std::vector<Vec3> points;  // contact points, A's frame
  double depth;              // every point's depth
};

// queryPair on (a, b, X), then: every property of checkPair, the status the gap implies, the
// expected points (any order), each with the expected depth.
void expectManifold(const Polytope& a,
                    const Polytope& b,
                    const Transform& X,
                    double gap,
                    const Expected& want,
                    const std::string& label) {
  SCOPED_TRACE(label);
  const PairResult r = checkedQuery(a, b, X);
  const ContactStatus status = gap > 0.0   ? ContactStatus::kSeparated
                               : gap < 0.0 ? ContactStatus::kPenetrating
                                           : ContactStatus::kTouching;
  EXPECT_EQ(r.status, status) << name(r.status);
  const double tol = 1e-9 * pairSize(a, b);
  ASSERT_EQ(static_cast<std::size_t>(r.manifold.count), want.points.size());
  for (const Vec3& p : want.points) {
    bool found = false;
    for (std::size_t i = 0; i < r.manifold.count && !found; ++i) {
      const ContactPoint& c = r.manifold.points[i];
      found = glm::length(c.point - p) <= tol && std::abs(c.depth - want.depth) <= tol;
    }
    std::string got;
    for (std::size_t i = 0; i < r.manifold.count; ++i) {
      const ContactPoint& c = r.manifold.points[i];
      got += " (" + std::to_string(c.point.x) + ", " + std::to_string(c.point.y) + ", " +
             std::to_string(c.point.z) + "; depth " + std::to_string(c.depth) + ")";
    }
    EXPECT_TRUE(found) << "missing contact (" << p.x << ", " << p.y << ", " << p.z << "), depth "
                       << want.depth << "; got" << got;
  }
}

const double kGaps[] = {0.01, 1e-7, 0.0, -0.01};

std::string gapName(double g) {
  return label(" gap ", g);
}

TEST(Manifold, FaceOnFaceGivesTheOverlapRectangle) {
  const Polytope a = hullOf(box(1, 1, 1));
  const Polytope b = hullOf(box(0.5, 0.5, 0.5));
  for (const double g : kGaps) {
    const Transform X = geom::Pose{{0.8, 0.7, 1.5 + g}, kIdentity}.toTransform();
    const double z = 1.0 + g / 2;
    expectManifold(a, b, X, g, {{{0.3, 0.2, z}, {1, 0.2, z}, {0.3, 1, z}, {1, 1, z}}, -g},
                   "face on face" + gapName(g));
  }
  // B turned about the normal: the overlap polygon has more corners, reduced to 4 at one depth
  for (const double g : kGaps) {
    const Transform X =
        geom::Pose{{0.8, 0.7, 1.5 + g}, glm::angleAxis(0.5, Vec3{0, 0, 1})}.toTransform();
    PairCache cache;
    const PairResult r = queryPair(a, b, X, cache);
    EXPECT_EQ(r.manifold.count, 4) << gapName(g);
    for (std::size_t i = 0; i < r.manifold.count; ++i) {
      EXPECT_NEAR(r.manifold.points[i].depth, -g, 1e-12) << gapName(g);
      EXPECT_NEAR(r.manifold.points[i].point.z, 1.0 + g / 2, 1e-12) << gapName(g);
    }
  }
}

TEST(Manifold, EdgeOnFaceGivesTwoPoints) {
  const Polytope a = hullOf(box(1, 1, 1));
  const Polytope b = hullOf(box(0.5, 0.5, 0.5));
  const Quat q = glm::angleAxis(std::numbers::pi / 4, Vec3{1, 0, 0});  // an edge along x, down
  for (const double g : kGaps) {
    const Transform X = geom::Pose{{0.8, 0.2, 1.0 + 0.5 * kSqrt2 + g}, q}.toTransform();
    const double z = 1.0 + g / 2;
    // the edge spans x in [0.3, 1.3]; A's face ends at x = 1
    expectManifold(a, b, X, g, {{{0.3, 0.2, z}, {1.0, 0.2, z}}, -g}, "edge on face" + gapName(g));
  }
}

TEST(Manifold, VertexOnFaceGivesOnePoint) {
  const Polytope a = hullOf(box(1, 1, 1));
  const Polytope b = hullOf(box(0.5, 0.5, 0.5));
  const Quat q = glm::rotation(glm::normalize(Vec3{-1, -1, -1}), Vec3{0, 0, -1});
  for (const double g : kGaps) {
    const Transform X = geom::Pose{{0.2, 0.1, 1.0 + 0.5 * kSqrt3 + g}, q}.toTransform();
    expectManifold(a, b, X, g, {{{0.2, 0.1, 1.0 + g / 2}}, -g}, "vertex on face" + gapName(g));
  }
}

// A face resting on a face, tilted by rounding (1e-9 rad) and lowered until its lowest corner is
// 1e-13 into the other: a pair the query calls touching. Answered from its depth, the manifold
// kept penetrating points only, the one corner; as touching it keeps the face's four, as a
// touching pair answered by the walk does (a box sliding onto the next of two flush tiles was
// held by one corner and tipped over it: docs/collision-pipeline.md "Flush seams")
TEST(Manifold, AFaceTiltedByRoundingTouchingKeepsItsPoints) {
  const Polytope a = hullOf(box(1, 1, 1));
  const Polytope b = hullOf(box(0.5, 0.5, 0.5));
  const Quat q = glm::angleAxis(1e-9, glm::normalize(Vec3{1, 2, 0}));
  geom::Pose pose{{0.3, 0.4, 1.5}, q};
  double lowest = 1e300;
  for (const auto& v : b.vertices())
    lowest = std::min(lowest, pose.toTransform().apply(v.p).z);
  pose.translation.z += 1.0 - 1e-13 - lowest;
  const Transform X = pose.toTransform();
  DepthCache cache;
  const DepthResult d = penetrationDepth(a, b, X, cache);
  ASSERT_NEAR(d.depth, 1e-13, 1e-15);
  ASSERT_NEAR(d.normal.z, 1.0, 1e-12);
  ManifoldOptions touching;
  touching.touching = true;
  const Manifold kept = manifoldFromDepth(a, b, X, d, touching);
  EXPECT_EQ(kept.count, 4);
  for (std::size_t i = 0; i < kept.count; ++i) {
    EXPECT_NEAR(kept.points[i].point.z, 1.0, 1e-8);
    EXPECT_GE(kept.points[i].depth, -1e-6 * pairSize(a, b));
    EXPECT_LE(kept.points[i].depth, d.depth);
  }
  // penetrating pairs keep their penetrating points only
  EXPECT_EQ(manifoldFromDepth(a, b, X, d).count, 1);
}

// Parallel edges: the overlap segment, also turned to a general orientation.
TEST(Manifold, ParallelEdgesGiveTheOverlapSegment) {
  std::mt19937_64 rng(17);
  for (int turn = 0; turn < 6; ++turn) {
    const Quat Q = turn == 0 ? kIdentity : reference::randomRotation(rng);
    std::vector<Vec3> pts = box(1, 1, 1);
    for (auto& p : pts)
      p = Q * p;
    const Polytope a = hullOf(pts);
    for (const double g : {0.01, 1e-7, 0.0}) {
      const double s = g / kSqrt2;
      const Transform X = geom::Pose{Q * Vec3{2 + s, 2 + s, 0.5}, kIdentity}.toTransform();
      expectManifold(
          a, a, X, g,
          {{Q * Vec3{1 + s / 2, 1 + s / 2, -0.5}, Q * Vec3{1 + s / 2, 1 + s / 2, 1.0}}, -g},
          "parallel edges, turn " + std::to_string(turn) + gapName(g));
    }
  }
}

TEST(Manifold, CrossedEdgesGiveOnePoint) {
  std::vector<Vec3> pa = box(1, 1, 1), pb = box(1, 1, 1);
  for (auto& p : pa)
    p = glm::angleAxis(std::numbers::pi / 4, Vec3{0, 1, 0}) * p;  // top edge along y
  for (auto& p : pb)
    p = glm::angleAxis(std::numbers::pi / 4, Vec3{1, 0, 0}) * p;  // bottom edge along x
  const Polytope a = hullOf(pa), b = hullOf(pb);
  for (const double g : kGaps) {
    const Transform X = geom::Pose{{0.1, 0.2, 2 * kSqrt2 + g}, kIdentity}.toTransform();
    expectManifold(a, b, X, g, {{{0.0, 0.2, kSqrt2 + g / 2}}, -g}, "crossed edges" + gapName(g));
  }
}

// A 12-gon cap on a face: 12 candidate points reduced to kMaxPoints, the deepest kept.
TEST(Manifold, ManyCornersReducedToFourKeepingTheDeepest) {
  const Polytope a = hullOf(box(1, 1, 1));
  std::vector<Vec3> pts = prism(12, 1.0, 0.5);
  for (auto& p : pts)
    p.z += 0.5;  // the cap at z = 0, centre of the cap at the origin
  const Polytope b = hullOf(pts);
  // tilted by t about x: the cap's lowest corner is (0, -1, 0) turned, at z = -sin(t)
  for (const auto& [tilt, gap] : {std::pair{1e-3, -0.01}, std::pair{1e-7, 0.01}}) {
    SCOPED_TRACE(label("tilt ", tilt, gapName(gap)));
    const Transform X =
        geom::Pose{{0.0, 0.0, 1.0 + gap}, glm::angleAxis(tilt, Vec3{1, 0, 0})}.toTransform();
    const PairResult r = checkedQuery(a, b, X);
    // separated: the lowest corner over A's face; penetrating: the minimal translation is along
    // the cap's normal (shallower than along z), its deepest point over the same corner
    const double deepest_depth =
        gap > 0.0 ? std::sin(tilt) - gap : std::sin(tilt) - gap * std::cos(tilt);
    EXPECT_NEAR(r.distance, -deepest_depth, 1e-12);
    ASSERT_EQ(static_cast<std::size_t>(r.manifold.count), Manifold::kMaxPoints);
    bool kept = false;
    for (std::size_t i = 0; i < r.manifold.count; ++i) {
      const ContactPoint& c = r.manifold.points[i];
      EXPECT_LE(c.depth, deepest_depth + 1e-12);
      kept = kept || (std::abs(c.depth - deepest_depth) <= 1e-12 &&
                      glm::length(Vec3{c.point.x, c.point.y + 1.0, 0.0}) <= 1e-3);
    }
    EXPECT_TRUE(kept) << "the deepest corner is not in the manifold";
    // the four points are spread: their hull covers much of the cap
    double max_sep = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
      for (std::size_t j = 0; j < 4; ++j) {
        max_sep =
            std::max(max_sep, glm::length(r.manifold.points[i].point - r.manifold.points[j].point));
      }
    }
    EXPECT_GT(max_sep, 1.5);
  }
}

// Boxes and prisms in random and nearly axis-aligned poses: every manifold invariant.
TEST(Manifold, InvariantsOnBoxesAndPrisms) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Figures fig;
  Failures fails;
  for (int i = 0; i < 4000; ++i) {
    auto shape = [&]() {
      switch (rng() % 3) {
        case 0:
          return box(0.2 + u(rng), 0.2 + u(rng), 0.2 + u(rng));
        case 1:
          return prism(3 + static_cast<int>(rng() % 10), 0.2 + u(rng), 0.2 + u(rng));
        default:
          return box(1.0, 1.0, 1e-3 + 1e-2 * u(rng));  // a plate
      }
    };
    const Polytope a = hullOf(shape()), b = hullOf(shape());
    // a third nearly axis-aligned (parallel faces and edges, turned by 0 or 1e-9 rad)
    Quat q = reference::randomRotation(rng);
    if (i % 3 == 0)
      q = glm::angleAxis(i % 2 ? 1e-9 : 0.0, glm::normalize(Vec3{u(rng), u(rng), 1.0}));
    std::normal_distribution<double> g(0.0, 1.0);
    const Transform X = geom::Pose{Vec3{g(rng), g(rng), g(rng)} * 1.2, q}.toTransform();
    const std::string err = checkPair(a, b, X, fig);
    fails.add(label("pair ", i, ": "), err);
  }
  fig.print("manifold invariants, boxes and prisms");
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  EXPECT_GT(fig.manifold_sizes[4], 100u);
  EXPECT_GT(fig.manifold_sizes[2], 100u);
}

}  // namespace
}  // namespace hapticd::collision
