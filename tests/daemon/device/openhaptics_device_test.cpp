// The openhaptics backend against the fake HD library (fake_hd.cpp, built by the tests and loaded
// by path like the real libHD): the missing library, the spec, opening (model, serial, DOF,
// limits, torque capability) and an unknown device name. The device-clocked loop over the fake's
// scheduler: tests/daemon/openhaptics_loop_test.cpp.
#include "daemon/device/openhaptics_device.h"

#include <gtest/gtest.h>

#include "daemon/device/device.h"
#include "daemon/device/hd_api.h"
#include "tests/daemon/device/fake_hd.h"

namespace hapticd::device {
namespace {

DeviceOptions fakeOptions() {
  DeviceOptions o;
  o.openhaptics_library = HAPTICD_FAKE_HD;
  return o;
}

TEST(OpenHapticsDevice, AMissingLibraryIsAOneLineErrorNamingTheLibraryAndThePackage) {
  DeviceOptions o;
  o.openhaptics_library = "/nonexistent/libHD.so";
  auto d = makeDevice("openhaptics", o);
  ASSERT_FALSE(d.ok());
  const std::string& m = d.error().message;
  EXPECT_EQ(m.rfind("device 'openhaptics': cannot load the OpenHaptics HD library (tried "
                    "/nonexistent/libHD.so",
                    0),
            0u)
      << m;
  EXPECT_NE(m.find("install 3D Systems' OpenHaptics"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  ::unsetenv(hd::kLibraryEnv);
  auto none = makeDevice("openhaptics:Left", DeviceOptions{});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("device 'openhaptics:Left': cannot load the OpenHaptics HD "
                                      "library (tried libHD.so, libHD.so.3.4"),
            std::string::npos)
      << none.error().message;
}

TEST(OpenHapticsDevice, SpecsTakeAnOptionalDeviceName) {
  auto a = parseDeviceSpec("openhaptics");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.value().backend, DeviceSpec::Backend::kOpenHaptics);
  EXPECT_EQ(a.value().arg, "");
  auto b = parseDeviceSpec("openhaptics:Default Device");
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.value().arg, "Default Device");
  EXPECT_FALSE(b.value().openIsHarmless());
  auto c = parseDeviceSpec("openhaptics:");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("needs the device's configured name"), std::string::npos);
}

TEST(OpenHapticsDevice, ATouchReportsSixDofSensingThreeDofForceAndItsLimits) {
  fakeHd().reset("Touch", 3, 3.3, 0.0);
  auto d = makeDevice("openhaptics", fakeOptions());
  ASSERT_TRUE(d.ok()) << d.error().message;
  const DeviceInfo& i = d.value()->info();
  EXPECT_EQ(i.name, "openhaptics Touch");
  EXPECT_EQ(i.serial, "21100000042");
  EXPECT_EQ(i.sensing_dof, 6);
  EXPECT_EQ(i.force_dof, 3);
  EXPECT_EQ(i.limits.max_force_n, 3.3);
  EXPECT_EQ(i.limits.max_torque_nm, 0.0);
  EXPECT_EQ(i.capabilities & kCapTorque, 0u);
  EXPECT_NE(i.capabilities & kCapOrientation, 0u);
  EXPECT_TRUE(d.value()->ownsClock());
  EXPECT_EQ(
      describeDevice(i),
      "openhaptics Touch: serial 21100000042, sensing 6 DOF, force 3 DOF, limits 3.3 N 0 N m");
}

TEST(OpenHapticsDevice, APremiumSixDofRendersTorqueWithinItsNominalLimit) {
  fakeHd().reset("PHANTOM Premium 1.5 6DOF", 6, 8.5, 515.0);
  auto d = makeDevice("openhaptics:Default Device", fakeOptions());
  ASSERT_TRUE(d.ok()) << d.error().message;
  const DeviceInfo& i = d.value()->info();
  EXPECT_EQ(i.name, "openhaptics:Default Device PHANTOM Premium 1.5 6DOF");
  EXPECT_EQ(i.force_dof, 6);
  EXPECT_EQ(i.limits.max_force_n, 8.5);
  EXPECT_EQ(i.limits.max_torque_nm, 0.515);
  EXPECT_NE(i.capabilities & kCapTorque, 0u);
}

TEST(OpenHapticsDevice, AnUnknownNameIsAClearError) {
  fakeHd().reset("Touch", 3, 3.3, 0.0);
  auto d = makeDevice("openhaptics:Right Arm", fakeOptions());
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("device 'openhaptics:Right Arm': cannot initialise the device "
                                   "(HD error 0x0300;"),
            std::string::npos)
      << d.error().message;
  EXPECT_NE(d.error().message.find("is 'Right Arm' its configured name"), std::string::npos);
}

}  // namespace
}  // namespace hapticd::device
