// The real servo loop at 1 kHz on the virtual clock with the forcedimension backend over the fake
// DHD library (tests/daemon/device/fake_dhd.cpp), and a fake simulation (a wall at y = 0 pushing
// up with 600 N/m): every force the fake records is within the limits and the step limit, in the
// SDK's frame; a device error latches the device fault, fades the force to zero and then brakes;
// a disconnect zeroes the force at once; a reconnection stays braked until re-armed.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "daemon/device/dhd_api.h"
#include "daemon/device/forcedimension_device.h"
#include "daemon/servo_loop.h"
#include "tests/daemon/device/fake_dhd.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

FakeDhd& fake() {
  static FakeDhd f(HAPTICD_FAKE_DHD);
  return f;
}

double length(const double v[3]) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

struct Rig {
  std::unique_ptr<device::ForceDimensionDevice> device;
  VirtualClock clock;
  std::unique_ptr<ServoLoop> loop;
  std::uint64_t ticks = 0;

  explicit Rig(int type = 104) {
    fake().reset(1, type);
    // 5 cm below the wall (the SDK's z is up)
    const double p[3] = {0.0, 0.0, -0.05};
    const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    fake().set_pose(0, p, R);
    auto api = device::dhd::loadApi(HAPTICD_FAKE_DHD);
    EXPECT_TRUE(api.ok());
    device::DeviceOptions o;
    auto d = device::ForceDimensionDevice::open(api.value(), 0, o);
    EXPECT_TRUE(d.ok()) << d.error().message;
    device = std::move(d).value();
    ServoOptions so;
    so.limits = device->info().limits;  // as toServoOptions: the tighter of config and device
    so.ramp_in_s = 0.0;  // full force from the start (the output stage's ramp-in is tested apart)
    loop = std::make_unique<ServoLoop>(so, clock, *device,
                                       testing::servoSceneOf<testing::FakeSimulation>(1));
    loop->prepareServoThread();
  }
  void run(std::uint64_t n) {
    ticks += n;
    loop->setMaxTicks(ticks);
    EXPECT_EQ(loop->run(), ServoExit::kMaxTicks);
  }
  void arm() {
    ServoCommand c;
    c.kind = CommandKind::kArm;
    ASSERT_TRUE(loop->sendCommand(c));
  }
  std::vector<FakeDhdForce> forces() const {
    const FakeDhdState s = fake().state(0);
    const FakeDhdForce* f = fake().forces(0);
    return {f, f + std::min<std::uint64_t>(s.force_calls, kFakeDhdForceCapacity)};
  }
};

TEST(ForceDimensionLoop, EveryForceWithinTheLimitsAndTheStepLimitInTheSdkFrame) {
  Rig rig;
  rig.run(1000);
  const auto f = rig.forces();
  ASSERT_EQ(f.size(), 1000u);  // armed at the start: live from the first tick
  const ServoOptions defaults;
  double previous[3] = {0.0, 0.0, 0.0};
  for (const FakeDhdForce& r : f) {
    EXPECT_EQ(r.forces_on, 1);
    EXPECT_LE(length(r.force), 10.0 + 1e-12);  // the configured 10 N (sigma.7: 20 N)
    EXPECT_LE(length(r.torque), 0.4 + 1e-12);  // the sigma.7's 0.4 N m (configured: 1)
    const double d[3] = {r.force[0] - previous[0], r.force[1] - previous[1],
                         r.force[2] - previous[2]};
    EXPECT_LE(length(d), defaults.max_force_step_n + 1e-12);
    std::copy(r.force, r.force + 3, previous);
  }
  // the wall pushes up: the SDK's z; the fake simulation's torque about the device's z (toward
  // the user) is about the SDK's x
  EXPECT_NEAR(f.back().force[2], 10.0, 1e-9);
  EXPECT_NEAR(f.back().force[0], 0.0, 1e-12);
  EXPECT_NEAR(f.back().torque[0], 0.4, 1e-9);
  EXPECT_EQ(rig.loop->state().faults, 0u);
}

