// The whole tick on the hard cases of issue 5, driven tick by tick on simulated time. Every case
// checks the invariants of tests/core/sim/harness.h on every tick and prints its figures.
#include "core/sim/simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>

#include "tests/core/alloc_counter.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;

// A floor: a static box whose top face is y = 0.
scene::Body floorBody(double s = 1.0) {
  return makeBody("floor", Motion::kStatic, at(0, -0.05 * s, 0),
                  {boxShape(Vec3{0.2, 0.05, 0.2} * s)});
}

TEST(Simulation, ProbeSphereDriven50mmIntoAWall) {
  scene::SceneModel s;
  s.name = "wall";
  s.bodies.push_back(floorBody());
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(makeShaped(finish(s), o), o);
  const double r = o.probe_sphere_radius_m;
  Path path({{0.0, at(0, r + 0.02, 0)},
             {2.0, at(0, r - 0.05, 0)},  // 50 mm inside the wall
             {2.5, at(0, r - 0.05, 0)},
             {4.5, at(0, r + 0.02, 0)},
             {5.0, at(0, r + 0.02, 0)}});
  double f_at_5mm = -1.0, delta = 0.0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (f_at_5mm < 0.0 && in.X_W_device.translation.y <= r - 0.005) {
      f_at_5mm = out.force_W_n.y;
      delta = out.delta_m;
    }
    EXPECT_GE(out.X_W_proxy.translation.y, r - 1e-3);  // the proxy stays at the surface
  });
  f.print("probe 50 mm into a wall");
  std::printf(
      "  force at 5 mm depth %.4f N (k_s (delta + D) = %.4f N for a true sphere; the "
      "hull's lowest point is above -r)\n",
      f_at_5mm, o.response.stiffness_n_per_m * (delta + 0.005));
  expectInvariants(f, o, 1e-3);
  EXPECT_NEAR(f.max_force_n, o.response.max_force_n, 1e-9);  // the limit was reached and held
}

TEST(Simulation, FaceRestingOnFace) {
  scene::SceneModel s;
  s.name = "face on face";
  s.bodies.push_back(floorBody());
  auto cube = makeBody("cube", Motion::kKinematic, at(0, 0.05, 0), {boxShape(Vec3{0.01})});
  cube.probe = true;
  s.bodies.push_back(cube);
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(makeShaped(finish(s), o), o);
  const double D = 0.002;  // device 2 mm below the floor
  Path path({{0.0, at(0, 0.05, 0)},
             {1.0, at(0, 0.01 - D, 0)},
             {2.0, at(0, 0.01 - D, 0)},
             {2.5, at(0, 0.01 - D, 0, axisAngle(Vec3{1, 0, 0}, 0.01))},  // tilt the hand
             {3.0, at(0, 0.01 - D, 0, axisAngle(Vec3{1, 0, 0}, 0.01))},
             {3.5, at(0, 0.01 - D, 0)},
             {4.5, at(0, 0.03, 0)},
             {5.0, at(0, 0.03, 0)}});
  double f_rest = 0.0, t_rest = 1.0, t_tilt = 0.0, delta = 0.0;
  std::uint32_t contacts_rest = 0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (std::abs(in.t_s - 1.9) < 1e-9) {
      f_rest = out.force_W_n.y;
      t_rest = glm::length(out.torque_W_nm);
      contacts_rest = out.contacts;
      delta = out.delta_m;
    }
    if (std::abs(in.t_s - 2.9) < 1e-9)
      t_tilt = out.torque_W_nm.x;
    if (std::getenv("TRACE"))
      std::printf("T %.3f dev %.6f prx %.6f F %.6f Fc %.6f c %u pen %.3g fl %u\n", in.t_s,
                  in.X_W_device.translation.y, out.X_W_proxy.translation.y, out.force_W_n.y,
                  out.contact_force_W_n.y, out.contacts, out.max_penetration_m, out.flags);
  });
  f.print("face resting on face");
  const double expect = o.response.stiffness_n_per_m * (delta + D);
  std::printf(
      "  resting force %.5f N (k_s (delta + D) = %.5f N, delta %.3g mm), torque %.3g N m, "
      "%u contacts; torque with the hand tilted 10 mrad %.5f N m\n",
      f_rest, expect, 1e3 * delta, t_rest, contacts_rest, t_tilt);
  expectInvariants(f, o, 1e-3);
  EXPECT_NEAR(f_rest, expect, 0.01 * expect);
  EXPECT_LT(t_rest, 1e-6);
  EXPECT_EQ(contacts_rest, 4u);
  EXPECT_LT(t_tilt, 0.0);  // the floor resists the tilt: the torque turns the hand back
}

