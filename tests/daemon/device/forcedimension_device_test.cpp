// The forcedimension backend against the fake DHD library (fake_dhd.cpp, built by the tests and
// loaded by path like the real SDK): the missing library, opening (model, serial, DOF, limits,
// gravity compensation and brakes), pose and buttons in the device frame, forces in the SDK's
// frame only while live, dropped torque, several devices by index, errors as faults and losses,
// reconnection by service() that needs re-arming, and no allocation in the servo-thread calls.
#include "daemon/device/forcedimension_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "core/geometry/rotation.h"
#include "daemon/device/device.h"
#include "daemon/device/dhd_api.h"
#include "tests/core/alloc_counter.h"
#include "tests/daemon/device/fake_dhd.h"

namespace hapticd::device {
namespace {

DeviceOptions fakeOptions() {
  DeviceOptions o;
  o.forcedimension_library = HAPTICD_FAKE_DHD;
  return o;
}

std::unique_ptr<ForceDimensionDevice> openFake(int index = 0) {
  auto api = dhd::loadApi(HAPTICD_FAKE_DHD);
  EXPECT_TRUE(api.ok()) << api.error().message;
  auto d = ForceDimensionDevice::open(api.value(), index, fakeOptions());
  EXPECT_TRUE(d.ok()) << d.error().message;
  return d.ok() ? std::move(d).value() : nullptr;
}

TEST(ForceDimensionDevice, AMissingLibraryIsAOneLineErrorNamingTheLibraryAndTheSdk) {
  DeviceOptions o;
  o.forcedimension_library = "/nonexistent/libdhd.so";
  auto d = makeDevice("forcedimension", o);
  ASSERT_FALSE(d.ok());
  const std::string& m = d.error().message;
  EXPECT_EQ(m.rfind("device 'forcedimension:0': cannot load the Force Dimension DHD library", 0),
            0u)
      << m;
  EXPECT_NE(m.find("/nonexistent/libdhd.so"), std::string::npos) << m;
  EXPECT_NE(m.find("install the Force Dimension SDK"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(ForceDimensionDevice, TheDefaultNamesAreTheSdksAndTheEnvironmentVariableOverridesThem) {
  ::unsetenv(dhd::kLibraryEnv);
  auto none = makeDevice("forcedimension", DeviceOptions{});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("tried libdhd.so, libdhd.so.3"), std::string::npos)
      << none.error().message;
  fakeDhd().reset(1, 104);
  ::setenv(dhd::kLibraryEnv, HAPTICD_FAKE_DHD, 1);
  auto d = makeDevice("forcedimension", DeviceOptions{});
  ::unsetenv(dhd::kLibraryEnv);
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_EQ(d.value()->info().model, "sigma.7");
}

TEST(ForceDimensionDevice, SpecsTakeAnIndexFrom0To15) {
  auto a = parseDeviceSpec("forcedimension");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.value().backend, DeviceSpec::Backend::kForceDimension);
  EXPECT_EQ(a.value().arg, "0");
  auto b = parseDeviceSpec("forcedimension:3");
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.value().arg, "3");
  EXPECT_FALSE(b.value().openIsHarmless());
  for (const char* bad : {"forcedimension:", "forcedimension:x", "forcedimension:16",
                          "forcedimension:-1", "forcedimension:1x"}) {
    auto r = parseDeviceSpec(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_NE(r.error().message.find("from 0 to 15"), std::string::npos) << r.error().message;
  }
}

TEST(ForceDimensionDevice, OpensWithGravityCompensationAndBrakesAndReportsWhatItIs) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  const DeviceInfo& i = d->info();
  EXPECT_EQ(i.name, "forcedimension:0 sigma.7");
  EXPECT_EQ(i.model, "sigma.7");
  EXPECT_EQ(i.serial, "1200");
  EXPECT_EQ(i.sensing_dof, 7);
  EXPECT_EQ(i.force_dof, 7);
  EXPECT_EQ(i.limits.max_force_n, 10.0);   // the configured 10 N under the sigma.7's 20 N
  EXPECT_EQ(i.limits.max_torque_nm, 0.4);  // the sigma.7's 0.4 N m under the configured 1
  EXPECT_NE(i.capabilities & kCapTorque, 0u);
  EXPECT_NE(i.capabilities & kCapOrientation, 0u);
  EXPECT_EQ(
      describeDevice(i),
      "forcedimension:0 sigma.7: serial 1200, sensing 7 DOF, force 7 DOF, limits 10 N 0.4 N m");
  const FakeDhdState s = fakeDhd().state(0);
  EXPECT_TRUE(s.open);
  EXPECT_TRUE(s.gravity);
  EXPECT_TRUE(s.brakes);
  EXPECT_FALSE(s.forces_on);
  d.reset();
  EXPECT_FALSE(fakeDhd().state(0).open);  // closed, brakes on
  EXPECT_TRUE(fakeDhd().state(0).brakes);
}

TEST(ForceDimensionDevice, PoseButtonsAndGripperInTheDeviceFrame) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  // SDK frame: x toward the user, y right, z up; a quarter turn about the SDK's z (up)
  const double p[3] = {0.01, 0.02, 0.03};
  const double R[9] = {0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0};
  fakeDhd().set_pose(0, p, R);
  fakeDhd().set_buttons(0, 0b101, 0.25);
  DeviceSample s;
  ASSERT_EQ(d->read(0.0, s), DeviceStatus::kOk);
  // device frame: x right, y up, z toward the user
  EXPECT_EQ(s.X_WD.translation, Vec3(0.02, 0.03, 0.01));
  const geom::Quat want = glm::angleAxis(M_PI / 2, Vec3(0.0, 1.0, 0.0));  // about up
  EXPECT_NEAR(std::abs(glm::dot(s.X_WD.rotation, want)), 1.0, 1e-12);
  EXPECT_EQ(s.buttons, 0b101u);
  EXPECT_EQ(s.gripper_rad, 0.25);
  // velocity: the backward difference
  const double p2[3] = {0.01, 0.02, 0.031};
  fakeDhd().set_pose(0, p2, R);
  ASSERT_EQ(d->read(0.001, s), DeviceStatus::kOk);
  EXPECT_NEAR(s.linear_velocity.y, 1.0, 1e-9);
  EXPECT_NEAR(s.linear_velocity.x, 0.0, 1e-9);
}

TEST(ForceDimensionDevice, ForcesGoOutInTheSdkFrameOnlyWhileLive) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  EXPECT_EQ(d->write(Vec3(1.0, 2.0, 3.0), Vec3(0.1, 0.2, 0.3)), DeviceStatus::kOk);
  EXPECT_EQ(fakeDhd().state(0).force_calls, 0u);  // braked: nothing sent
  d->setOutputHeld(false);
  EXPECT_TRUE(fakeDhd().state(0).forces_on);
  EXPECT_FALSE(fakeDhd().state(0).brakes);
  EXPECT_FALSE(d->braked());
  EXPECT_EQ(d->write(Vec3(1.0, 2.0, 3.0), Vec3(0.1, 0.2, 0.3)), DeviceStatus::kOk);
  ASSERT_EQ(fakeDhd().state(0).force_calls, 1u);
  const FakeDhdForce& f = fakeDhd().forces(0)[0];
  EXPECT_EQ(f.force[0], 3.0);  // SDK x = device z
  EXPECT_EQ(f.force[1], 1.0);
  EXPECT_EQ(f.force[2], 2.0);
  EXPECT_EQ(f.torque[0], 0.3);
  EXPECT_EQ(f.torque[1], 0.1);
  EXPECT_EQ(f.torque[2], 0.2);
  EXPECT_EQ(f.gripper, 0.0);
  EXPECT_EQ(f.forces_on, 1);
  d->setOutputHeld(true);
  EXPECT_TRUE(fakeDhd().state(0).brakes);
  EXPECT_FALSE(fakeDhd().state(0).forces_on);
  EXPECT_TRUE(d->braked());
}