TEST(ForceDimensionLoop, ADeviceErrorLatchesAFaultFadesTheForceToZeroThenBrakes) {
  Rig rig;
  rig.run(500);
  const std::size_t before = rig.forces().size();
  fake().fail(0, device::dhd::kError, 1);  // the next call (the position read) fails
  rig.run(200);
  const ServoState st = rig.loop->state();
  EXPECT_NE(st.faults & kFaultDevice, 0u);
  EXPECT_EQ(faultNames(st.faults), "device");
  const auto f = rig.forces();
  ASSERT_GT(f.size(), before + 10);
  // a ramp: never rising, still above zero 10 ticks in, zero at the end
  double last = length(f[before - 1].force);
  EXPECT_NEAR(last, 10.0, 1e-9);
  for (std::size_t i = before; i < f.size(); ++i) {
    EXPECT_LE(length(f[i].force), last + 1e-12) << i;
    last = length(f[i].force);
  }
  EXPECT_GT(length(f[before + 10].force), 0.0);
  EXPECT_EQ(last, 0.0);
  // after the fade: braked, and no more force calls
  EXPECT_TRUE(fake().state(0).brakes);
  EXPECT_FALSE(fake().state(0).forces_on);
  EXPECT_LT(f.size(), before + 200);
  const std::size_t braked = f.size();
  rig.run(50);
  EXPECT_EQ(rig.forces().size(), braked);
  // re-armed: forces again
  rig.arm();
  rig.run(100);
  EXPECT_FALSE(fake().state(0).brakes);
  EXPECT_GT(rig.forces().size(), braked);
  EXPECT_EQ(rig.forces().back().forces_on, 1);
  EXPECT_GT(length(rig.forces().back().force), 0.0);
  EXPECT_EQ(rig.loop->state().faults, 0u);
}

TEST(ForceDimensionLoop, ADisconnectZeroesTheForceAtOnceAndAReconnectionNeedsReArming) {
  Rig rig;
  rig.run(500);
  EXPECT_NEAR(glm::length(rig.loop->state().force_W_n), 10.0, 1e-9);
  const std::size_t before = rig.forces().size();
  fake().set_present(0, 0);
  rig.run(1);
  ServoState st = rig.loop->state();
  EXPECT_EQ(st.force_W_n, geom::Vec3(0.0));  // at once, no ramp
  EXPECT_EQ(st.torque_W_nm, geom::Vec3(0.0));
  EXPECT_FALSE(st.device_connected);
  EXPECT_EQ(st.device_lost_count, 1u);
  rig.run(100);
  EXPECT_EQ(rig.loop->state().force_W_n, geom::Vec3(0.0));
  EXPECT_EQ(rig.forces().size(), before);  // nothing reached the (absent) device
  EXPECT_FALSE(rig.device->service());
  fake().set_present(0, 1);
  ASSERT_TRUE(rig.device->service());
  rig.run(200);
  st = rig.loop->state();
  EXPECT_TRUE(st.device_connected);
  EXPECT_NE(st.faults & kFaultDevice, 0u);  // back: the device fault holds the output
  EXPECT_TRUE(fake().state(0).brakes);
  EXPECT_EQ(rig.forces().size(), before);  // braked since it came back
  rig.arm();
  rig.run(100);
  EXPECT_EQ(rig.loop->state().faults, 0u);
  EXPECT_FALSE(fake().state(0).brakes);
  ASSERT_GT(rig.forces().size(), before);
  EXPECT_GT(length(rig.forces().back().force), 0.0);
  EXPECT_LE(length(rig.forces().back().force), 10.0 + 1e-12);
}

TEST(ForceDimensionLoop, DisarmedAtTheStartTheDeviceStaysBrakedUntilArmed) {
  fake().reset(1, 104);
  auto api = device::dhd::loadApi(HAPTICD_FAKE_DHD);
  ASSERT_TRUE(api.ok());
  auto d = device::ForceDimensionDevice::open(api.value(), 0, device::DeviceOptions{});
  ASSERT_TRUE(d.ok());
  VirtualClock clock;
  ServoOptions so;
  so.armed_at_start = false;
  so.max_ticks = 100;
  ServoLoop loop(so, clock, *d.value(), testing::servoSceneOf<testing::FakeSimulation>(1));
  loop.prepareServoThread();
  (void)loop.run();
  EXPECT_TRUE(fake().state(0).brakes);
  EXPECT_EQ(fake().state(0).force_calls, 0u);
}

}  // namespace
}  // namespace hapticd::daemon