TEST(Simulation, StepAllocatesNothingAfterCreate) {
  scene::SceneModel s;
  s.bodies.push_back(floorBody());
  sim::SimOptions o;
  auto sim = makeShaped(finish(s), o);
  const double r = o.probe_sphere_radius_m;
  Path path(
      {{0.0, at(0, r + 0.01, 0)}, {1.0, at(0, r - 0.01, 0.01)}, {2.0, at(0.01, r + 0.01, 0)}});
  sim->prepareThread();  // as the daemon does on its servo thread
  const std::uint64_t before = testing_alloc::count();
  for (int k = 0; k <= 2000; ++k) {
    sim::TickInput in;
    in.t_s = k * 0.001;
    in.X_W_device = path.at(in.t_s);
    in.buttons = static_cast<std::uint32_t>((k / 300) % 2);
    (void)sim->step(in);
  }
  EXPECT_EQ(testing_alloc::count() - before, 0u);
}

// The device lost, a NaN pose, restartRamp(): zero at once, nothing non-finite, ramp in again.
TEST(Simulation, LostDeviceBadPoseAndRestartRampAreSafe) {
  scene::SceneModel s;
  s.bodies.push_back(floorBody());
  sim::SimOptions o;
  o.response.ramp_s = 0.1;
  auto sim = makeShaped(finish(s), o);
  const double r = o.probe_sphere_radius_m;
  sim::TickInput in;
  in.X_W_device = at(0, r - 0.005, 0);  // 5 mm into the floor
  sim::TickOutput out;
  int ramp_ticks = 0;
  for (int k = 0; k < 400; ++k) {
    in.t_s = k * 0.001;
    out = sim->step(in);
    if (out.flags & sim::kTickRamping)
      ++ramp_ticks;
  }
  const double pressed = out.force_W_n.y;
  EXPECT_GT(pressed, 2.5);
  EXPECT_EQ(ramp_ticks, 100);
  // lost: zero at once
  in.device_ok = false;
  out = sim->step(in);
  EXPECT_EQ(glm::length(out.force_W_n), 0.0);
  EXPECT_EQ(glm::length(out.torque_W_nm), 0.0);
  // back: ramps in again, never faster than F_max per tick
  in.device_ok = true;
  double prev = 0.0, worst_step = 0.0;
  for (int k = 0; k < 300; ++k) {
    out = sim->step(in);
    worst_step = std::max(worst_step, std::abs(out.force_W_n.y - prev));
    prev = out.force_W_n.y;
  }
  EXPECT_NEAR(out.force_W_n.y, pressed, 1e-9);
  EXPECT_LE(worst_step, o.response.max_force_step_n + 1e-12);
  // a NaN pose: zero, finite; the proxy is not pulled anywhere (only its contacts may relax it,
  // by less than one safe distance: safe_distance_fraction of the probe sphere's radius)
  const Pose proxy_before = out.X_W_proxy;
  sim::TickInput bad = in;
  bad.X_W_device.translation.x = std::numeric_limits<double>::quiet_NaN();
  out = sim->step(bad);
  EXPECT_EQ(glm::length(out.force_W_n), 0.0);
  EXPECT_TRUE(std::isfinite(out.X_W_proxy.translation.x));
  EXPECT_LE(glm::length(out.X_W_proxy.translation - proxy_before.translation),
            o.response.safe_distance_fraction * o.probe_sphere_radius_m + 1e-12);
  EXPECT_TRUE(out.flags & sim::kTickRamping);
  bad.X_W_device.translation.x = std::numeric_limits<double>::infinity();
  out = sim->step(bad);
  EXPECT_EQ(glm::length(out.force_W_n), 0.0);
  // restartRamp(): the force fades at the step limit and comes back
  for (int k = 0; k < 300; ++k)
    out = sim->step(in);
  EXPECT_NEAR(out.force_W_n.y, pressed, 1e-9);
  sim->restartRamp();
  out = sim->step(in);
  EXPECT_NEAR(out.force_W_n.y, pressed - o.response.max_force_step_n, 1e-9);
  std::printf("[safety] pressed %.4f N; ramp %d ticks; largest step coming back %.4f N\n", pressed,
              ramp_ticks, worst_step);
}

TEST(Simulation, CreateRefusesBadOptionsAndScenesWithAMessage) {
  scene::SceneModel s;
  s.bodies.push_back(floorBody());
  s.probe_body = 3;
  auto bad_probe =
      sim::Simulation::create(std::make_shared<const scene::SceneModel>(s), sim::SimOptions{});
  ASSERT_FALSE(bad_probe.ok());
  std::printf("[create] %s\n", bad_probe.error().message.c_str());
  EXPECT_NE(bad_probe.error().message.find("probe body 3"), std::string::npos);
  s.probe_body = -1;
  sim::SimOptions o;
  o.response.stiffness_n_per_m = std::numeric_limits<double>::quiet_NaN();
  auto bad_k = sim::Simulation::create(std::make_shared<const scene::SceneModel>(s), o);
  ASSERT_FALSE(bad_k.ok());
  EXPECT_NE(bad_k.error().message.find("stiffness"), std::string::npos);
  o = sim::SimOptions{};
  o.response.proxy_stiffness_ratio = 1.0;
  EXPECT_FALSE(sim::Simulation::create(std::make_shared<const scene::SceneModel>(s), o).ok());
  EXPECT_FALSE(sim::Simulation::create(nullptr, sim::SimOptions{}).ok());
}

}  // namespace
}  // namespace hapticd::simtest
