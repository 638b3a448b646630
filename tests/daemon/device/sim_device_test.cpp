// The sim device: the closed loop is stable at 1 and 4 kHz, the hand follows commands, the idle
// motion is smooth, runs are bitwise deterministic, servo calls allocate nothing.
#include "daemon/device/sim_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "core/geometry/rotation.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::device {
namespace {

DeviceOptions quietOptions() {
  DeviceOptions o;
  o.sim_idle_motion_after_s = std::numeric_limits<double>::infinity();
  return o;
}

std::unique_ptr<Device> open(const DeviceOptions& o) {
  auto d = makeDevice("sim", o);
  EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
  return std::move(d).value();
}

// The loop closed through a stiff spring toward the commanded point (a wall or a virtual
// coupling), with no damping of its own: all dissipation comes from the hand model. Energy of
// the whole system (hand relative to its target plus the loop spring) must fall, tick by tick
// within a small numerical ripple, to nothing.
void closedLoopDecays(double rate_hz, double loop_k_n_per_m, double loop_kr_nm_per_rad) {
  DeviceOptions o = quietOptions();
  o.sim_home.translation = Vec3(0.05, -0.03, 0.02);  // start 6 cm from the target
  o.sim_home.rotation = geom::quatFromRotationVector(Vec3(0.0, 0.6, 0.2));
  auto dev = open(o);
  auto* sim = dynamic_cast<SimDevice*>(dev.get());
  ASSERT_NE(sim, nullptr);
  PoseCommand cmd;  // the origin, identity
  dev->command(cmd);
  const double dt = 1.0 / rate_hz;
  DeviceSample s;
  double e0 = -1.0;
  double e_max_rise = 0.0;  // largest tick-to-tick rise, relative to e0
  double e_prev = 0.0;
  const int ticks = static_cast<int>(10.0 * rate_hz);
  for (int i = 0; i <= ticks; ++i) {
    ASSERT_EQ(dev->read(i * dt, s), DeviceStatus::kOk);
    const Vec3 p = s.X_WD.translation;
    const Vec3 r = geom::rotationVector(s.X_WD.rotation);
    const double e = sim->energy() + 0.5 * loop_k_n_per_m * glm::dot(p, p) +
                     0.5 * loop_kr_nm_per_rad * glm::dot(r, r);
    if (e0 < 0.0)
      e0 = e;
    if (i > 0)
      e_max_rise = std::max(e_max_rise, (e - e_prev) / e0);
    e_prev = e;
    ASSERT_TRUE(std::isfinite(e));
    ASSERT_LE(e, e0 * (1.0 + 1e-9)) << "tick " << i;
    dev->write(-loop_k_n_per_m * p, -loop_kr_nm_per_rad * r);
  }
  std::printf("  %g Hz, loop k %g N/m, %g N*m/rad: E0 %.3e J, E(10 s) %.3e J, max rise %.2e E0\n",
              rate_hz, loop_k_n_per_m, loop_kr_nm_per_rad, e0, e_prev, e_max_rise);
  EXPECT_LT(e_prev, 1e-12 * e0);
  EXPECT_LT(e_max_rise, 1e-3);
}

TEST(SimDevice, ClosedLoopEnergyDecaysAt1kHz) {
  closedLoopDecays(1000.0, 2000.0, 5.0);
}
TEST(SimDevice, ClosedLoopEnergyDecaysAt4kHz) {
  closedLoopDecays(4000.0, 8000.0, 20.0);
}

TEST(SimDevice, FollowsCommands) {
  auto dev = open(quietOptions());
  PoseCommand cmd;
  cmd.X_W_target = Pose::fromXyzw(Vec3(0.03, -0.01, 0.02), 0.0, std::sin(0.25), 0.0,
                                  std::cos(0.25));  // 0.5 rad about y
  cmd.buttons = 5;
  DeviceSample s;
  dev->read(0.0, s);
  dev->command(cmd);
  for (int i = 1; i <= 3000; ++i)
    dev->read(i * 1e-3, s);
  const Vec3 dp = s.X_WD.translation - cmd.X_W_target.translation;
  const double angle =
      glm::length(geom::rotationVector(s.X_WD.rotation * glm::conjugate(cmd.X_W_target.rotation)));
  std::printf("  after 3 s: position error %.3e m, angle error %.3e rad\n", glm::length(dp), angle);
  EXPECT_LT(glm::length(dp), 1e-6);
  EXPECT_LT(angle, 1e-6);
  EXPECT_EQ(s.buttons, 5u);
  // a command moving at constant velocity is tracked with no lag at steady state (the damper
  // pulls toward the target's velocity)
  const Vec3 v(0.02, 0.0, -0.01);
  for (int i = 3001; i <= 6000; ++i) {
    PoseCommand moving;
    moving.X_W_target.translation = cmd.X_W_target.translation + v * ((i - 3000) * 1e-3);
    moving.X_W_target.rotation = cmd.X_W_target.rotation;
    moving.linear_velocity = v;
    dev->command(moving);
    dev->read(i * 1e-3, s);
    if (i == 6000) {
      const Vec3 lag = moving.X_W_target.translation - s.X_WD.translation;
      std::printf("  moving at 2.2 cm/s: lag %.3e m, velocity error %.3e m/s\n", glm::length(lag),
                  glm::length(s.linear_velocity - v));
      // semi-implicit Euler lags by about one step at the target velocity
      EXPECT_LT(glm::length(lag), 1e-4);
      EXPECT_LT(glm::length(s.linear_velocity - v), 1e-6);
    }
  }
}

TEST(SimDevice, ForceFromTheLoopDisplacesTheHand) {
  auto dev = open(quietOptions());
  DeviceSample s;
  const Vec3 f(1.0, -2.0, 0.5);
  const Vec3 torque(0.0, 0.0, 0.05);
  for (int i = 0; i <= 5000; ++i) {
    dev->read(i * 1e-3, s);
    dev->write(f, torque);
  }
  const DeviceOptions o;
  // static equilibrium: the spring balances the force
  const Vec3 expected = f / o.sim_hand_stiffness_n_per_m;
  EXPECT_LT(glm::length(s.X_WD.translation - expected), 1e-9);
  const Vec3 r = geom::rotationVector(s.X_WD.rotation);
  EXPECT_NEAR(r.z, 0.05 / o.sim_hand_rot_stiffness_nm_per_rad, 1e-6);
}

TEST(SimDevice, IdleMotionIsTheDerivativeOfItsPath) {
  const Pose home = Pose::fromXyzw(Vec3(0.1, 0.2, 0.3), 0.1, 0.2, 0.3, 0.9);
  const double h = 1e-6;
  for (double t = 0.0; t < 60.0; t += 0.37) {
    const Pose a = simIdleMotion(home, 0.02, 0.1, t - h).X_W;
    const Pose b = simIdleMotion(home, 0.02, 0.1, t + h).X_W;
    const IdleMotion m = simIdleMotion(home, 0.02, 0.1, t);
    const Pose& x = m.X_W;
    const Vec3& vx = m.v_W;
    const Vec3& wx = m.w_W;
    const Vec3 v_fd = (b.translation - a.translation) / (2.0 * h);
    const Vec3 w_fd = geom::rotationVector(b.rotation * glm::conjugate(a.rotation)) / (2.0 * h);
    EXPECT_LT(glm::length(v_fd - vx), 1e-8) << t;
    EXPECT_LT(glm::length(w_fd - wx), 1e-7) << t;
    EXPECT_LE(glm::length(x.translation - home.translation), 0.02 * 1.5 + 1e-12);
  }
  const Pose x0 = simIdleMotion(home, 0.02, 0.1, 0.0).X_W;
  EXPECT_EQ(x0.translation, home.translation);
}

TEST(SimDevice, IdleMotionStartsSmoothlyAfterTheLastCommand) {
  DeviceOptions o;  // idle after 1 s
  auto dev = open(o);
  DeviceSample s;
  dev->read(0.0, s);
  PoseCommand cmd;
  cmd.X_W_target.translation = Vec3(0.01, 0.0, 0.0);
  dev->command(cmd);
  Vec3 last = s.X_WD.translation;
  double max_step = 0.0;
  double max_accel = 0.0;
  Vec3 last_v = s.linear_velocity;
  double farthest = 0.0;
  for (int i = 1; i <= 30000; ++i) {
    dev->read(i * 1e-3, s);
    max_step = std::max(max_step, glm::length(s.X_WD.translation - last));
    if (i > 1000)
      max_accel = std::max(max_accel, glm::length(s.linear_velocity - last_v) / 1e-3);
    farthest = std::max(farthest, glm::length(s.X_WD.translation - o.sim_home.translation));
    last = s.X_WD.translation;
    last_v = s.linear_velocity;
  }
  std::printf(
      "  idle: largest step %.3e m/tick, largest acceleration %.3e m/s^2, farthest %.4f m\n",
      max_step, max_accel, farthest);
  EXPECT_GT(farthest, 0.01);  // it moves
  EXPECT_LT(farthest, 0.05);  // gently, around home
  EXPECT_LT(max_step, 1e-4);
  EXPECT_LT(max_accel, 0.5);
}

TEST(SimDevice, BitwiseDeterministic) {
  auto run = [] {
    DeviceOptions o;
    o.sim_idle_motion_after_s = 0.5;
    auto dev = open(o);
    std::vector<DeviceSample> out;
    DeviceSample s;
    for (int i = 0; i < 8000; ++i) {
      if (i == 100) {
        PoseCommand c;
        c.X_W_target = Pose::fromXyzw(Vec3(0.02, 0.01, 0.0), 0.1, 0.0, 0.0, 1.0);
        dev->command(c);
      }
      dev->read(i * 2.5e-4, s);
      out.push_back(s);
      const Vec3 p = s.X_WD.translation;
      dev->write(Vec3(-300.0 * p.x, std::sin(p.y * 100.0), 0.0), Vec3(0.0, 0.01 * p.z, 0.0));
    }
    return out;
  };
  const auto a = run();
  const auto b = run();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(DeviceSample)), 0);
}

