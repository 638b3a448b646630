// The dynamic demo of §6.2 with the held stick swept through the pile by the probe; no
// allocation per step; the same run twice gives the same bits.
#include <gtest/gtest.h>

#include <cstring>

#include "tests/core/alloc_counter.h"
#include "tests/core/dynamics/demo_scene.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;

// the held stick, driven kinematically by the probe, sweeps through the pile and back
TEST(DemoScene, HeldStickSweepsThroughThePile) {
  Rig rig(demoScene(true));
  Watch w;
  HeldInput in;
  in.mode = HeldMode::kKinematic;
  double felt = 0.0, worst_force = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double t = (k + 1) * kDt;
    // a circle of radius 0.3 m at 0.06 m over the floor, 0.5 m/s, the stick turning with it
    const double a = 0.5 / 0.3 * t;
    in.X_WB_target =
        at(Vec3{0.3 * std::cos(a), 0.06, 0.3 * std::sin(a)}, glm::angleAxis(-a, Vec3{0, 1, 0}));
    rig.tick(kDt, &in);
    check(rig, w);
    if (!w.finite)
      break;
    const HeldFeedback& fb = rig.dyn->heldFeedback();
    felt += glm::length(fb.impulse_W_ns);
    worst_force = std::max(worst_force, glm::length(fb.force_W_n));
  }
  EXPECT_TRUE(w.finite);
  EXPECT_LT(w.deepest, 0.05);
  EXPECT_GT(felt, 0.0) << "the stick hit something and the hand was told";
  // nothing is thrown faster than a few times the stick's speed
  EXPECT_LT(w.fastest, 5.0);
  std::printf(
      "held stick: impulses felt %.4f N s in total, largest spread force %.3f N, "
      "fastest body %.3f m/s\n",
      felt, worst_force, w.fastest);
}

TEST(DemoScene, StepAllocatesNothing) {
  Rig rig(demoScene(true));
  HeldInput in;
  in.mode = HeldMode::kKinematic;
  rig.run(500, kDt);
  std::uint64_t during_dynamics = 0;
  const std::uint64_t start = testing_alloc::count();
  for (int k = 0; k < 3000; ++k) {
    const double t = (k + 1) * kDt;
    in.X_WB_target = at(Vec3{0.3 * std::cos(t), 0.06, 0.3 * std::sin(t)});
    rig.world->step();
    const std::uint64_t before = testing_alloc::count();
    rig.dyn->step(*rig.world, kDt, &in);
    during_dynamics += testing_alloc::count() - before;
  }
  EXPECT_EQ(during_dynamics, 0u);
  EXPECT_EQ(testing_alloc::count() - start, 0u) << "world and dynamics together";
}

TEST(DemoScene, SameRunSameBits) {
  const auto run = [] {
    Rig rig(demoScene(false));
    rig.run(3000, kDt);
    std::vector<double> out;
    for (std::uint32_t b = 0; b < rig.dyn->bodyCount(); ++b) {
      const Pose X = rig.dyn->pose(b);
      out.insert(out.end(), {X.translation.x, X.translation.y, X.translation.z, X.rotation.w,
                             X.rotation.x, X.rotation.y, X.rotation.z});
    }
    return out;
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}

}  // namespace
}  // namespace hapticd::dynamics::testing