TEST(ForceDimensionDevice, WithoutAnActiveWristTorqueIsDroppedAndCounted) {
  fakeDhd().reset(1, 33);  // omega.3
  auto d = openFake();
  ASSERT_TRUE(d);
  EXPECT_EQ(d->info().sensing_dof, 3);
  EXPECT_EQ(d->info().force_dof, 3);
  EXPECT_EQ(d->info().capabilities & (kCapTorque | kCapOrientation), 0u);
  EXPECT_EQ(d->info().limits.max_torque_nm, 0.0);
  d->setOutputHeld(false);
  EXPECT_EQ(d->write(Vec3(0.0, 1.0, 0.0), Vec3(0.1, 0.0, 0.0)), DeviceStatus::kOk);
  EXPECT_EQ(d->write(Vec3(0.0, 1.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  ASSERT_EQ(fakeDhd().state(0).force_calls, 2u);
  EXPECT_EQ(fakeDhd().forces(0)[0].torque[1], 0.0);
  EXPECT_EQ(fakeDhd().forces(0)[0].force[2], 1.0);
  EXPECT_EQ(d->torquesDropped(), 1u);
}

TEST(ForceDimensionDevice, SeveralDevicesByIndex) {
  fakeDhd().reset(2, 104);
  auto a = openFake(0);
  auto b = openFake(1);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->info().serial, "1200");
  EXPECT_EQ(b->info().serial, "1201");
  EXPECT_EQ(b->info().name, "forcedimension:1 sigma.7");
  b->setOutputHeld(false);
  EXPECT_EQ(b->write(Vec3(0.0, 1.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_EQ(fakeDhd().state(1).force_calls, 1u);
  EXPECT_EQ(fakeDhd().state(0).force_calls, 0u);
  auto c = makeDevice("forcedimension:2", fakeOptions());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("device 'forcedimension:2': no device found at index 2 (the "
                                   "SDK sees 2;"),
            std::string::npos)
      << c.error().message;
}

TEST(ForceDimensionDevice, AnErrorIsAFaultAndACommunicationErrorALoss) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  DeviceSample s;
  const double p[3] = {0.0, 0.0, 0.05};
  const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  fakeDhd().set_pose(0, p, R);
  ASSERT_EQ(d->read(0.0, s), DeviceStatus::kOk);
  fakeDhd().fail(0, dhd::kError, 1);
  ASSERT_EQ(d->read(0.001, s), DeviceStatus::kFault);
  EXPECT_EQ(s.X_WD.translation.y, 0.05);  // the last good sample
  EXPECT_EQ(d->faults(), 1u);
  EXPECT_TRUE(d->connected());
  ASSERT_EQ(d->read(0.002, s), DeviceStatus::kOk);
  fakeDhd().fail(0, dhd::kErrorCom, 1);
  EXPECT_EQ(d->read(0.003, s), DeviceStatus::kLost);
  EXPECT_FALSE(d->connected());
  EXPECT_EQ(d->disconnects(), 1u);
  EXPECT_EQ(d->read(0.004, s), DeviceStatus::kLost);
  EXPECT_EQ(d->write(Vec3(1.0), Vec3(0.0)), DeviceStatus::kLost);
  // a write error that is not a loss: the next read reports the fault
  EXPECT_TRUE(d->service());
  ASSERT_EQ(d->read(0.005, s), DeviceStatus::kFault);  // back after a loss
  d->setOutputHeld(true);
  d->setOutputHeld(false);
  fakeDhd().fail(0, dhd::kError, 1);
  EXPECT_EQ(d->write(Vec3(1.0), Vec3(0.0)), DeviceStatus::kFault);
  EXPECT_EQ(d->read(0.006, s), DeviceStatus::kFault);
  EXPECT_EQ(d->read(0.007, s), DeviceStatus::kOk);
}

TEST(ForceDimensionDevice, ReconnectsThroughServiceBrakedUntilReArmed) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  d->setOutputHeld(false);
  DeviceSample s;
  ASSERT_EQ(d->read(0.0, s), DeviceStatus::kOk);
  fakeDhd().set_present(0, 0);
  EXPECT_EQ(d->read(0.001, s), DeviceStatus::kLost);
  EXPECT_FALSE(d->service());  // not back yet
  fakeDhd().set_present(0, 1);
  EXPECT_TRUE(d->service());
  EXPECT_TRUE(d->connected());
  FakeDhdState st = fakeDhd().state(0);
  EXPECT_EQ(st.opens, 2u);
  EXPECT_TRUE(st.open && st.brakes && st.gravity && !st.forces_on);
  EXPECT_EQ(d->read(0.002, s), DeviceStatus::kFault);  // once: the loop latches a fault
  EXPECT_EQ(d->read(0.003, s), DeviceStatus::kOk);
  EXPECT_EQ(d->write(Vec3(0.0, 1.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_EQ(fakeDhd().state(0).force_calls, 0u);  // braked
  d->setOutputHeld(true);                         // the fault held the output...
  d->setOutputHeld(false);                        // ...until re-armed
  EXPECT_EQ(d->write(Vec3(0.0, 1.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_EQ(fakeDhd().state(0).force_calls, 1u);
}

TEST(ForceDimensionDevice, ServoThreadCallsAllocateNothing) {
  fakeDhd().reset(1, 104);
  auto d = openFake();
  ASSERT_TRUE(d);
  DeviceSample s;
  d->setOutputHeld(false);
  (void)d->read(0.0, s);
  (void)d->write(Vec3(0.0), Vec3(0.0));
  const std::uint64_t before = testing_alloc::count();
  for (int i = 1; i < 20000; ++i) {
    if (i % 1000 == 0)
      fakeDhd().fail(0, dhd::kError, 1);
    if (i % 500 == 0)
      d->setOutputHeld(i % 1000 == 0);
    (void)d->read(i * 0.001, s);
    (void)d->write(Vec3(0.0, 0.001 * (i % 7), 0.0), Vec3(0.01, 0.0, 0.0));
  }
  EXPECT_EQ(testing_alloc::count(), before);
  EXPECT_GT(fakeDhd().state(0).force_calls, 10000u);
}

}  // namespace
}  // namespace hapticd::device
