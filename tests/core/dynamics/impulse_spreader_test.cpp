// The impulse spreader (§6.2 "small blips"): the force record of an impulse integrates to the
// impulse for every window; its peak falls as 2 J / window; steady impulse streams come out as
// the steady force; through the dynamics, a ball hitting the held paddle is felt over the window.
#include "core/dynamics/impulse_spreader.h"

#include <gtest/gtest.h>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;

struct Record {
  double integral = 0.0;
  double peak = 0.0;
  int peak_tick = -1;
  int ticks_nonzero = 0;
};

Record spread(double window_s, const Vec3& J) {
  ImpulseSpreader s(window_s, kDt);
  s.add(J, Vec3{0.0});
  Record r;
  for (int k = 0; k < 200; ++k) {
    Vec3 f, t;
    s.pop(&f, &t);
    r.integral += f.x * kDt;
    if (f.x > r.peak)
      r.peak = f.x, r.peak_tick = k;
    r.ticks_nonzero += f.x != 0.0;
    EXPECT_EQ(t, Vec3(0.0));
  }
  return r;
}

TEST(ImpulseSpreader, IntegralPreservedPeakFallsWithTheWindow) {
  const double J = 0.05;  // N s: a 0.1 kg ball at 0.5 m/s stopped
  std::printf("window_ms  peak_N  2J/window_N  peak_tick  integral_Ns\n");
  double last_peak = 1e300;
  for (const double w : {0.0, 0.001, 0.005, 0.010, 0.020, 0.040, 0.080}) {
    const Record r = spread(w, Vec3{J, 0, 0});
    EXPECT_NEAR(r.integral, J, 1e-14 * J) << w;
    const auto n = static_cast<int>(std::max(1.0, std::round(w / kDt)));
    if (n > 1) {
      EXPECT_LT(r.peak, last_peak) << "a longer window gives a lower peak";
    } else {
      EXPECT_LE(r.peak, last_peak);
    }
    last_peak = r.peak;
    EXPECT_LE(r.ticks_nonzero, n);
    if (n == 1) {
      EXPECT_DOUBLE_EQ(r.peak, J / kDt);  // the bare blip
    } else {
      // Hann: peak 2 J / window, less the tick averaging: 1 - (pi^2 / 3) / n^2 at worst
      const double hann = 2 * J / w;
      EXPECT_LE(r.peak, hann * (1 + 1e-12)) << w;
      EXPECT_GE(r.peak, hann * (1 - 3.3 / (n * n))) << w;
      EXPECT_NEAR(r.peak_tick, n / 2, 1) << w;  // at half the window
    }
    std::printf("%9.0f  %6.2f  %11.2f  %9d  %.12f\n", w * 1e3, r.peak, n > 1 ? 2 * J / w : J / kDt,
                r.peak_tick, r.integral);
  }
}

TEST(ImpulseSpreader, SteadyImpulsesComeOutAsTheSteadyForce) {
  ImpulseSpreader s(0.020, kDt);
  Vec3 f, t;
  for (int k = 0; k < 100; ++k) {
    s.add(Vec3{0, 2.0 * kDt, 0}, Vec3{0, 0, 0.1 * kDt});  // 2 N and 0.1 N m held
    s.pop(&f, &t);
  }
  EXPECT_NEAR(f.y, 2.0, 1e-12);
  EXPECT_NEAR(t.z, 0.1, 1e-13);
  s.clear();
  s.pop(&f, &t);
  EXPECT_EQ(f, Vec3(0.0));
}

TEST(ImpulseSpreader, BallHittingTheHeldPaddleIsFeltOverTheWindow) {
  // a kinematic paddle (the held body) and a ball falling onto it; the force record of the
  // paddle for two windows
  const auto run = [](double window_s, double* peak, double* integral, double* impulse) {
    SceneModel s;
    s.gravity_W = Vec3{0, -9.81, 0};
    s.materials.push_back(material(0.0, 0.5));
    Body paddle = staticBody("paddle", boxShape(Vec3{0.1, 0.01, 0.1}), at(Vec3{0}), 0);
    paddle.motion = Motion::kKinematic;
    paddle.probe = true;
    s.bodies.push_back(paddle);
    s.bodies.push_back(
        dynamicBody("ball", ellipsoidShape(Vec3{0.02}), at(Vec3{0, 0.1, 0}), 1000.0, 0));
    DynamicsOptions o;
    o.impulse_window_s = window_s;
    Rig rig(std::move(s), o);
    HeldInput in;
    in.mode = HeldMode::kKinematic;
    in.X_WB_target = at(Vec3{0});
    *peak = *integral = *impulse = 0.0;
    for (int k = 0; k < 170; ++k) {  // the first impact and its window, not the second
      rig.tick(kDt, &in);
      const HeldFeedback& fb = rig.dyn->heldFeedback();
      *peak = std::max(*peak, -fb.force_W_n.y);
      *integral += -fb.force_W_n.y * kDt;
      *impulse += -fb.impulse_W_ns.y;
    }
    return rig.scene->bodies[1].mass;
  };
  double p0, i0, j0, p20, i20, j20;
  const double m = run(0.0, &p0, &i0, &j0);
  run(0.020, &p20, &i20, &j20);
  // the impulse on the paddle: the ball's momentum change, m (1 + e) v with v = sqrt(2 g h)
  const double v = std::sqrt(2 * 9.81 * (0.1 - 0.01 - 0.02));
  EXPECT_NEAR(j0, m * 1.5 * v, 0.02 * m * 1.5 * v);
  EXPECT_NEAR(i0, j0, 1e-12);
  EXPECT_NEAR(i20, j20, 1e-3 * j20);  // the window is over: all of it was felt
  EXPECT_NEAR(p0, j0 / kDt, 0.02 * j0 / kDt);
  EXPECT_LE(p20, 2 * j20 / 0.020 * (1 + 1e-12));
  EXPECT_GE(p20, 2 * j20 / 0.020 * (1 - 3.3 / 400));
  std::printf("ball on paddle: impulse %.4f N s; peak %.2f N bare, %.3f N over 20 ms\n", j0, p0,
              p20);
}

}  // namespace
}  // namespace hapticd::dynamics::testing