TEST(SimDevice, LongGapsAreSubSteppedAndNonFiniteInputIgnored) {
  auto dev = open(quietOptions());
  DeviceSample s;
  dev->read(0.0, s);
  PoseCommand bad;
  bad.X_W_target.translation = Vec3(std::nan(""), 0.0, 0.0);
  dev->command(bad);
  dev->write(Vec3(std::numeric_limits<double>::infinity(), 0.0, 0.0), Vec3(0.0));
  PoseCommand cmd;
  cmd.X_W_target.translation = Vec3(0.05, 0.0, 0.0);
  dev->command(cmd);
  ASSERT_EQ(dev->read(0.05, s), DeviceStatus::kOk);  // one 50 ms gap
  EXPECT_TRUE(geom::finite(s.X_WD.translation));
  EXPECT_GT(s.X_WD.translation.x, 0.0);
  EXPECT_LT(s.X_WD.translation.x, 0.05);
  // time going backwards, or not a number, changes nothing
  const DeviceSample before = s;
  dev->read(0.01, s);
  EXPECT_EQ(std::memcmp(&before, &s, sizeof s), 0);
  dev->read(std::nan(""), s);
  EXPECT_EQ(std::memcmp(&before, &s, sizeof s), 0);
  dev->read(0.051, s);  // and time goes on from where it was
  EXPECT_NE(s.X_WD.translation.x, before.X_WD.translation.x);
}

