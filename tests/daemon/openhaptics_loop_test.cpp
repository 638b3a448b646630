// The real servo loop in device-clocked mode with the openhaptics backend over the fake HD library
// (tests/daemon/device/fake_hd.cpp): every tick runs inside the fake scheduler's callback, between
// hdBeginFrame and hdEndFrame, on the virtual clock; a fake simulation (a wall at y = 0, 600 N/m).
// Forces within the limits and the step limit; torque on a 6-DOF device, dropped and counted on a
// 3-DOF one; an HD error fades the force to zero; a disconnect zeroes it at once; a reconnection
// (service()) needs re-arming; a calibration that is not ok is a fault.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "daemon/device/hd_api.h"
#include "daemon/device/openhaptics_device.h"
#include "daemon/servo_loop.h"
#include "tests/daemon/device/fake_hd.h"
#include "tests/daemon/fakes.h"
#include "tests/daemon/vendor_loop.h"

namespace hapticd::daemon {
namespace {

using testing::length;
using testing::stepFrom;

struct Rig : testing::VendorLoopRig<device::OpenHapticsDevice> {
  Rig(const char* model,
      int output_dof,
      double force_n,
      double torque_mnm,
      std::uint64_t max_ticks) {
    fakeHd().reset(model, output_dof, force_n, torque_mnm);
    const double p[3] = {0.0, -50.0, 0.0};  // 5 cm below the wall (mm)
    const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    fakeHd().set_pose(p, R);
    auto api = device::hd::loadApi(HAPTICD_FAKE_HD);
    EXPECT_TRUE(api.ok());
    ServoOptions so;
    so.max_ticks = max_ticks;
    start(device::OpenHapticsDevice::open(api.value(), "", device::DeviceOptions{}), so);
  }
  std::vector<FakeHdFrame> frames() const {
    const FakeHdFrame* f = fakeHd().records();
    return {f, f + std::min<std::uint64_t>(fakeHd().frame_count(), kFakeHdForceCapacity)};
  }
};

// waits (bounded) until the scheduler waits at its pause of frame `frame`
bool waitPausedAt(std::uint64_t frame) {
  auto there = [&] { return fakeHd().paused() != 0 && fakeHd().frames() == frame; };
  for (int i = 0; i < 20000 && !there(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return there();
}

TEST(OpenHapticsLoop, EveryTickRunsInsideASchedulerFrameWithinTheLimits) {
  Rig rig("Touch", 3, 3.3, 0.0, 1000);
  EXPECT_EQ(rig.loop->run(), ServoExit::kMaxTicks);
  EXPECT_EQ(fakeHd().frames(), 1000u);  // the device's scheduler ran every tick
  EXPECT_EQ(fakeHd().misuse(), 0u);     // every state call inside a frame, on its thread
  const auto f = rig.frames();
  ASSERT_EQ(f.size(), 1000u);
  const ServoOptions defaults;
  double previous[3] = {0.0, 0.0, 0.0};
  for (const FakeHdFrame& r : f) {
    EXPECT_LE(length(r.force), 3.3 + 1e-12);
    EXPECT_LE(stepFrom(previous, r.force), defaults.max_force_step_n + 1e-12);
    EXPECT_EQ(length(r.torque), 0.0);  // 3-DOF force: no torque sent
  }
  EXPECT_NEAR(f.back().force[1], 3.3, 1e-9);  // the wall pushes up (y)
  // the fake simulation's torque never reaches the device: the output stage clamps it to the
  // Touch's 0 N m (what would reach it would be dropped and counted)
  EXPECT_EQ(rig.device->torquesDropped(), 0u);
  EXPECT_EQ(rig.loop->state().torque_W_nm, geom::Vec3(0.0));
  EXPECT_EQ(rig.loop->state().tick, 1000u);
}

TEST(OpenHapticsLoop, ASixDofDeviceGetsGimbalTorqueInMilliNewtonMetres) {
  Rig rig("PHANTOM Premium 1.5 6DOF", 6, 8.5, 515.0, 1000);
  EXPECT_EQ(rig.loop->run(), ServoExit::kMaxTicks);
  const auto f = rig.frames();
  ASSERT_EQ(f.size(), 1000u);
  for (const FakeHdFrame& r : f) {
    EXPECT_LE(length(r.force), 8.5 + 1e-12);
    EXPECT_LE(length(r.torque), 515.0 + 1e-9);
  }
  EXPECT_NEAR(f.back().torque[2], 515.0, 1e-6);  // the fake simulation's torque about z
  EXPECT_EQ(rig.device->torquesDropped(), 0u);
}

TEST(OpenHapticsLoop, AnHdErrorLatchesTheDeviceFaultAndFadesTheForceToZero) {
  Rig rig("Touch", 3, 3.3, 0.0, 500);
  fakeHd().at(300, kFakeHdError, 0x0201);  // HD_EXCEEDED_MAX_FORCE
  EXPECT_EQ(rig.loop->run(), ServoExit::kMaxTicks);
  EXPECT_NE(rig.loop->state().faults & kFaultDevice, 0u);
  EXPECT_GE(rig.device->faults(), 1u);
  const auto f = rig.frames();
  ASSERT_EQ(f.size(), 500u);
  EXPECT_NEAR(length(f[298].force), 3.3, 1e-9);
  double last = length(f[299].force);
  for (std::size_t i = 300; i < f.size(); ++i) {
    EXPECT_LE(length(f[i].force), last + 1e-12) << i;
    last = length(f[i].force);
  }
  EXPECT_GT(length(f[305].force), 0.0);  // a ramp, not a cut
  EXPECT_EQ(last, 0.0);
}

TEST(OpenHapticsLoop, ADisconnectZeroesTheForceAtOnceAndAReconnectionNeedsReArming) {
  Rig rig("Touch", 3, 3.3, 0.0, 1500);
  fakeHd().at(300, kFakeHdDisconnect, 0);
  fakeHd().at(500, kFakeHdReconnect, 0);
  fakeHd().at(600, kFakeHdPause, 0);
  fakeHd().at(700, kFakeHdPause, 0);
  ServoExit exit = ServoExit::kStopped;
  std::atomic<bool> finished{false};
  std::thread servo([&] {
    exit = rig.loop->run();
    finished = true;
  });
  struct Joiner {  // whatever fails below, the scheduler is let go and the thread joined
    std::thread& t;
    std::atomic<bool>& finished;
    ~Joiner() {
      for (int i = 0; i < 60000 && !finished.load(); ++i) {
        fakeHd().resume();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      t.join();
    }
  } joiner{servo, finished};
  ASSERT_TRUE(waitPausedAt(600));  // reconnected at 500
  ServoState st = rig.loop->state();
  EXPECT_FALSE(st.device_connected);
  EXPECT_EQ(st.device_lost_count, 1u);
  EXPECT_EQ(st.force_W_n, geom::Vec3(0.0));
  auto f = rig.frames();
  const std::size_t before = f.size();
  ASSERT_GE(before, 299u);
  for (std::size_t i = 299; i < before; ++i)
    EXPECT_EQ(length(f[i].force), 0.0) << i;  // nothing but zero since the loss
  EXPECT_TRUE(rig.device->service());         // the callback's probe saw it back
  fakeHd().resume();
  ASSERT_TRUE(waitPausedAt(700));
  st = rig.loop->state();
  EXPECT_TRUE(st.device_connected);
  EXPECT_NE(st.faults & kFaultDevice, 0u);
  f = rig.frames();
  ASSERT_GT(f.size(), before);
  for (std::size_t i = before; i < f.size(); ++i)
    EXPECT_EQ(length(f[i].force), 0.0) << i;  // held since it came back
  ServoCommand arm;
  arm.kind = CommandKind::kArm;
  ASSERT_TRUE(rig.loop->sendCommand(arm));
  fakeHd().resume();
  for (int i = 0; i < 60000 && !finished.load(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(finished.load());
  EXPECT_EQ(exit, ServoExit::kMaxTicks);
  EXPECT_EQ(rig.loop->state().faults, 0u);
  f = rig.frames();
  EXPECT_NEAR(length(f.back().force), 3.3, 1e-9);
  EXPECT_EQ(fakeHd().misuse(), 0u);
}

TEST(OpenHapticsLoop, ACalibrationThatIsNotOkIsAFault) {
  Rig rig("Touch", 3, 3.3, 0.0, 200);
  fakeHd().set_calibration(device::hd::kCalibrationNeedsUpdate);
  EXPECT_EQ(rig.loop->run(), ServoExit::kMaxTicks);
  EXPECT_NE(rig.loop->state().faults & kFaultDevice, 0u);
  EXPECT_EQ(rig.device->calibration(), device::hd::kCalibrationNeedsUpdate);
  EXPECT_EQ(rig.device->uncalibratedTicks(), 200u);
  EXPECT_EQ(length(rig.frames().back().force), 0.0);
}

}  // namespace
}  // namespace hapticd::daemon
