// Coherent trajectories of 10 000 steps (at most 0.1 mm and 0.1 degree per step, objects of 50 mm,
// metres) from separated through touching into penetration and out again, several times: one
// PairCache (and one FeatureCache) kept along the path gives the same answers as a fresh cache at
// every step, and the reference's every 10th step (and every step where the pair touches).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/gtx/quaternion.hpp>
#include <numbers>

#include "core/collision/pair_query.h"
#include "tests/core/collision/pair_checks.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using namespace checks;  // NOLINT(google-build-using-namespace): test helpers
using geom::Pose;
using geom::Quat;

constexpr int kSteps = 10000;
constexpr double kStepM = 1e-4;                              // 0.1 mm
constexpr double kStepRad = 0.1 * std::numbers::pi / 180.0;  // 0.1 degree

struct TrajectoryFigures {
  std::size_t steps = 0, touching_steps = 0, status_changes = 0;
  double max_warm_cold = 0.0;  // |warm - cold| distance, of the size
  double max_warm_cold_normal = 0.0;
  std::uint64_t warm_iterations = 0, cold_iterations = 0;
};

// Runs `pose(k)` (B in A's frame) for kSteps steps.
void runTrajectory(const char* what,
                   const Polytope& a,
                   const Polytope& b,
                   const std::function<Pose(int)>& pose) {
  const double size = pairSize(a, b);
  const double tol = kDistTol * size;
  PairCache warm;
  FeatureCache warm_features;
  Figures fig;
  Failures fails;
  TrajectoryFigures t;
  ContactStatus last = ContactStatus::kSeparated;
  Pose previous = pose(0);
  for (int k = 0; k < kSteps; ++k) {
    const Pose X = pose(k);
    // the step bounds of the issue
    ASSERT_LE(glm::length(X.translation - previous.translation), kStepM * (1 + 1e-9))
        << "step " << k;
    ASSERT_LE(2.0 * std::acos(std::min(1.0, std::abs(glm::dot(X.rotation, previous.rotation)))),
              kStepRad * (1 + 1e-6))
        << "step " << k;
    previous = X;
    const Transform X_AB = X.toTransform();
    const std::string label = std::string(what) + ", step " + std::to_string(k);

    const PairResult w = queryPair(a, b, X_AB, warm);
    PairCache fresh;
    const PairResult c = queryPair(a, b, X_AB, fresh);
    const ClosestResult wf = closestFeatures(a, b, X_AB, warm_features);
    FeatureCache fresh_features;
    const ClosestResult cf = closestFeatures(a, b, X_AB, fresh_features);
    t.warm_iterations += wf.iterations;
    t.cold_iterations += cf.iterations;
    ++t.steps;
    ASSERT_NE(wf.end, WalkEnd::kIterationCap) << label << " (warm walk)\n" << describe(a, b, X_AB);
    ASSERT_NE(cf.end, WalkEnd::kIterationCap) << label << " (cold walk)\n" << describe(a, b, X_AB);
    if (wf.end == WalkEnd::kConverged && cf.end == WalkEnd::kConverged) {
      ASSERT_NEAR(wf.distance, cf.distance, tol) << label << " (walk)";
    }

    // warm == cold
    ASSERT_TRUE(statusAcceptable(w.status, c.distance, size))
        << label << ": warm " << name(w.status) << ", cold " << name(c.status) << "\n"
        << describe(a, b, X_AB);
    const double dd = std::abs(w.distance - c.distance);
    t.max_warm_cold = std::max(t.max_warm_cold, dd / size);
    ASSERT_LE(dd, tol) << label << ": warm " << w.distance << ", cold " << c.distance << "\n"
                       << describe(a, b, X_AB);
    const double na = angle(w.normal, c.normal);
    if (na > kAngleTol) {
      // only where the normal is not unique
      const bool unique =
          w.status == ContactStatus::kSeparated || axisMargin(a, b, X_AB).unique(size);
      ASSERT_FALSE(unique) << label << ": warm normal differs from cold by " << na << " rad\n"
                           << describe(a, b, X_AB);
    } else {
      t.max_warm_cold_normal = std::max(t.max_warm_cold_normal, na);
    }
    if (w.status != last)
      ++t.status_changes;
    last = w.status;
    t.touching_steps += w.status == ContactStatus::kTouching;

    // the reference every 10th step and at every touching step
    if (k % 10 == 0 || w.status == ContactStatus::kTouching) {
      const auto ref = reference::bruteForce(a, b, X_AB);
      fails.add(label + " (warm query)", checkPairResult({a, b, X_AB, ref}, w, fig));
      fails.add(label + " (warm walk)", checkClosest({a, b, X_AB, ref}, wf, fig));
    }
  }
  fig.print(std::string(what) + ", warm answers checked against the reference");
  std::printf(
      "[figures] %s: %zu steps, %zu touching, %zu status changes; warm vs cold: max "
      "distance difference %.3g of size, max normal difference %.3g rad; mean walk "
      "iterations warm %.3f, cold %.3f\n",
      what, t.steps, t.touching_steps, t.status_changes, t.max_warm_cold, t.max_warm_cold_normal,
      static_cast<double>(t.warm_iterations) / kSteps,
      static_cast<double>(t.cold_iterations) / kSteps);
  std::fflush(stdout);
  EXPECT_EQ(fails.total(), 0u) << fails.summary();
  EXPECT_GE(t.status_changes, 4u) << "the path must go in and out of contact";
  EXPECT_GT(fig.separated, 50u);
  EXPECT_GT(fig.penetrating, 50u);
}

