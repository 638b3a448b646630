// The hard cases, each checked against the brute-force reference and, where the geometry gives
// it, against the exact expected distance: parallel faces (turned by 0 and 1e-9 rad), parallel
// edges, exact touching, gaps of 1e-7 of the size, identical and nested hulls, slivers of aspect
// 1e4, 4 to 2000 vertices. Every case runs at unit scales 1e-3, 1 and 1e3, with A's frame at the
// world origin or 1e4 sizes away, axis-aligned or turned, and must give the same relative answer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtx/quaternion.hpp>
#include <numbers>
#include <optional>
#include <random>

#include "core/collision/pair_query.h"
#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers
using geom::Pose;
using geom::Quat;

const Quat kI{1.0, 0.0, 0.0, 0.0};
const double kSqrt2 = std::sqrt(2.0);
const double kSqrt3 = std::sqrt(3.0);
const double kPi = std::numbers::pi;

Quat turn(double rad, const Vec3& axis) {
  return glm::angleAxis(rad, glm::normalize(axis));
}

std::vector<Vec3> rotated(std::vector<Vec3> pts, const Quat& q) {
  for (auto& p : pts)
    p = q * p;
  return pts;
}

struct HardCase {
  std::string name;
  std::vector<Vec3> a, b;
  Pose pose_b;  ///< B in A's frame, at scale 1
  /// Expected signed distance at scale 1, when the geometry gives it exactly.
  std::optional<double> expect;
  /// Expected status, when it is part of the case.
  std::optional<ContactStatus> status;
  /// Tolerance on `expect`, relative to the size (the default: the distance tolerance).
  double expect_tol = kDistTol;
};

// The case with the largest distance error against the reference so far.
std::string& worst_distance_case() {
  static std::string label;
  return label;
}

// One case in 12 frames: scale x (A's frame at the origin or 1e4 sizes away) x (axis-aligned or
// turned world frame). B's world pose composes A's with pose_b; X_AB comes from
// geom::relativeTransform, as the daemon computes it.
void runCase(const HardCase& h,
             Figures& fig,
             Failures& fails,
             double& max_expect_err,
             double& max_frame_dev,
             bool all_frames = true) {
  const Quat world_turn = turn(0.7, {0.3, -0.5, 0.8});
  std::optional<PairResult> base;
  double base_size = 0.0;
  bool base_normal_unique = false;
  for (const double s : {1.0, 1e-3, 1e3}) {
    const Polytope a = hullOf(scaled(h.a, s));
    const Polytope b = hullOf(scaled(h.b, s));
    const double size = pairSize(a, b);
    for (const bool far : {false, true}) {
      for (const bool turned : {false, true}) {
        // the large hulls: the first frame and the most distant one only (reference time)
        if (!all_frames && !(s == 1.0 && !far && !turned) && !(s == 1e3 && far && turned))
          continue;
        const Vec3 offset = far ? Vec3{1e4, -2e4, 0.7e4} * size : Vec3{0.0};
        const Quat qa = turned ? world_turn : kI;
        const Pose X_WA{offset, qa};
        const Pose X_WB{offset + qa * (h.pose_b.translation * s), qa * h.pose_b.rotation};
        const Transform X_AB = geom::relativeTransform(X_WA, X_WB);
        const std::string label = h.name + ", scale " + checks::label(s) +
                                  (far ? ", 1e4 sizes away" : ", at the origin") +
                                  (turned ? ", turned frame" : ", axis-aligned frame");
        SCOPED_TRACE(label);
        if (h.expect) {
          // the reference itself against the exact answer
          const double ref_err =
              std::abs(reference::bruteForce(a, b, X_AB).signed_distance / s - *h.expect) /
              (size / s);
          EXPECT_LE(ref_err, h.expect_tol) << "the reference is off the exact distance";
        }
        const double before = fig.max_dist_err;
        fails.add(label, checkPair(a, b, X_AB, fig));
        if (fig.max_dist_err > before)
          worst_distance_case() = label;
        PairCache cache;
        const PairResult r = queryPair(a, b, X_AB, cache);
        if (h.expect) {
          const double e = std::abs(r.distance / s - *h.expect) / (size / s);
          max_expect_err = std::max(max_expect_err, e);
          EXPECT_LE(e, h.expect_tol)
              << "distance " << r.distance / s << " at scale 1, expected " << *h.expect;
        }
        if (h.status) {
          EXPECT_EQ(name(r.status), name(*h.status));
        }
        // the same relative answer in every frame
        if (!base) {
          base = r;
          base_size = size / s;
          base_normal_unique =
              r.status == ContactStatus::kSeparated || axisMargin(a, b, X_AB).unique(size);
          continue;
        }
        const double dev = std::abs(r.distance / s - base->distance);
        max_frame_dev = std::max(max_frame_dev, dev / base_size);
        EXPECT_LE(dev, kDistTol * base_size)
            << "distance " << r.distance / s << " vs " << base->distance << " in the first frame";
        EXPECT_TRUE(statusAcceptable(r.status, base->distance, base_size))
            << name(r.status) << " vs " << name(base->status) << " in the first frame";
        // (1e4 sizes away the input itself moves by ~1e-12 of the size in relativeTransform,
        // which turns the normal of a 1e-7 gap by ~1e-5 rad: there the normal is checked against
        // the reference on the same input only)
        if (!far && base_normal_unique && r.status == base->status) {
          EXPECT_LE(angle(r.normal, base->normal), kAngleTol)
              << "normal differs from the first frame";
        }
      }
    }
  }
}

