// The narrow phase against the brute-force reference: random pairs, hard cases at three unit
// scales and far from the origin, coherent trajectories (warm start == cold start), manifolds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include <glm/gtx/quaternion.hpp>

#include "core/collision/pair_query.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using geom::Pose;
using geom::Quat;
using reference::RefAnswer;

constexpr double kDistTol = 1e-9;   // of the object size
constexpr double kAngleTol = 1e-6;  // radians

Polytope hull(const std::vector<Vec3>& pts) {
  auto r = Polytope::fromPoints(pts);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return std::move(r).value();
}

std::vector<Vec3> box(double x, double y, double z) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(Vec3{i & 1 ? x : -x, i & 2 ? y : -y, i & 4 ? z : -z});
  return p;
}

std::vector<Vec3> scaled(std::vector<Vec3> p, double s) {
  for (auto& v : p) v *= s;
  return p;
}

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

double angle(const Vec3& a, const Vec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Largest signed distance of p (in A's frame) outside polytope q placed by X (q's frame -> A's).
double outside(const Polytope& q, const Transform& X, const Vec3& p) {
  const Vec3 x = X.inverse().apply(p);
  double worst = -1e300;
  for (const auto& f : q.faces()) worst = std::max(worst, glm::dot(f.normal, x) - f.offset);
  return worst;
}

struct Figures {
  std::size_t pairs = 0, separated = 0, touching = 0, penetrating = 0;
  double max_dist_err = 0.0, max_normal_err = 0.0, max_depth_dir_err = 0.0;
  std::uint32_t max_iterations = 0;
  void print(const char* what) const {
    std::printf("[figures] %s: %zu pairs (%zu separated, %zu touching, %zu penetrating), "
                "max distance error %.3g of size, max normal error (separated) %.3g rad, "
                "max |depth along our normal - depth| %.3g of size, max walk iterations %u\n",
                what, pairs, separated, touching, penetrating, max_dist_err, max_normal_err,
                max_depth_dir_err, max_iterations);
  }
};

// One pair, every property the issue asks for.
void checkPair(const Polytope& a, const Polytope& b, const Transform& X_AB, Figures& fig,
               const std::string& label) {
  const double size = std::max(a.radius(), b.radius());
  const double tol = kDistTol * size;
  PairCache cache;
  const PairResult r = queryPair(a, b, X_AB, cache);
  FeatureCache fc;
  const ClosestResult c = closestFeatures(a, b, X_AB, fc);
  ASSERT_NE(c.end, WalkEnd::kIterationCap) << label;
  fig.max_iterations = std::max(fig.max_iterations, c.iterations);
  ASSERT_TRUE(std::isfinite(r.distance) && finite(r.normal) && finite(r.point_a) && finite(r.point_b))
      << label;
  ASSERT_NEAR(glm::length(r.normal), 1.0, 1e-12) << label;

  const RefAnswer ref = reference::bruteForce(a, b, X_AB);
  const double err = std::abs(r.distance - ref.signed_distance);
  fig.max_dist_err = std::max(fig.max_dist_err, err / size);
  ASSERT_LE(err, tol) << label << ": ours " << r.distance << " reference " << ref.signed_distance;
  ++fig.pairs;
  if (ref.signed_distance > tol) {
    ASSERT_EQ(r.status, ContactStatus::kSeparated) << label;
    ++fig.separated;
    // the normal of separated convex sets is unique
    const double e = angle(r.normal, ref.normal);
    fig.max_normal_err = std::max(fig.max_normal_err, e);
    ASSERT_LE(e, kAngleTol) << label;
    EXPECT_NEAR(glm::length(r.point_b - r.point_a), r.distance, tol) << label;
    EXPECT_LE(std::abs(outside(a, Transform{}, r.point_a)), tol) << label << " point_a on A";
    EXPECT_LE(std::abs(outside(b, X_AB, r.point_b)), tol) << label << " point_b on B";
  } else if (ref.signed_distance < -tol) {
    ASSERT_EQ(r.status, ContactStatus::kPenetrating) << label;
    ++fig.penetrating;
    // the normal is a minimal translation direction: the depth along it is the depth
    const double along = reference::bruteDepthAlong(a, b, X_AB, r.normal);
    ASSERT_NEAR(along, -r.distance, tol) << label << " depth along our normal";
    fig.max_depth_dir_err = std::max(fig.max_depth_dir_err, std::abs(along + r.distance) / size);
  } else {
    ASSERT_EQ(r.status, ContactStatus::kTouching) << label << " d=" << r.distance;
    ++fig.touching;
  }
  // manifold: 1..4 points, finite, the deepest is the pair's depth
  ASSERT_GE(r.manifold.count, 1) << label;
  ASSERT_LE(r.manifold.count, Manifold::kMaxPoints) << label;
  double deepest = -1e300;
  for (std::size_t i = 0; i < r.manifold.count; ++i) {
    const auto& p = r.manifold.points[i];
    ASSERT_TRUE(finite(p.point) && finite(p.normal) && std::isfinite(p.depth)) << label;
    deepest = std::max(deepest, p.depth);
  }
  EXPECT_NEAR(deepest, -r.distance, tol) << label << " deepest manifold point";
}

Transform randomTransform(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Pose{Vec3{g(rng), g(rng), g(rng)} * spread, reference::randomRotation(rng)}.toTransform();
}

// 100 000 random pairs of small hulls, poses spread so that about half overlap; plus larger hulls.
TEST(NarrowPhase, RandomPairsAgainstBruteForce) {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Figures fig;
  const int kPairs = 100000;
  for (int i = 0; i < kPairs; ++i) {
    const double scale = std::pow(10.0, 3.0 * static_cast<double>(i % 3) - 3.0);  // 1e-3, 1, 1e3
    const auto pa = reference::randomPointSet(rng, 4 + static_cast<std::size_t>(u(rng) * 9), scale);
    const auto pb = reference::randomPointSet(rng, 4 + static_cast<std::size_t>(u(rng) * 9), scale);
    auto ra = Polytope::fromPoints(pa), rb = Polytope::fromPoints(pb);
    if (!ra.ok() || !rb.ok()) continue;  // a degenerate random set (e.g. a flat sliver)
    const Transform X = randomTransform(rng, 1.2 * scale);
    checkPair(ra.value(), rb.value(), X, fig, "random pair " + std::to_string(i));
    if (HasFatalFailure()) return;
  }
  fig.print("random small pairs");
  EXPECT_GE(fig.pairs, 99000u);
  EXPECT_GT(fig.separated, 10000u);
  EXPECT_GT(fig.penetrating, 10000u);
}

TEST(NarrowPhase, RandomLargerHullsAgainstBruteForce) {
  std::mt19937_64 rng(7);
  Figures fig;
  for (std::size_t n : {16u, 32u, 64u}) {
    for (int i = 0; i < 150; ++i) {
      const auto pa = reference::ellipsoidPoints(n, 0.025, 0.018, 0.012, rng());
      const auto pb = reference::randomPointSet(rng, n, 0.02);
      auto rb = Polytope::fromPoints(pb);
      if (!rb.ok()) continue;
      const Polytope a = hull(pa);
      const Transform X = randomTransform(rng, 0.03);
      checkPair(a, rb.value(), X, fig, "n=" + std::to_string(n));
      if (HasFatalFailure()) return;
      // the benchmark's faster reference agrees with the full one
      const RefAnswer ref = reference::bruteForce(a, rb.value(), X);
      if (ref.overlapping) {
        ASSERT_NEAR(reference::bruteMinkowskiDepth(a, rb.value(), X, nullptr), -ref.signed_distance,
                    kDistTol * a.radius());
      }
    }
  }
  fig.print("random larger hulls");
}

// The hard cases, each at three unit scales and 1e4 sizes away from the origin.
struct HardCase {
  std::string name;
  std::vector<Vec3> a, b;
  Pose pose_b;       // A at the identity
  double expect;     // expected signed distance at scale 1 (NaN: reference only)
};

void runHard(const HardCase& h, Figures& fig) {
  for (const double s : {1e-3, 1.0, 1e3}) {
    for (const bool far : {false, true}) {
      const Polytope a = hull(scaled(h.a, s));
      const Polytope b = hull(scaled(h.b, s));
      const double size = std::max(a.radius(), b.radius());
      const Vec3 offset = far ? Vec3{1e4, -2e4, 0.7e4} * size : Vec3{0.0};
      const Pose X_WA{offset, Quat{1, 0, 0, 0}};
      const Pose X_WB{offset + h.pose_b.translation * s, h.pose_b.rotation};
      const Transform X_AB = geom::relativeTransform(X_WA, X_WB);
      const std::string label = h.name + " scale " + std::to_string(s) + (far ? " far" : "");
      checkPair(a, b, X_AB, fig, label);
      if (::testing::Test::HasFatalFailure()) return;
      if (!std::isnan(h.expect)) {
        PairCache cache;
        const PairResult r = queryPair(a, b, X_AB, cache);
        // far from the origin the input itself is only known to ~1e-12 of the size
        EXPECT_NEAR(r.distance / s, h.expect, kDistTol * size / s) << label;
      }
    }
  }
}

TEST(NarrowPhase, HardCases) {
  const auto cube = box(1, 1, 1);
  const auto q = [](double angle_rad, Vec3 axis) { return glm::angleAxis(angle_rad, glm::normalize(axis)); };
  const Quat I{1, 0, 0, 0};
  const double nan = std::nan("");
  std::vector<HardCase> cases = {
      {"parallel faces gap", cube, cube, {{2.1, 0.3, 0.2}, I}, 0.1},
      {"parallel faces rotated 1e-9", cube, cube, {{2.1, 0.3, 0.2}, q(1e-9, {0, 0, 1})}, nan},
      {"parallel faces touching", cube, cube, {{2.0, 0.3, 0.2}, I}, 0.0},
      {"parallel faces penetrating", cube, cube, {{1.99, 0.3, 0.2}, I}, -0.01},
      {"parallel edges gap", cube, cube, {{2.001, 2.001, 0.5}, I}, 0.001 * std::sqrt(2.0)},
      {"parallel edges touching", cube, cube, {{2.0, 2.0, 0.5}, I}, 0.0},
      {"crossed edges touching", cube, cube,
       {{2.0 + std::sqrt(2.0) - 1.0 + 1.0, 0.0, 0.0}, q(M_PI / 4, {0, 0, 1})}, nan},
      {"vertex on face touching", cube, cube,
       {{1.0 + std::sqrt(3.0), 0.2, 0.1}, glm::rotation(glm::normalize(Vec3{-1, -1, -1}), Vec3{-1, 0, 0})}, 0.0},
      {"gap 1e-7 of size", cube, cube, {{2.0 + 1e-7 * std::sqrt(3.0), 0.3, 0.2}, I}, 1e-7 * std::sqrt(3.0)},
      {"gap 1e-7 rotated", cube, cube, {{2.0 + 1e-7, 0.1, 0.0}, q(0.3, {1, 0, 0})}, nan},
      {"identical", cube, cube, {{0, 0, 0}, I}, -2.0},
      {"nested", cube, box(0.3, 0.2, 0.1), {{0.1, 0, 0}, q(0.2, {1, 2, 3})}, nan},
      {"sliver 1e4 over cube", box(1, 1e-4, 1e-4), cube, {{0.3, 1.0 + 1e-4 + 0.01, 0}, q(0.4, {0, 1, 0})}, nan},
      {"sliver vs sliver crossing", box(1, 1e-4, 1e-4), box(1, 1e-4, 1e-4), {{0, 0, 3e-4}, q(1.0, {0, 0, 1})}, 1e-4},
      {"sliver vs sliver penetrating", box(1, 1e-4, 1e-4), box(1, 1e-4, 1e-4), {{0, 0, 1.5e-4}, q(1.0, {0, 0, 1})}, -0.5e-4},
      {"tetrahedron under cube", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, cube, {{0.3, 0.3, -1.2}, I}, 0.2},
  };
  // 32-sided prisms: 64 vertices, large enough for the EPA path, with parallel caps and sides
  std::vector<Vec3> prism;
  for (int k = 0; k < 32; ++k) {
    const double t = k * 2.0 * M_PI / 32.0;
    prism.push_back({std::cos(t), std::sin(t), -0.5});
    prism.push_back({std::cos(t), std::sin(t), 0.5});
  }
  cases.push_back({"prism caps penetrating", prism, prism, {{0.3, 0.1, 0.99}, I}, -0.01});
  cases.push_back({"prism caps touching", prism, prism, {{0.3, 0.1, 1.0}, I}, 0.0});
  cases.push_back({"prism caps gap 1e-7", prism, prism, {{0.3, 0.1, 1.0 + 1e-7}, I}, 1e-7});
  cases.push_back({"prism sides penetrating", prism, prism, {{1.99, 0.0, 0.2}, q(M_PI / 32, {0, 0, 1})}, nan});
  cases.push_back({"prism deep", prism, prism, {{0.2, 0.1, 0.3}, q(0.4, {1, 1, 0})}, nan});
  cases.push_back({"prism identical", prism, prism, {{0, 0, 0}, I}, -1.0});
  // a vertex just inside a three-wall corner
  cases.push_back({"vertex into corner", cube, cube,
                   {{1.0 + std::sqrt(3.0) - 1e-3, 1.0, 1.0},
                    glm::rotation(glm::normalize(Vec3{-1, -1, -1}), glm::normalize(Vec3{-1, 0, 0}))},
                   nan});
  Figures fig;
  for (const HardCase& h : cases) {
    runHard(h, fig);
    if (HasFatalFailure()) return;
  }
  fig.print("hard cases x 3 scales x 2 offsets");
}

// Hulls of 4 to 2000 vertices; the large ones against the separated-only reference.
TEST(NarrowPhase, FourToTwoThousandVertices) {
  std::mt19937_64 rng(3);
  Figures fig;
  for (std::size_t n : {4u, 8u, 64u, 200u}) {
    for (int i = 0; i < 10; ++i) {
      checkPair(hull(reference::ellipsoidPoints(n, 1.0, 0.7, 0.5, rng())),
                hull(reference::ellipsoidPoints(n, 0.8, 0.8, 0.4, rng())), randomTransform(rng, 1.0),
                fig, "n=" + std::to_string(n));
      if (HasFatalFailure()) return;
    }
  }
  fig.print("4..200 vertices, full reference");
  double max_err = 0.0;
  for (std::size_t n : {1000u, 2000u}) {
    const Polytope a = hull(reference::ellipsoidPoints(n, 1.0, 0.7, 0.5, 1));
    const Polytope b = hull(reference::ellipsoidPoints(n, 0.8, 0.8, 0.4, 2));
    ASSERT_GE(a.vertices().size(), n - 5);
    for (int i = 0; i < 2; ++i) {
      // B beyond the plane x = 1 + gap (A reaches x = 1 at most): certainly apart
      const Pose X{Vec3{1.0 + 0.8 + 0.05 * (i + 1), 0.1 * i, 0.0}, Quat{1, 0, 0, 0}};
      const Transform X_AB = X.toTransform();
      PairCache cache;
      const PairResult r = queryPair(a, b, X_AB, cache);
      const double ref = reference::bruteSeparatedDistance(a, b, X_AB);
      ASSERT_EQ(r.status, ContactStatus::kSeparated);
      max_err = std::max(max_err, std::abs(r.distance - ref));
      ASSERT_NEAR(r.distance, ref, kDistTol) << "n=" << n;
      // and overlapping: depth along our normal equals our depth, and no axis of A, B beats it
      const Pose Y{Vec3{1.5, 0.2, 0.1 * i}, glm::angleAxis(0.3 * i, Vec3{0, 0, 1})};
      const Transform Y_AB = Y.toTransform();
      PairCache c2;
      const PairResult p = queryPair(a, b, Y_AB, c2);
      ASSERT_EQ(p.status, ContactStatus::kPenetrating);
      ASSERT_NEAR(reference::bruteDepthAlong(a, b, Y_AB, p.normal), -p.distance, kDistTol);
      for (const auto& f : a.faces()) {
        ASSERT_GE(reference::bruteDepthAlong(a, b, Y_AB, f.normal), -p.distance - kDistTol);
      }
    }
  }
  std::printf("[figures] 1000 and 2000 vertices: max distance error %.3g\n", max_err);
}

// 10 000 steps of 0.1 mm and 0.1 degree on 50 mm objects, in and out of contact: one warm cache
// along the path gives the same answers as a cold start at every step, and the reference's every
// 25th step.
TEST(NarrowPhase, CoherentTrajectoryWarmEqualsCold) {
  const Polytope a = hull(reference::ellipsoidPoints(64, 0.025, 0.018, 0.012, 1));
  const Polytope b = hull(reference::ellipsoidPoints(64, 0.025, 0.018, 0.012, 2));
  const double size = std::max(a.radius(), b.radius());
  const double tol = kDistTol * size;
  PairCache warm;
  Figures fig;
  std::size_t warm_iterations = 0;
  const Vec3 axis = glm::normalize(Vec3{1, 2, 3});
  for (int k = 0; k < 10000; ++k) {
    // x oscillates between 75 mm (apart) and 15 mm (deep): at most 0.1 mm per step
    const double x = 0.045 + 0.03 * std::cos(k * 0.1e-3 / 0.03);
    const Pose X{Vec3{x, 0.004 * std::sin(k * 0.002), 0.0}, glm::angleAxis(k * 0.1 * M_PI / 180.0, axis)};
    const Transform X_AB = X.toTransform();
    const PairResult w = queryPair(a, b, X_AB, warm);
    PairCache cold;
    const PairResult c = queryPair(a, b, X_AB, cold);
    warm_iterations += w.iterations;
    ASSERT_EQ(w.status, c.status) << "step " << k;
    ASSERT_NEAR(w.distance, c.distance, tol) << "step " << k;
    if (w.status != ContactStatus::kTouching) {
      ASSERT_LE(angle(w.normal, c.normal), kAngleTol) << "step " << k;
    }
    if (k % 25 == 0) {
      checkPair(a, b, X_AB, fig, "trajectory step " + std::to_string(k));
      if (HasFatalFailure()) return;
    }
  }
  fig.print("trajectory (every 25th step vs reference)");
  std::printf("[figures] trajectory: mean warm walk iterations %.3f per step\n",
              static_cast<double>(warm_iterations) / 10000.0);
  EXPECT_GT(fig.separated, 50u);
  EXPECT_GT(fig.penetrating, 50u);
}

TEST(NarrowPhase, ManifoldShapes) {
  const Polytope cube = hull(box(1, 1, 1));
  const Quat I{1, 0, 0, 0};
  auto query = [&](const Pose& X) {
    PairCache c;
    return queryPair(cube, cube, X.toTransform(), c);
  };
  // face on face: the overlap square
  EXPECT_EQ(query({{2.01, 0.5, 0.5}, I}).manifold.count, 4);
  EXPECT_EQ(query({{1.99, 0.5, 0.5}, I}).manifold.count, 4);
  // an edge on a face
  const Pose edge_on_face{{1.0 + std::sqrt(2.0) + 0.01, 0.2, 0.0}, glm::angleAxis(M_PI / 4, Vec3{0, 0, 1})};
  const PairResult ef = query(edge_on_face);
  EXPECT_EQ(ef.manifold.count, 2);
  for (std::size_t i = 0; i < ef.manifold.count; ++i) EXPECT_NEAR(ef.manifold.points[i].depth, -0.01, 1e-12);
  // a vertex on a face
  const Pose vertex_on_face{{1.0 + std::sqrt(3.0) + 0.01, 0.2, 0.1},
                            glm::rotation(glm::normalize(Vec3{-1, -1, -1}), Vec3{-1, 0, 0})};
  EXPECT_EQ(query(vertex_on_face).manifold.count, 1);
  // parallel edges: their overlap segment
  const PairResult pe = query({{2.01, 2.01, 0.5}, I});
  ASSERT_EQ(pe.manifold.count, 2);
  EXPECT_NEAR(std::abs(pe.manifold.points[0].point.z - pe.manifold.points[1].point.z), 1.5, 1e-12);
  // crossed edges: one point
  EXPECT_EQ(query({{2.0 + 0.01, 0.0, 2.0 + 0.01}, glm::angleAxis(M_PI / 2, Vec3{1, 0, 0})}).manifold.count, 2);
  // a many-sided face on a face: reduced to 4, the deepest kept
  std::vector<Vec3> prism;
  for (int k = 0; k < 12; ++k) {
    const double t = k * 2.0 * M_PI / 12.0;
    prism.push_back({std::cos(t), std::sin(t), 0.0});
    prism.push_back({std::cos(t), std::sin(t), 1.0});
  }
  const Polytope p = hull(prism);
  const Pose tilted{{0.0, 0.0, 1.0 - 0.01}, glm::angleAxis(1e-3, Vec3{1, 0, 0})};
  PairCache c;
  const PairResult r = queryPair(cube, p, tilted.toTransform(), c);
  ASSERT_EQ(r.status, ContactStatus::kPenetrating);
  EXPECT_EQ(r.manifold.count, 4);
  double deepest = -1e300;
  for (std::size_t i = 0; i < r.manifold.count; ++i) deepest = std::max(deepest, r.manifold.points[i].depth);
  EXPECT_NEAR(deepest, -r.distance, 1e-12);
}

// The two depth methods agree: GJK+EPA (certified or refused) and the separating axes, on random
// overlapping pairs of all shapes, including the small hulls the pair query sends to the axes.
TEST(NarrowPhase, EpaEqualsSeparatingAxes) {
  std::mt19937_64 rng(31);
  std::normal_distribution<double> g(0.0, 1.0);
  std::size_t overlapping = 0, certified = 0;
  double max_err = 0.0;
  for (std::size_t k = 0; k < 20000; ++k) {
    auto ra = Polytope::fromPoints(reference::randomPointSet(rng, 4 + k % 40, 1.0));
    auto rb = Polytope::fromPoints(reference::randomPointSet(rng, 4 + (k / 3) % 40, 1.0));
    if (!ra.ok() || !rb.ok()) continue;
    const Polytope& a = ra.value();
    const Polytope& b = rb.value();
    const Transform X = Pose{Vec3{g(rng), g(rng), g(rng)} * 0.5, reference::randomRotation(rng)}.toTransform();
    DepthCache c1, c2;
    const DepthResult exact = penetrationDepthExact(a, b, X, c1);
    if (exact.depth <= 1e-9) continue;
    ++overlapping;
    DepthResult epa;
    if (!penetrationDepthEpa(a, b, X, c2, epa)) continue;
    ++certified;
    const double size = std::max(a.radius(), b.radius());
    max_err = std::max(max_err, std::abs(epa.depth - exact.depth) / size);
    ASSERT_NEAR(epa.depth, exact.depth, kDistTol * size) << "pair " << k;
    ASSERT_NEAR(reference::bruteDepthAlong(a, b, X, epa.normal), epa.depth, kDistTol * size) << "pair " << k;
    ASSERT_NEAR(glm::length(epa.point_a - epa.point_b - epa.normal * epa.depth), 0.0, kDistTol * size);
  }
  std::printf("[figures] EPA: %zu overlapping pairs, %zu certified (the rest refused, answered by the "
              "axes), max depth difference %.3g of size\n", overlapping, certified, max_err);
  EXPECT_GT(certified, overlapping * 9 / 10);
}

TEST(NarrowPhase, DepthAlongADirection) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  const Polytope a = hull(reference::ellipsoidPoints(128, 0.025, 0.018, 0.012, 4));
  const Polytope b = hull(reference::ellipsoidPoints(128, 0.02, 0.02, 0.01, 5));
  std::uint32_t ha = 0, hb = 0;
  for (int i = 0; i < 2000; ++i) {
    const Transform X = randomTransform(rng, 0.02);
    const Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
    ASSERT_NEAR(depthAlong(a, b, X, dir, ha, hb), reference::bruteDepthAlong(a, b, X, dir),
                kDistTol * 0.025);
  }
}

// The same answers at any unit: a pair in mm, m and km, relative to size.
TEST(NarrowPhase, UnitScaleInvariance) {
  std::mt19937_64 rng(12);
  for (int i = 0; i < 300; ++i) {
    const auto pa = reference::ellipsoidPoints(24, 1.0, 0.6, 0.4, rng());
    const auto pb = reference::ellipsoidPoints(24, 0.7, 0.7, 0.3, rng());
    const Transform X = randomTransform(rng, 1.0);
    double base = 0.0;
    for (const double s : {1e-3, 1.0, 1e3}) {
      const Transform Xs{X.R, X.t * s};
      PairCache c;
      const PairResult r = queryPair(hull(scaled(pa, s)), hull(scaled(pb, s)), Xs, c);
      if (s == 1e-3) base = r.distance / s;
      ASSERT_NEAR(r.distance / s, base, 1e-9) << "pair " << i << " scale " << s;
    }
  }
}

}  // namespace
}  // namespace hapticd::collision