// A triangle wave of integer steps: 0, 1, ..., amplitude, amplitude - 1, ..., -amplitude, ...
int triangle(int k, int amplitude) {
  const int period = 4 * amplitude;
  const int m = ((k % period) + period) % period;
  if (m <= amplitude)
    return m;
  if (m <= 3 * amplitude)
    return 2 * amplitude - m;
  return m - 4 * amplitude;
}

// Box on box, face to face: the gap steps by 0.05 mm, through exactly zero (touching) on the way in
// and out, down to 2 mm deep; B slides across and spins about the face normal.
TEST(Trajectory, BoxOnBoxThroughExactTouching) {
  const Polytope a = hullOf(box(0.025, 0.025, 0.025));
  const Polytope b = hullOf(box(0.025, 0.02, 0.015));
  runTrajectory("box on box", a, b, [](int k) {
    const double gap = 0.5 * kStepM * (60 - triangle(k + 40, 100));  // 0.05 mm steps, exactly 0
    const double slide = 0.3 * kStepM;
    return Pose{
        {0.05 + gap, 0.004 * std::sin(k * slide / 0.004), 0.003 * std::cos(k * slide / 0.003)},
        glm::angleAxis(0.7 * kStepRad * k, Vec3{1, 0, 0})};
  });
}

// Two 40-point ellipsoid hulls, B turning about a skew axis while its centre swings from 75 mm
// (apart) to 15 mm (deep) and back.
TEST(Trajectory, EllipsoidsTurningInAndOut) {
  const Polytope a = hullOf(reference::ellipsoidPoints(40, 0.025, 0.018, 0.012, 1));
  const Polytope b = hullOf(reference::ellipsoidPoints(40, 0.025, 0.018, 0.012, 2));
  const Vec3 axis = glm::normalize(Vec3{1, 2, 3});
  runTrajectory("ellipsoids", a, b, [&](int k) {
    const double x = 0.045 + 0.03 * std::cos(k * 0.8 * kStepM / 0.03);
    return Pose{{x, 0.004 * std::sin(k * 0.002), 0.0}, glm::angleAxis(0.5 * kStepRad * k, axis)};
  });
}

// A cube tumbling about a skew axis against a 12-sided prism: vertex, edge and face contacts in
// turn, passing through contact many times.
TEST(Trajectory, TumblingCubeOnPrism) {
  const Polytope a = hullOf(prism(12, 0.025, 0.02));
  const Polytope b = hullOf(box(0.012, 0.012, 0.012));
  const Vec3 axis = glm::normalize(Vec3{-2, 1, 3});
  runTrajectory("tumbling cube", a, b, [&](int k) {
    const double r = 0.025 + 0.017 + 0.006 * std::cos(k * 0.7 * kStepM / 0.006);
    const double around = k * 0.3 * kStepM / 0.045;
    return Pose{
        {r * std::cos(around), r * std::sin(around), 0.01 * std::sin(k * 0.2 * kStepM / 0.01)},
        glm::angleAxis(0.8 * kStepRad * k, axis)};
  });
}

}  // namespace
}  // namespace hapticd::collision
