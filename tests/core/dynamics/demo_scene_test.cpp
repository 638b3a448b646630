// The dynamic demo of §6.2 (Color Plate III): four cubes, four spheres and four ellipsoids of
// 320 faces, and a stick-like block, on a floor under gravity. Ten simulated minutes: no NaN,
// no tunnelling through the floor, no energy gain. The held stick, the no-allocation and the
// determinism checks are in demo_scene_extra_test.cpp.
#include "tests/core/dynamics/demo_scene.h"

#include <gtest/gtest.h>

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;
#ifdef HAPTICD_DYNAMICS_SHORT_RUNS
constexpr int kTenMinutes = 60 * 1000;  // sanitizer builds: one minute, the same bounds
#else
constexpr int kTenMinutes = 600 * 1000;
#endif

TEST(DemoScene, TenMinutesNoNanNoTunnellingNoEnergyGain) {
  // sleep off: ten minutes of resting contact solved on every tick (the hard case)
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig rig(demoScene(false), o);
  const double e0 = rig.energy();
  const double ke0 = rig.dyn->kineticEnergy();
  Watch w;
  std::uint64_t toi = 0, capped = 0;
  for (int k = 0; k < kTenMinutes; ++k) {
    const StepReport r = rig.tick(kDt);
    toi += r.toi_substeps;
    capped += (r.flags & kStepToiCapped) != 0;
    if (k % 10 == 0)
      check(rig, w);
    if (!w.finite)
      break;
  }
  check(rig, w);
  EXPECT_TRUE(w.finite);
  EXPECT_LT(w.deepest, 0.05) << "a body sank through the floor (fraction of its size)";
  // no explosion: the energy never rises above where it started (a margin of 1% of the
  // initial kinetic energy for the free-rotation integrator's bounded error)
  EXPECT_LE(w.worst_energy, e0 + 0.01 * ke0);
  EXPECT_LT(rig.dyn->kineticEnergy(), ke0) << "friction and inelastic impacts took energy";
  for (std::uint32_t b = kFirstMoving; b < rig.dyn->bodyCount(); ++b) {
    const Vec3 x = rig.dyn->centerOfMass(b);
    EXPECT_LT(std::max(std::abs(x.x), std::abs(x.z)), kHalf) << "inside the walls";
    EXPECT_GT(x.y, kFloorTop) << b;
  }
  std::printf(
      "demo, %d s: TOI substeps %llu, capped ticks %llu, deepest %.4f of a size, "
      "fastest %.3f m/s, KE %.4g -> %.4g J, worst E - E0 %.3g J, ticks with work %.1f s\n",
      kTenMinutes / 1000, static_cast<unsigned long long>(toi),
      static_cast<unsigned long long>(capped), w.deepest, w.fastest, ke0, rig.dyn->kineticEnergy(),
      w.worst_energy - e0, static_cast<double>(rig.dyn->counters().ticks) * kDt);
}

}  // namespace
}  // namespace hapticd::dynamics::testing
