// The real servo loop at 1 kHz on the virtual clock with the haply backend over the fake Haply
// Inverse Service (tests/daemon/device/fake_haply.h, a WebSocket server on 127.0.0.1), and a fake
// simulation (a wall at y = 0 pushing up with 600 N/m). The exchange with the service runs on the
// device's I/O thread; the tests step the loop one tick at a time and wait (bounded, never a timing
// assertion) until the service has the tick's force, so that it receives every tick's force: all
// within the limits and the step limit, in Haply's frame; a service error fades the force to zero;
// a disconnect zeroes it at once; a reconnection needs re-arming.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "daemon/device/haply_device.h"
#include "tests/daemon/device/fake_haply.h"
#include "tests/daemon/vendor_loop.h"

namespace hapticd::daemon {
namespace {

using testing::eventually;
using testing::FakeHaply;

struct Rig {
  FakeHaply fake;
  testing::VendorLoopRig<device::HaplyDevice> rig;

  Rig() {
    fake.move({0.0, 0.0, -0.05});  // 5 cm below the wall (Haply's z is up)
    rig.start(device::HaplyDevice::open(fake.url(), device::DeviceOptions{}));
  }

  // n ticks, each waited for until the service has answered its force
  void step(std::uint64_t n) {
    for (std::uint64_t i = 0; i < n; ++i) {
      rig.run(1);
      const device::HaplyDevice& d = *rig.device;
      ASSERT_TRUE(eventually([&] {
        return !d.connected() || d.forcesAnswered() >= d.forcesWritten();
      })) << "tick "
          << rig.ticks;
    }
  }
};

double length(const std::array<double, 3>& v) {
  return testing::length(v.data());
}

TEST(HaplyLoop, EveryForceTheServiceReceivesIsWithinTheLimitsAndTheStepLimit) {
  Rig r;
  r.step(1000);
  const auto f = r.fake.forces();
  ASSERT_GE(f.size(), 1000u);  // every tick's force (and the keepalives), the ramp step by step
  const ServoOptions defaults;
  std::array<double, 3> previous{};
  for (const auto& g : f) {
    EXPECT_LE(length(g), 10.0 + 1e-12);
    const std::array<double, 3> d{g[0] - previous[0], g[1] - previous[1], g[2] - previous[2]};
    EXPECT_LE(length(d), defaults.max_force_step_n + 1e-12);
    previous = g;
  }
  // the wall pushes up: Haply's z
  EXPECT_NEAR(f.back()[2], 10.0, 1e-9);
  EXPECT_NEAR(f.back()[0], 0.0, 1e-12);
  EXPECT_NEAR(f.back()[1], 0.0, 1e-12);
  // the fake simulation's torque never reaches write(): the Inverse3's torque limit is 0
  EXPECT_EQ(r.rig.device->torquesDropped(), 0u);
  EXPECT_EQ(r.rig.loop->state().faults, 0u);
  EXPECT_EQ(r.fake.otherMessages(), 0u);
}

TEST(HaplyLoop, AServiceErrorLatchesTheDeviceFaultAndFadesTheForceToZero) {
  Rig r;
  r.step(500);
  r.fake.reportError(true);
  // the error reaches the servo thread with the next state message
  for (int i = 0; i < 5000 && (r.rig.loop->state().faults & kFaultDevice) == 0; ++i) {
    r.step(1);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_NE(r.rig.loop->state().faults & kFaultDevice, 0u);
  EXPECT_EQ(faultNames(r.rig.loop->state().faults), "device");
  const std::size_t before = r.fake.forces().size();
  r.step(200);
  const auto f = r.fake.forces();
  double last = length(f[before - 1]);
  EXPECT_NEAR(last, 10.0, 0.5 + 1e-9);  // at most one step into the fade
  for (std::size_t i = before; i < f.size(); ++i) {
    EXPECT_LE(length(f[i]), last + 1e-12) << i;
    last = length(f[i]);
  }
  EXPECT_GT(length(f[before + 5]), 0.0);  // a ramp, not a cut
  EXPECT_EQ(last, 0.0);
  EXPECT_GE(r.rig.device->faultTicks(), 1u);
  // the error gone and re-armed: forces again
  r.fake.reportError(false);
  ASSERT_TRUE(eventually([&] {
    device::DeviceSample s;
    return r.rig.device->read(0.0, s) == device::DeviceStatus::kOk;
  }));
  r.rig.arm();
  r.step(100);
  EXPECT_EQ(r.rig.loop->state().faults, 0u);
  EXPECT_NEAR(r.fake.forces().back()[2], 10.0, 1e-9);
}

TEST(HaplyLoop, ADisconnectZeroesTheForceAtOnceAndAReconnectionNeedsReArming) {
  Rig r;
  r.step(500);
  EXPECT_NEAR(glm::length(r.rig.loop->state().force_W_n), 10.0, 1e-9);
  r.fake.disconnect();
  ASSERT_TRUE(eventually([&] { return !r.rig.device->connected(); }));
  r.rig.run(1);
  ServoState st = r.rig.loop->state();
  EXPECT_EQ(st.force_W_n, geom::Vec3(0.0));  // at once, no ramp
  EXPECT_FALSE(st.device_connected);
  EXPECT_EQ(st.device_lost_count, 1u);
  r.rig.run(100);
  EXPECT_EQ(r.rig.loop->state().force_W_n, geom::Vec3(0.0));
  EXPECT_FALSE(r.rig.device->service());  // the service is still down
  r.fake.comeBack();
  ASSERT_TRUE(eventually([&] { return r.rig.device->service(); }));
  const std::size_t back = r.fake.forces().size();
  r.step(200);
  st = r.rig.loop->state();
  EXPECT_TRUE(st.device_connected);
  EXPECT_NE(st.faults & kFaultDevice, 0u);  // back: the device fault holds the output
  const auto f = r.fake.forces();
  ASSERT_GT(f.size(), back);
  for (std::size_t i = back; i < f.size(); ++i)
    EXPECT_EQ(length(f[i]), 0.0) << i;  // held since it came back
  r.rig.arm();
  r.step(100);
  EXPECT_EQ(r.rig.loop->state().faults, 0u);
  EXPECT_GT(r.fake.forces().back()[2], 0.0);  // live again, within the limit
  EXPECT_LE(length(r.fake.forces().back()), 10.0 + 1e-12);
  EXPECT_EQ(r.fake.connections(), 2u);
}

}  // namespace
}  // namespace hapticd::daemon