std::vector<HardCase> hardCases() {
  const auto cube = box(1, 1, 1);
  const auto sliver = box(1, 1e-4, 1e-4);  // aspect 1e4
  const auto plate = box(1, 1, 1e-4);
  const Quat vertex_down = glm::rotation(glm::normalize(Vec3{-1, -1, -1}), Vec3{0, 0, -1});
  const Quat edge_down = turn(kPi / 4, {1, 0, 0});  // a cube edge along x, pointing down
  const auto tilted_y = rotated(cube, turn(kPi / 4, {0, 1, 0}));  // top edge along y at z = sqrt2
  const auto tilted_x = rotated(cube, turn(kPi / 4, {1, 0, 0}));  // bottom edge along x at -sqrt2
  const double g7 = 1e-7 * kSqrt3;                                // 1e-7 of the cube's size
  using CS = ContactStatus;
  std::vector<HardCase> c = {
      // parallel faces
      {"faces 0.1 apart", cube, cube, {{2.1, 0.3, 0.2}, kI}, 0.1, CS::kSeparated},
      {"faces 0.1 apart, B turned 1e-9 about z",
       cube,
       cube,
       {{2.1, 0.3, 0.2}, turn(1e-9, {0, 0, 1})},
       0.1,
       CS::kSeparated,
       2e-9},
      {"faces 0.1 apart, B turned 1e-9 about a skew axis",
       cube,
       cube,
       {{2.1, 0.3, 0.2}, turn(1e-9, {0.3, 1, 0.5})},
       0.1,
       CS::kSeparated,
       2e-9},
      {"faces 0.1 apart, B turned 0.3 about the normal",
       cube,
       cube,
       {{2.1, 0.3, 0.2}, turn(0.3, {1, 0, 0})},
       0.1,
       CS::kSeparated},
      {"faces touching", cube, cube, {{2.0, 0.3, 0.2}, kI}, 0.0, CS::kTouching},
      {"faces touching, B turned 0.3 about the normal",
       cube,
       cube,
       {{2.0, 0.3, 0.2}, turn(0.3, {1, 0, 0})},
       0.0,
       CS::kTouching},
      {"faces touching edge to edge", cube, cube, {{2.0, 0.0, 0.0}, kI}, 0.0, CS::kTouching},
      {"faces touching, B turned 1e-9 about z",
       cube,
       cube,
       {{2.0, 0.3, 0.2}, turn(1e-9, {0, 0, 1})},
       std::nullopt,
       std::nullopt},
      {"faces penetrating 0.01", cube, cube, {{1.99, 0.3, 0.2}, kI}, -0.01, CS::kPenetrating},
      {"faces penetrating 0.01, B turned 1e-9",
       cube,
       cube,
       {{1.99, 0.3, 0.2}, turn(1e-9, {0.2, 1, 0.1})},
       -0.01,
       CS::kPenetrating,
       2e-9},
      {"box on box, different sizes",
       cube,
       box(0.4, 0.3, 0.2),
       {{0.5, -0.6, 1.2 + 1e-3}, kI},
       1e-3,
       CS::kSeparated},
      // parallel edges
      {"parallel edges 1e-3 apart",
       cube,
       cube,
       {{2.001, 2.001, 0.5}, kI},
       0.001 * kSqrt2,
       CS::kSeparated},
      {"parallel edges touching", cube, cube, {{2.0, 2.0, 0.5}, kI}, 0.0, CS::kTouching},
      {"parallel edges penetrating",
       cube,
       cube,
       {{1.999, 1.999, 0.5}, kI},
       -0.001,
       CS::kPenetrating},
      {"parallel edges 1e-7 of the size apart",
       cube,
       cube,
       {{2.0 + g7 / kSqrt2, 2.0 + g7 / kSqrt2, 0.5}, kI},
       g7,
       CS::kSeparated},
      {"nearly parallel edges (1e-9 rad)",
       cube,
       cube,
       {{2.001, 2.001, 0.5}, turn(1e-9, {1, -1, 0})},
       0.001 * kSqrt2,
       CS::kSeparated,
       2e-9},
      {"nearly parallel edges (1e-8 rad)",
       cube,
       cube,
       {{2.001, 2.001, 0.5}, turn(1e-8, {1, -1, 0})},
       std::nullopt,
       CS::kSeparated},
      {"nearly parallel edges (1e-7 rad)",
       cube,
       cube,
       {{2.001, 2.001, 0.5}, turn(1e-7, {1, -1, 0})},
       std::nullopt,
       CS::kSeparated},
      {"nearly parallel edges (1e-6 rad)",
       cube,
       cube,
       {{2.001, 2.001, 0.5}, turn(1e-6, {1, -1, 0})},
       std::nullopt,
       CS::kSeparated},
      {"edge on face, touching",
       cube,
       cube,
       {{0.3, 0.2, 1.0 + kSqrt2}, edge_down},
       0.0,
       CS::kTouching},
      {"edge on face, 1e-7 of the size apart",
       cube,
       cube,
       {{0.3, 0.2, 1.0 + kSqrt2 + g7}, edge_down},
       g7,
       CS::kSeparated},
      // vertices and crossed edges
      {"vertex on face, touching",
       cube,
       cube,
       {{0.2, 0.1, 1.0 + kSqrt3}, vertex_down},
       0.0,
       CS::kTouching},
      {"vertex on face, 1e-7 of the size apart",
       cube,
       cube,
       {{0.2, 0.1, 1.0 + kSqrt3 + g7}, vertex_down},
       g7,
       CS::kSeparated},
      {"vertex on vertex, touching", cube, cube, {{2.0, 2.0, 2.0}, kI}, 0.0, CS::kTouching},
      {"vertex into a corner",
       cube,
       cube,
       {{1.0 + kSqrt3 - 1e-3, 1.0, 1.0},
        glm::rotation(glm::normalize(Vec3{-1, -1, -1}), Vec3{-1, 0, 0})},
       std::nullopt,
       CS::kPenetrating},
      {"crossed edges touching",
       tilted_y,
       tilted_x,
       {{0.1, 0.2, 2 * kSqrt2}, kI},
       0.0,
       CS::kTouching},
      {"crossed edges 1e-7 of the size apart",
       tilted_y,
       tilted_x,
       {{0.1, 0.2, 2 * kSqrt2 + g7}, kI},
       g7,
       CS::kSeparated},
      {"crossed edges penetrating",
       tilted_y,
       tilted_x,
       {{0.1, 0.2, 2 * kSqrt2 - 0.01}, kI},
       -0.01,
       CS::kPenetrating},
      {"faces 1e-7 of the size apart", cube, cube, {{2.0 + g7, 0.3, 0.2}, kI}, g7, CS::kSeparated},
      {"faces 1e-7 apart, B turned 0.3 about x",
       cube,
       cube,
       {{2.0 + 1e-7, 0.1, 0.0}, turn(0.3, {1, 0, 0})},
       1e-7,
       CS::kSeparated},
      // identical and nested
      {"identical cubes", cube, cube, {{0, 0, 0}, kI}, -2.0, CS::kPenetrating},
      {"identical cubes, turned together",
       rotated(cube, turn(0.4, {1, 2, 3})),
       rotated(cube, turn(0.4, {1, 2, 3})),
       {{0, 0, 0}, kI},
       -2.0,
       CS::kPenetrating},
      {"identical ellipsoids",
       reference::ellipsoidPoints(64, 1.0, 0.7, 0.5, 5),
       reference::ellipsoidPoints(64, 1.0, 0.7, 0.5, 5),
       {{0, 0, 0}, kI},
       std::nullopt,
       CS::kPenetrating},
      {"nested box, axis-aligned",
       cube,
       box(0.3, 0.2, 0.1),
       {{0.5, 0, 0}, kI},
       -0.8,
       CS::kPenetrating},
      {"nested box, turned",
       cube,
       box(0.3, 0.2, 0.1),
       {{0.1, 0, 0}, turn(0.2, {1, 2, 3})},
       std::nullopt,
       CS::kPenetrating},
      {"nested sliver",
       cube,
       sliver,
       {{0.0, 0.3, -0.2}, turn(0.5, {0, 0, 1})},
       std::nullopt,
       CS::kPenetrating},
      {"nested tetrahedron at the centre",
       cube,
       {{0.1, 0.1, 0.1}, {-0.1, -0.1, 0.1}, {-0.1, 0.1, -0.1}, {0.1, -0.1, -0.1}},
       {{0, 0, 0}, kI},
       std::nullopt,
       CS::kPenetrating},
      // slivers of aspect 1e4
      {"sliver 0.01 over a cube",
       cube,
       sliver,
       {{0.3, 1.0 + 1e-4 + 0.01, 0}, turn(0.4, {0, 1, 0})},
       0.01,
       CS::kSeparated},
      {"sliver touching a cube",
       cube,
       sliver,
       {{0.3, 1.0 + 1e-4, 0}, turn(0.4, {0, 1, 0})},
       0.0,
       CS::kTouching},
      {"sliver crossing a sliver",
       sliver,
       sliver,
       {{0, 0, 3e-4}, turn(1.0, {0, 0, 1})},
       1e-4,
       CS::kSeparated},
      {"sliver touching a sliver",
       sliver,
       sliver,
       {{0, 0, 2e-4}, turn(1.0, {0, 0, 1})},
       0.0,
       CS::kTouching},
      {"sliver into a sliver",
       sliver,
       sliver,
       {{0, 0, 1.5e-4}, turn(1.0, {0, 0, 1})},
       -0.5e-4,
       CS::kPenetrating},
      {"slivers side by side 1e-7 apart",
       sliver,
       sliver,
       {{0.5, 2e-4 + 1e-7, 0}, kI},
       1e-7,
       CS::kSeparated},
      {"slivers side by side, turned 1e-9",
       sliver,
       sliver,
       {{0.5, 2e-4 + 1e-7, 0}, turn(1e-9, {0, 0, 1})},
       1e-7,
       CS::kSeparated,
       2e-9},
      {"plate on plate 1e-7 apart, turned 1e-9",
       plate,
       plate,
       {{0.3, 0.2, 2e-4 + 1e-7}, turn(1e-9, {1, 1, 0})},
       1e-7,
       CS::kSeparated,
       2e-9},
      {"plate on plate penetrating",
       plate,
       plate,
       {{0.3, 0.2, 1.5e-4}, kI},
       -0.5e-4,
       CS::kPenetrating},
      {"sliver end 1e-7 over a cube face",
       cube,
       sliver,
       {{1.0 + std::cos(0.3) + 1e-4 * std::sin(0.3) + 1e-7, 0.3, 0.3}, turn(0.3, {0, 0, 1})},
       1e-7,
       CS::kSeparated},
      {"tetrahedron under a cube",
       {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
       cube,
       {{0.3, 0.3, -1.2}, kI},
       0.2,
       CS::kSeparated},
  };
  // a 32-sided prism: parallel caps and parallel side edges, large enough for the EPA path
  const auto p32 = prism(32, 1.0, 0.5);
  c.push_back(
      {"prism caps penetrating", p32, p32, {{0.3, 0.1, 0.99}, kI}, -0.01, CS::kPenetrating});
  c.push_back({"prism caps touching", p32, p32, {{0.3, 0.1, 1.0}, kI}, 0.0, CS::kTouching});
  c.push_back(
      {"prism caps 1e-7 apart", p32, p32, {{0.3, 0.1, 1.0 + 1e-7}, kI}, 1e-7, CS::kSeparated});
  // B turned by half a side: B's side face at x = 1 meets A's side edge at x = 1
  const double apothem = std::cos(kPi / 32);
  c.push_back({"prism side edge on side face, touching",
               p32,
               p32,
               {{1.0 + apothem, 0.0, 0.2}, turn(kPi / 32, {0, 0, 1})},
               0.0,
               CS::kTouching});
  c.push_back({"prism side edge into side face",
               p32,
               p32,
               {{1.0 + apothem - 0.01, 0.0, 0.2}, turn(kPi / 32, {0, 0, 1})},
               std::nullopt,
               CS::kPenetrating});
  c.push_back({"prism deep",
               p32,
               p32,
               {{0.2, 0.1, 0.3}, turn(0.4, {1, 1, 0})},
               std::nullopt,
               CS::kPenetrating});
  c.push_back({"prism identical", p32, p32, {{0, 0, 0}, kI}, -1.0, CS::kPenetrating});
  return c;
}

TEST(HardCases, EveryCaseInEveryFrame) {
  Figures fig;
  Failures fails;
  double max_expect_err = 0.0, max_frame_dev = 0.0;
  std::size_t cases = 0;
  for (const HardCase& h : hardCases()) {
    runCase(h, fig, fails, max_expect_err, max_frame_dev);
    ++cases;
  }
  fig.print("hard cases (" + std::to_string(cases) + " cases x 3 scales x 2 offsets x 2 frames)");
  std::printf(
      "[figures] hard cases: max error against the exact expected distance %.3g of size; "
      "max deviation between frames and scales %.3g of size; largest distance error "
      "against the reference in: %s\n",
      max_expect_err, max_frame_dev, worst_distance_case().c_str());
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

// 4 to 2000 vertices, against the full reference (a small box keeps it affordable) and, for two
// prisms of 2000 vertices, against the exact distances of parallel caps and sides.
TEST(HardCases, FourToTwoThousandVertices) {
  Figures fig;
  Failures fails;
  double max_expect_err = 0.0, max_frame_dev = 0.0;
  std::mt19937_64 rng(8);
  for (const std::size_t n : {4u, 8u, 64u, 500u, 2000u}) {
    const auto ell = reference::ellipsoidPoints(n, 1.0, 0.7, 0.5, 100 + n);
    const auto small = box(0.3, 0.2, 0.1);
    const Quat q = reference::randomRotation(rng);
    // B over the ellipsoid's top (z = 0.5 at most): apart, near, through
    for (const double z : {0.8, 0.62, 0.55, 0.3}) {
      if (n >= 500 && (z == 0.8 || z == 0.55))
        continue;  // reference time
      runCase({"ellipsoid n=" + std::to_string(n) + " vs box, z " + checks::label(z),
               ell,
               small,
               {{0.1, -0.05, z}, q},
               std::nullopt,
               std::nullopt},
              fig, fails, max_expect_err, max_frame_dev, n < 500);
    }
  }
  const auto p1000 = prism(1000, 1.0, 0.5);  // 2000 vertices
  ASSERT_EQ(hullOf(p1000).vertices().size(), 2000u);
  const std::vector<HardCase> big = {
      {"2000-vertex prisms, caps 1e-7 apart",
       p1000,
       p1000,
       {{0.3, 0.1, 1.0 + 1e-7}, kI},
       1e-7,
       ContactStatus::kSeparated},
      {"2000-vertex prisms, caps touching",
       p1000,
       p1000,
       {{0.3, 0.1, 1.0}, kI},
       0.0,
       ContactStatus::kTouching},
      {"2000-vertex prisms, caps penetrating",
       p1000,
       p1000,
       {{0.3, 0.1, 0.99}, kI},
       -0.01,
       ContactStatus::kPenetrating},
      {"2000-vertex prisms, side edges 1e-3 apart",
       p1000,
       p1000,
       {{2.001, 0.0, 0.2}, kI},
       1e-3,
       ContactStatus::kSeparated},
  };
  for (const HardCase& h : big) {
    // too large for the full reference: the exact expectation, in every frame
    const Quat world_turn = turn(0.7, {0.3, -0.5, 0.8});
    for (const double s : {1.0, 1e-3, 1e3}) {
      const Polytope a = hullOf(scaled(h.a, s));
      const double size = a.radius();
      for (const bool far : {false, true}) {
        for (const bool turned : {false, true}) {
          const Vec3 offset = far ? Vec3{1e4, -2e4, 0.7e4} * size : Vec3{0.0};
          const Quat qa = turned ? world_turn : kI;
          const Transform X_AB = geom::relativeTransform(
              Pose{offset, qa}, Pose{offset + qa * (h.pose_b.translation * s), qa});
          const std::string label = h.name + " scale " + checks::label(s) + (far ? " far" : "") +
                                    (turned ? " turned" : "");
          PairCache cache;
          const PairResult r = queryPair(a, a, X_AB, cache);
          FeatureCache fc;
          const ClosestResult c = closestFeatures(a, a, X_AB, fc);
          ASSERT_NE(c.end, WalkEnd::kIterationCap) << label;
          ASSERT_TRUE(std::isfinite(r.distance) && finite(r.normal)) << label;
          EXPECT_EQ(name(r.status), name(*h.status)) << label;
          const double e = std::abs(r.distance / s - *h.expect) / (size / s);
          max_expect_err = std::max(max_expect_err, e);
          EXPECT_LE(e, kDistTol) << label << ": " << r.distance / s << " expected " << *h.expect;
          EXPECT_NEAR(reference::bruteDepthAlong(a, a, X_AB, r.normal), -r.distance,
                      kDistTol * size)
              << label;
          EXPECT_LE(glm::length(r.point_b - r.point_a - r.normal * r.distance), kDistTol * size)
              << label;
        }
      }
    }
  }
  fig.print("ellipsoids of 4..2000 vertices against a box, every frame");
  std::printf(
      "[figures] 4..2000 vertices: max error against exact distances %.3g of size, max "
      "deviation between frames %.3g of size\n",
      max_expect_err, max_frame_dev);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
}

}  // namespace
}  // namespace hapticd::collision