TEST(SimDevice, ServoCallsDoNotAllocate) {
  DeviceOptions o;
  o.sim_idle_motion_after_s = 0.2;
  auto dev = open(o);
  DeviceSample s;
  PoseCommand c;
  const std::uint64_t before = testing_alloc::count();
  for (int i = 0; i < 2000; ++i) {
    if (i % 100 == 0)
      dev->command(c);
    dev->read(i * 1e-3, s);
    dev->write(Vec3(0.1, 0.0, 0.0), Vec3(0.0));
  }
  EXPECT_EQ(testing_alloc::count(), before);
}

TEST(SimDevice, BadSpecsAndOptionsAreRefusedWithTheirName) {
  DeviceOptions o;
  o.sim_hand_mass_kg = 0.0;
  auto r = makeDevice("sim", o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("sim_hand_mass_kg"), std::string::npos) << r.error().message;
  o = DeviceOptions{};
  o.sim_hand_damping_n_s_per_m = std::nan("");
  r = makeDevice("sim", o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("sim_hand_damping_n_s_per_m"), std::string::npos);
  // each bad spec, and what its message must contain
  const std::pair<const char*, std::vector<const char*>> bad_specs[] = {
      {"bogus", {"'bogus'", "unknown backend"}},
      {"sim:x", {"takes no argument"}},
      {"replay:", {"needs a file"}},
      {"usb:phantom", {"unknown usb device 'phantom'"}},
      {"", {}}};
  for (const auto& [spec, expect] : bad_specs) {
    r = makeDevice(spec, DeviceOptions{});
    ASSERT_FALSE(r.ok()) << spec;
    for (const char* text : expect)
      EXPECT_NE(r.error().message.find(text), std::string::npos) << spec;
  }
  auto ok = makeDevice("sim", DeviceOptions{});
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.value()->info().name, "sim");
  EXPECT_TRUE(ok.value()->info().capabilities & kCapPoseCommands);
}

}  // namespace
}  // namespace hapticd::device
