// The haply backend against the fake Haply Inverse Service (fake_haply.h, a WebSocket server on
// 127.0.0.1): the spec and its URL, a missing service as a one-line error that says what to
// install, what the device reports, pose, velocity, orientation and buttons in the device frame,
// forces in Haply's frame (zero while held, torque dropped), a service error as a fault, a lost
// service (closed, silent, the Inverse3 gone) as a lost device, reconnection by service() that
// needs re-arming, and no allocation in the servo-thread calls.
#include "daemon/device/haply_device.h"

#include <gtest/gtest.h>

#include <boost/asio/ip/tcp.hpp>
#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "tests/core/alloc_counter.h"
#include "tests/daemon/device/fake_haply.h"

namespace hapticd::device {
namespace {

using testing::eventually;
using testing::FakeHaply;

// a loopback port with nothing listening on it
std::uint16_t closedPort() {
  boost::asio::io_context ioc;
  boost::asio::ip::tcp::acceptor a(ioc, {boost::asio::ip::make_address("127.0.0.1"), 0});
  return a.local_endpoint().port();
}

std::unique_ptr<HaplyDevice> openOn(const FakeHaply& fake, const DeviceOptions& o = {}) {
  auto d = HaplyDevice::open(fake.url(), o);
  EXPECT_TRUE(d.ok()) << d.error().message;
  return d.ok() ? std::move(d).value() : nullptr;
}

TEST(HaplyDevice, SpecTakesAWebSocketUrlAndDefaultsToTheServicesPort) {
  auto a = parseDeviceSpec("haply");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.value().backend, DeviceSpec::Backend::kHaply);
  EXPECT_EQ(a.value().arg, "ws://127.0.0.1:10001");
  auto b = parseDeviceSpec("haply:ws://[::1]:9000/sim");
  ASSERT_TRUE(b.ok()) << b.error().message;
  auto u = parseWsUrl(b.value().arg);
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(u.value().host, "::1");
  EXPECT_EQ(u.value().port, 9000);
  EXPECT_EQ(u.value().path, "/sim");
  for (const char* bad :
       {"haply:", "haply:http://127.0.0.1:10001", "haply:ws://127.0.0.1", "haply:ws://:10001",
        "haply:ws://h:0", "haply:ws://h:65536", "haply:ws://h:1x", "haply:wss://h:1"}) {
    auto r = parseDeviceSpec(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_NE(r.error().message.find(std::string("device '") + bad + "'"), std::string::npos)
        << r.error().message;
  }
  EXPECT_NE(parseDeviceSpec("haply:wss://h:1").error().message.find("TLS"), std::string::npos);
}

TEST(HaplyDevice, NoServiceIsAOneLineErrorThatSaysWhatToInstall) {
  const std::string url = "ws://127.0.0.1:" + std::to_string(closedPort());
  auto d = makeDevice("haply:" + url, DeviceOptions{});
  ASSERT_FALSE(d.ok());
  const std::string& m = d.error().message;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_EQ(
      m.rfind("device 'haply:" + url + "': cannot reach the Haply Inverse Service at " + url, 0),
      0u)
      << m;
  EXPECT_NE(m.find("install the Haply Inverse Service"), std::string::npos) << m;
  DeviceOptions bad;
  bad.haply_silence_lost_s = 0.0;
  EXPECT_NE(makeDevice("haply:" + url, bad).error().message.find("haply_silence_lost_s"),
            std::string::npos);
}

TEST(HaplyDevice, ReportsModelHandednessSerialDofAndLimits) {
  FakeHaply wired;
  DeviceOptions o;
  o.limits.max_force_n = 7.0;
  auto d = openOn(wired, o);
  ASSERT_TRUE(d);
  const DeviceInfo& i = d->info();
  EXPECT_EQ(i.model, "Inverse3 (right-handed) + VerseGrip");
  EXPECT_EQ(i.serial, "049D");
  EXPECT_EQ(i.sensing_dof, 6);
  EXPECT_EQ(i.force_dof, 3);
  EXPECT_EQ(i.capabilities, kCapPosition | kCapOrientation | kCapForce | kCapButtons);
  EXPECT_EQ(describeDevice(i), "haply:" + wired.url() +
                                   " Inverse3 (right-handed) + VerseGrip: serial 049D, sensing 6 "
                                   "DOF, force 3 DOF, limits 7 N 0 N m");
  EXPECT_TRUE(d->connected());

  FakeHaply::Options alone;
  alone.grip = false;
  alone.handedness = "left";
  alone.type = "minverse";
  FakeHaply bare(alone);
  auto e = openOn(bare);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->info().model, "Minverse (left-handed)");
  EXPECT_EQ(e->info().sensing_dof, 3);
  EXPECT_EQ(e->info().capabilities, kCapPosition | kCapForce);
}

TEST(HaplyDevice, PoseVelocityOrientationAndButtonsInTheDeviceFrame) {
  for (const bool wireless : {false, true}) {
    FakeHaply::Options fo;
    fo.wireless = wireless;
    FakeHaply fake(fo);
    auto d = openOn(fake);
    ASSERT_TRUE(d);
    // 90 degrees about Haply's z (up) is 90 degrees about the device's y (up)
    const double s = std::sqrt(0.5);
    fake.move({0.01, 0.02, 0.03}, {0.1, 0.2, 0.3});
    fake.turn({0.0, 0.0, s, s});
    fake.press(true, false, true);
    DeviceSample sample;
    double t = 0.0;
    EXPECT_TRUE(eventually([&] {
      t += 0.001;
      (void)d->write(Vec3(0.0), Vec3(0.0));  // commands keep the exchange going
      return d->read(t, sample) == DeviceStatus::kOk && sample.buttons != 0 &&
             sample.X_WD.translation.x != 0.0;
    }));
    EXPECT_NEAR(glm::length(sample.X_WD.translation - Vec3(0.01, 0.03, -0.02)), 0.0, 1e-15);
    EXPECT_NEAR(glm::length(sample.linear_velocity - Vec3(0.1, 0.3, -0.2)), 0.0, 1e-15);
    const Vec3 x = sample.X_WD.rotation * Vec3(1.0, 0.0, 0.0);
    EXPECT_NEAR(glm::length(x - Vec3(0.0, 0.0, -1.0)), 0.0, 1e-12);  // x turned toward -z
    EXPECT_EQ(sample.buttons, wireless ? 0b101u : 0b1u);             // a wired grip has one button
    EXPECT_EQ(d->badMessages(), 0u);
  }
}

TEST(HaplyDevice, ForcesReachTheServiceInHaplysFrameZeroWhileHeld) {
  FakeHaply fake;
  auto d = openOn(fake);
  ASSERT_TRUE(d);
  auto last = [&] {
    const auto f = fake.forces();
    return f.empty() ? std::array<double, 3>{-1, -1, -1} : f.back();
  };
  EXPECT_EQ(d->write(Vec3(1.0, 2.0, 3.0), Vec3(0.0, 0.0, 0.1)), DeviceStatus::kOk);
  EXPECT_TRUE(eventually([&] { return last() == std::array<double, 3>{1.0, -3.0, 2.0}; }));
  EXPECT_EQ(d->torquesDropped(), 1u);
  d->setOutputHeld(true);
  EXPECT_EQ(d->write(Vec3(1.0, 2.0, 3.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_TRUE(eventually([&] { return last() == std::array<double, 3>{0.0, 0.0, 0.0}; }));
  d->setOutputHeld(false);
  EXPECT_EQ(d->write(Vec3(0.5, 0.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_TRUE(eventually([&] { return last() == std::array<double, 3>{0.5, 0.0, 0.0}; }));
  EXPECT_EQ(fake.otherMessages(), 0u);  // every message hapticd sent was a set_cursor_force
  // with no new force the I/O thread still sends (the same force) at least every 10 ms
  const std::uint64_t n = fake.forceCount();
  EXPECT_TRUE(eventually([&] { return fake.forceCount() > n + 3; }));
  d.reset();  // closing sends a zero force
  EXPECT_EQ(last(), (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(HaplyDevice, AServiceErrorIsAFaultWhileItLasts) {
  FakeHaply fake;
  auto d = openOn(fake);
  ASSERT_TRUE(d);
  DeviceSample s;
  fake.reportError(true);
  EXPECT_TRUE(eventually([&] { return d->read(0.0, s) == DeviceStatus::kFault; }));
  EXPECT_GE(d->faultTicks(), 1u);
  EXPECT_TRUE(d->connected());
  fake.reportError(false);
  EXPECT_TRUE(eventually([&] { return d->read(0.0, s) == DeviceStatus::kOk; }));
}

TEST(HaplyDevice, ALostServiceIsALostDeviceAndAReconnectionNeedsReArming) {
  FakeHaply fake;
  auto d = openOn(fake);
  ASSERT_TRUE(d);
  DeviceSample s;
  EXPECT_EQ(d->write(Vec3(0.0, 4.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_TRUE(eventually([&] { return fake.forceCount() > 0 && fake.forces().back()[2] == 4.0; }));
  fake.disconnect();
  EXPECT_TRUE(eventually([&] { return !d->connected(); }));
  EXPECT_EQ(d->read(0.0, s), DeviceStatus::kLost);
  EXPECT_EQ(d->write(Vec3(0.0, 4.0, 0.0), Vec3(0.0)), DeviceStatus::kLost);
  EXPECT_EQ(d->disconnects(), 1u);
  EXPECT_FALSE(d->service());  // the service is still down
  EXPECT_FALSE(d->connected());
  fake.comeBack();
  const std::size_t before = fake.forceCount();
  EXPECT_TRUE(eventually([&] { return d->service(); }));
  EXPECT_TRUE(d->connected());
  EXPECT_EQ(fake.connections(), 2u);
  EXPECT_EQ(d->read(0.0, s), DeviceStatus::kFault);  // back: re-arm first
  EXPECT_EQ(d->read(0.001, s), DeviceStatus::kOk);
  // until the servo thread writes again the service gets zero, never the force from before
  EXPECT_TRUE(eventually([&] { return fake.forceCount() > before; }));
  EXPECT_EQ(fake.forces()[before], (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(HaplyDevice, ASilentServiceOrAVanishedInverse3IsALoss) {
  FakeHaply fake;
  auto d = openOn(fake);
  ASSERT_TRUE(d);
  fake.silent(true);
  EXPECT_TRUE(eventually([&] { return !d->connected(); }));
  EXPECT_EQ(d->disconnects(), 1u);
  fake.silent(false);
  EXPECT_TRUE(eventually([&] { return d->service(); }));
  fake.dropInverse3(true);
  EXPECT_TRUE(eventually([&] { return !d->connected(); }));
  EXPECT_EQ(d->disconnects(), 2u);
  // a service that lists no Inverse3 cannot be reconnected to
  EXPECT_FALSE(d->service());
  fake.dropInverse3(false);
  EXPECT_TRUE(eventually([&] { return d->service(); }));
}

TEST(HaplyDevice, ServoThreadCallsAllocateNothing) {
  FakeHaply fake;
  auto d = openOn(fake);
  ASSERT_TRUE(d);
  DeviceSample s;
  (void)d->read(0.0, s);
  const std::uint64_t before = testing_alloc::count();
  for (int i = 1; i <= 20000; ++i) {
    (void)d->read(i * 1e-3, s);
    (void)d->write(Vec3(0.0, 1e-4 * (i % 100), 0.0), Vec3(0.0, 0.0, 0.01));
    if (i % 5000 == 0)
      d->setOutputHeld(i % 10000 == 0);
  }
  EXPECT_EQ(testing_alloc::count(), before);
  EXPECT_TRUE(eventually([&] { return fake.forceCount() > 0; }));  // the I/O thread sent them
}

}  // namespace
}  // namespace hapticd::device
