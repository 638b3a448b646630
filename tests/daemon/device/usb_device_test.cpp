// The usb device (Novint Falcon): packet encoding and decoding, stream reassembly, encoder
// angles, kinematics (forward/inverse round trip, the Jacobian against finite differences,
// J^T motor commands), and the device through a fake Falcon: pose in, commands out, homing,
// hotplug removal and arrival (and polling without hotplug), silence and I/O errors, no
// allocation.
#include "daemon/device/usb_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "daemon/device/falcon_firmware.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::device {
namespace {

using namespace falcon;

std::array<std::uint8_t, kPacketSize> bytesOf(const char* s) {
  std::array<std::uint8_t, kPacketSize> b{};
  for (std::size_t i = 0; i < kPacketSize; ++i)
    b[i] = static_cast<std::uint8_t>(s[i]);
  return b;
}

TEST(FalconPackets, OutLayoutAndRoundTrip) {
  OutPacket p;
  p.motor = {1, -1, 0x1234};
  p.leds = kLedGreen | kLedRed;
  p.homing_mode = true;
  std::array<std::uint8_t, kPacketSize> b{};
  encodeOut(p, b);
  // nibbles least significant first, each plus 'A'; byte 13 = 'A' + (0x0a | 0x01)
  EXPECT_EQ(b, bytesOf("<BAAAPPPPEDCBLA>"));
  OutPacket back;
  ASSERT_TRUE(decodeOut(b, back));
  EXPECT_EQ(back.motor, p.motor);
  EXPECT_EQ(back.leds, p.leds);
  EXPECT_TRUE(back.homing_mode);
}

TEST(FalconPackets, InRoundTripAndRefusals) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> enc(-32768, 32767);
  for (int k = 0; k < 1000; ++k) {
    InPacket p;
    for (auto& e : p.encoders)
      e = static_cast<std::int16_t>(enc(rng));
    p.homing_status = static_cast<std::uint8_t>(k % 8);
    p.buttons = static_cast<std::uint8_t>(k % 16);
    std::array<std::uint8_t, kPacketSize> b{};
    encodeIn(p, b);
    InPacket back;
    ASSERT_TRUE(decodeIn(b, back));
    EXPECT_EQ(back.encoders, p.encoders);
    EXPECT_EQ(back.homing_status, p.homing_status);
    EXPECT_EQ(back.buttons, p.buttons);
  }
  InPacket back;
  auto homed = bytesOf("<AAAAAAAAAAAAAA>");
  homed[13] = 0x41 + 0x75;  // homing bits 7, buttons 5
  EXPECT_TRUE(decodeIn(homed, back));
  EXPECT_EQ(back.homing_status, 7);
  EXPECT_EQ(back.buttons, 5);
  EXPECT_FALSE(decodeIn(bytesOf("[AAAAAAAAAAAAAA>"), back));  // framing
  EXPECT_FALSE(decodeIn(bytesOf("<AAAAAAAAAAAAAA]"), back));
  EXPECT_FALSE(decodeIn(bytesOf("<AAAAAQAAAAAAAA>"), back));  // 'Q' is not a nibble
  EXPECT_FALSE(decodeIn(bytesOf("<AAAAAAAAAAAA@A>"), back));  // below 'A'
}

TEST(FalconPackets, ReaderReassemblesAnyChunking) {
  InPacket a;
  a.encoders = {10, -20, 30};
  InPacket b;
  b.encoders = {-1, 2, -3};
  b.buttons = 4;
  std::array<std::uint8_t, kPacketSize> pa{}, pb{};
  encodeIn(a, pa);
  encodeIn(b, pb);
  std::vector<std::uint8_t> stream = {'x', 'y', '>'};       // garbage
  stream.insert(stream.end(), pa.begin(), pa.begin() + 9);  // a truncated packet...
  stream.insert(stream.end(), pa.begin(), pa.end());        // ...then a whole one
  stream.insert(stream.end(), {'<', 'A', 'Z', 'A', 'A', 'A', 'A', 'A', 'A', 'A', 'A', 'A', 'A', 'A',
                               'A', '>'});  // a bad nibble
  stream.insert(stream.end(), pb.begin(), pb.end());
  for (std::size_t chunk : {1u, 2u, 5u, 16u, 17u, 64u, 1000u}) {
    PacketReader r;
    int packets = 0;
    for (std::size_t i = 0; i < stream.size(); i += chunk)
      packets += r.feed(std::span(stream).subspan(i, std::min(chunk, stream.size() - i)));
    EXPECT_EQ(packets, 2) << chunk;
    EXPECT_EQ(r.latest().encoders, b.encoders) << chunk;
    EXPECT_EQ(r.latest().buttons, 4) << chunk;
    EXPECT_EQ(r.malformed(), 2u) << chunk;
  }
}

TEST(FalconKinematics, EncoderAngles) {
  EXPECT_DOUBLE_EQ(encoderToAngle(0), 35.0 * std::numbers::pi / 180.0);
  // 1280 counts per motor turn through a 14.25 / 110 capstan
  EXPECT_NEAR(encoderToAngle(1280) - encoderToAngle(0), 2.0 * std::numbers::pi * 14.25 / 110.0,
              1e-12);
  for (int c : {-32768, -1500, -1, 0, 1, 777, 32767})
    EXPECT_EQ(angleToEncoder(encoderToAngle(static_cast<std::int16_t>(c))), c);
}

// points of the Falcon's workspace (a 6 cm box around the home point; the corners of a 10 cm
// box are out of the arms' reach)
std::vector<Vec3> workspace(const Geometry& g) {
  const Vec3 home = homePosition(g);
  std::vector<Vec3> out;
  for (double x = -0.03; x <= 0.0301; x += 0.015)
    for (double y = -0.03; y <= 0.0301; y += 0.015)
      for (double z = -0.03; z <= 0.0301; z += 0.015)
        out.push_back(home + Vec3(x, y, z));
  return out;
}

TEST(FalconKinematics, ForwardThenInverseRoundTrip) {
  const Geometry g;
  const Vec3 home = homePosition(g);
  std::printf("  home (all arms at 35 deg): (%.6f, %.6f, %.6f) m\n", home.x, home.y, home.z);
  EXPECT_LT(std::hypot(home.x, home.y), 1e-12);  // on the axis, by symmetry
  EXPECT_GT(home.z, 0.08);
  EXPECT_LT(home.z, 0.2);
  double worst_p = 0.0;
  double worst_theta = 0.0;
  for (const Vec3& p : workspace(g)) {
    Vec3 theta;
    ASSERT_TRUE(inverseKinematics(g, p, theta)) << p.x << " " << p.y << " " << p.z;
    EXPECT_LT(glm::length(constraint(g, p, theta)), 1e-15);
    Vec3 p2;
    ASSERT_EQ(forwardKinematics(g, theta, home, p2), FkStatus::kConverged);
    worst_p = std::max(worst_p, glm::length(p2 - p));
    Vec3 theta2;
    ASSERT_TRUE(inverseKinematics(g, p2, theta2));
    worst_theta = std::max(worst_theta, glm::length(theta2 - theta));
  }
  std::printf("  125 points: |FK(IK(p)) - p| <= %.2e m, |IK(FK(theta)) - theta| <= %.2e rad\n",
              worst_p, worst_theta);
  EXPECT_LT(worst_p, 1e-12);
  EXPECT_LT(worst_theta, 1e-10);
}

TEST(FalconKinematics, JacobianMatchesFiniteDifferences) {
  const Geometry g;
  const Vec3 home = homePosition(g);
  const double h = 1e-6;
  double worst = 0.0;
  for (const Vec3& p : workspace(g)) {
    Vec3 theta;
    ASSERT_TRUE(inverseKinematics(g, p, theta));
    Mat3 J;
    ASSERT_TRUE(jacobian(g, p, theta, J));
    for (int j = 0; j < 3; ++j) {
      Vec3 tp = theta, tm = theta;
      tp[j] += h;
      tm[j] -= h;
      Vec3 pp, pm;
      ASSERT_EQ(forwardKinematics(g, tp, home, pp), FkStatus::kConverged);
      ASSERT_EQ(forwardKinematics(g, tm, home, pm), FkStatus::kConverged);
      const Vec3 fd = (pp - pm) / (2.0 * h);
      worst = std::max(worst, glm::length(fd - J[j]) / glm::length(J[j]));
    }
  }
  std::printf("  Jacobian vs central differences: worst relative error %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(FalconKinematics, MotorCommandsAreJacobianTransposeScaledTogether) {
  const Geometry g;
  const Vec3 p = homePosition(g) + Vec3(0.01, -0.02, 0.015);
  Vec3 theta;
  ASSERT_TRUE(inverseKinematics(g, p, theta));
  Mat3 J;
  ASSERT_TRUE(jacobian(g, p, theta, J));
  const Vec3 f(0.5, -1.0, 2.0);
  const Vec3 tau = glm::transpose(J) * f;
  // virtual work: tau . dtheta = F . dp for any small motion
  const Vec3 dtheta(1e-3, -2e-3, 5e-4);
  EXPECT_NEAR(glm::dot(tau, dtheta), glm::dot(f, J * dtheta), 1e-15);
  const auto small = motorCommands(g, p, theta, f, 32767);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(small[static_cast<std::size_t>(i)], std::lround(kMotorCountsPerNm * tau[i]));
  // a large force: the largest command sits at the limit, the ratios are kept
  const auto big = motorCommands(g, p, theta, 100.0 * f, 4096);
  const double largest =
      std::max({std::abs(tau.x), std::abs(tau.y), std::abs(tau.z)}) * std::abs(kMotorCountsPerNm);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(big[static_cast<std::size_t>(i)]), 4096);
    EXPECT_NEAR(big[static_cast<std::size_t>(i)],
                kMotorCountsPerNm * tau[i] * 100.0 * 4096.0 / (100.0 * largest), 0.5);
  }
  const auto none = motorCommands(g, p, theta, Vec3(std::nan(""), 0.0, 0.0), 4096);
  EXPECT_EQ(none, (std::array<std::int16_t, 3>{0, 0, 0}));
}

// --- the device through a fake Falcon -------------------------------------------------------

struct FakeFalcon {
  bool present = true;
  bool mute = false;                   // stops answering
  bool io_error = false;               // the next transfers fail
  bool firmware_loaded = true;         // else it does not answer
  std::vector<std::uint8_t> firmware;  // what loadFirmware received
  InPacket state;                      // what it reports
  std::array<std::uint8_t, 4096> pending{};
  std::size_t pending_n = 0;
  std::size_t chunk = 7;  // bytes handed out per read (reassembly across reads)
  OutPacket last;
  int commands = 0;
  int malformed_commands = 0;
};

class FakeUsbTransport final : public UsbTransport {
 public:
  explicit FakeUsbTransport(std::shared_ptr<FakeFalcon> f) : f_(std::move(f)) {}
  int read(std::span<std::uint8_t> buf) noexcept override {
    if (!f_->present || f_->io_error)
      return -1;
    const std::size_t n = std::min({f_->pending_n, f_->chunk, buf.size()});
    std::copy_n(f_->pending.begin(), n, buf.begin());
    std::copy(f_->pending.begin() + static_cast<std::ptrdiff_t>(n),
              f_->pending.begin() + static_cast<std::ptrdiff_t>(f_->pending_n),
              f_->pending.begin());
    f_->pending_n -= n;
    return static_cast<int>(n);
  }
  int write(std::span<const std::uint8_t> bytes) noexcept override {
    if (!f_->present || f_->io_error)
      return -1;
    if (bytes.size() != kPacketSize ||
        !decodeOut(std::span<const std::uint8_t, kPacketSize>(bytes.data(), kPacketSize),
                   f_->last)) {
      ++f_->malformed_commands;
      return static_cast<int>(bytes.size());
    }
    ++f_->commands;
    if (!f_->mute && f_->firmware_loaded && f_->pending_n + kPacketSize <= f_->pending.size()) {
      std::array<std::uint8_t, kPacketSize> reply{};
      encodeIn(f_->state, reply);
      std::copy(reply.begin(), reply.end(),
                f_->pending.begin() + static_cast<std::ptrdiff_t>(f_->pending_n));
      f_->pending_n += kPacketSize;
    }
    return static_cast<int>(bytes.size());
  }

 private:
  std::shared_ptr<FakeFalcon> f_;
};

class FakeUsbBackend final : public UsbBackend {
 public:
  explicit FakeUsbBackend(std::shared_ptr<FakeFalcon> f, bool hotplug)
      : f_(std::move(f)), hotplug_(hotplug) {}
  bool startHotplug(std::function<void(UsbHotplugEvent)> cb) override {
    if (!hotplug_)
      return false;
    cb_ = std::move(cb);
    return true;
  }
  void handleEvents() override {
    while (!events_.empty()) {
      const UsbHotplugEvent e = events_.front();
      events_.pop_front();
      if (cb_)
        cb_(e);
    }
  }
  int countFalcons() override { return f_->present ? 1 : 0; }
  Result<std::unique_ptr<UsbTransport>> open() override {
    if (!f_->present)
      return Error{"no device"};
    ++opens;
    f_->pending_n = 0;
    f_->io_error = false;
    return std::unique_ptr<UsbTransport>(std::make_unique<FakeUsbTransport>(f_));
  }
  Result<bool> loadFirmware(std::span<const std::uint8_t> firmware) override {
    if (!f_->present)
      return Error{"no device"};
    ++firmware_loads;
    f_->firmware.assign(firmware.begin(), firmware.end());
    f_->firmware_loaded = true;
    return true;
  }
  void unplug() {
    f_->present = false;
    f_->firmware_loaded = false;  // a power cycle loses the firmware
    if (hotplug_)
      events_.push_back(UsbHotplugEvent::kLeft);
  }
  void plug() {
    f_->present = true;
    if (hotplug_)
      events_.push_back(UsbHotplugEvent::kArrived);
  }
  int opens = 0;
  int firmware_loads = 0;

 private:
  std::shared_ptr<FakeFalcon> f_;
  bool hotplug_;
  std::function<void(UsbHotplugEvent)> cb_;
  std::deque<UsbHotplugEvent> events_;
};

struct Rig {
  std::shared_ptr<FakeFalcon> falcon = std::make_shared<FakeFalcon>();
  FakeUsbBackend* backend = nullptr;
  std::unique_ptr<FalconDevice> dev;
  explicit Rig(bool hotplug = true, DeviceOptions o = {}) {
    auto b = std::make_unique<FakeUsbBackend>(falcon, hotplug);
    backend = b.get();
    auto d = FalconDevice::open(std::move(b), o);
    EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
    dev = std::move(d).value();
  }
  // put the fake's encoders where the effector at p_F (Falcon frame) would read
  void moveTo(const Vec3& p_F) {
    Vec3 theta;
    ASSERT_TRUE(inverseKinematics(Geometry{}, p_F, theta));
    for (int i = 0; i < 3; ++i)
      falcon->state.encoders[static_cast<std::size_t>(i)] = angleToEncoder(theta[i]);
  }
};

Vec3 positionOfEncoders(const std::array<std::int16_t, 3>& e, Vec3& theta) {
  const Geometry g;
  theta = Vec3(encoderToAngle(e[0]), encoderToAngle(e[1]), encoderToAngle(e[2]));
  Vec3 p;
  EXPECT_EQ(forwardKinematics(g, theta, homePosition(g), p), FkStatus::kConverged);
  return p;
}

TEST(FalconDevice, EncodersInCommandsOutWithHoming) {
  Rig rig;
  FalconDevice& dev = *rig.dev;
  EXPECT_EQ(dev.info().capabilities & (kCapForce | kCapTorque | kCapOrientation), kCapForce);
  EXPECT_EQ(rig.falcon->commands, 2);  // probed and primed at open
  const Geometry g;
  const Vec3 home = homePosition(g);
  rig.moveTo(home + Vec3(0.01, 0.02, -0.015));
  rig.falcon->state.buttons = 0x5;
  DeviceSample s;
  ASSERT_EQ(dev.read(0.0, s), DeviceStatus::kOk);
  // the primed reply carried the encoders at open (zero): home
  EXPECT_LT(glm::length(s.X_WD.translation), 1e-12);
  ASSERT_EQ(dev.write(Vec3(1.0, 0.0, 0.0), Vec3(0.0)), DeviceStatus::kOk);
  // not homed yet: zero motors, homing mode, red LED
  EXPECT_EQ(rig.falcon->last.motor, (std::array<std::int16_t, 3>{0, 0, 0}));
  EXPECT_TRUE(rig.falcon->last.homing_mode);
  EXPECT_EQ(rig.falcon->last.leds, kLedRed);
  EXPECT_FALSE(dev.homed());
  ASSERT_EQ(dev.read(0.001, s), DeviceStatus::kOk);
  Vec3 theta;
  const Vec3 expected = positionOfEncoders(rig.falcon->state.encoders, theta) - home;
  EXPECT_LT(glm::length(s.X_WD.translation - expected), 1e-12);
  EXPECT_LT(glm::length(s.X_WD.translation - Vec3(0.01, 0.02, -0.015)), 2e-4);  // encoder steps
  EXPECT_EQ(s.buttons, 5u);
  // homed: the force goes out as J^T F
  rig.falcon->state.homing_status = 7;
  dev.write(Vec3(0.0), Vec3(0.0));
  ASSERT_EQ(dev.read(0.002, s), DeviceStatus::kOk);
  EXPECT_TRUE(dev.homed());
  const Vec3 f(2.0, -1.0, 3.0);
  ASSERT_EQ(dev.write(f, Vec3(0.5)), DeviceStatus::kOk);
  const auto want = motorCommands(g, expected + home, theta, f, 4096);
  EXPECT_EQ(rig.falcon->last.motor, want);
  EXPECT_NE(want, (std::array<std::int16_t, 3>{0, 0, 0}));
  EXPECT_FALSE(rig.falcon->last.homing_mode);
  EXPECT_EQ(rig.falcon->last.leds, kLedGreen);
  EXPECT_EQ(rig.falcon->malformed_commands, 0);
}

TEST(FalconDevice, VelocityByFiniteDifference) {
  Rig rig;
  const Vec3 home = homePosition(Geometry{});
  DeviceSample s;
  rig.dev->read(0.0, s);
  rig.dev->write(Vec3(0.0), Vec3(0.0));
  Vec3 prev(0.0);
  for (int i = 1; i <= 50; ++i) {
    rig.moveTo(home + Vec3(0.0, 0.0, 0.0004 * i));  // 0.4 m/s along z
    rig.dev->read(i * 1e-3, s);
    rig.dev->write(Vec3(0.0), Vec3(0.0));
    if (i > 2) {
      EXPECT_NEAR(s.linear_velocity.z, (s.X_WD.translation.z - prev.z) / 1e-3, 1e-9);
      EXPECT_NEAR(s.linear_velocity.z, 0.4, 0.4);  // quantised by the encoders
    }
    prev = s.X_WD.translation;
  }
}

void lostAndBack(bool hotplug) {
  Rig rig(hotplug);
  FalconDevice& dev = *rig.dev;
  DeviceSample s;
  ASSERT_EQ(dev.read(0.0, s), DeviceStatus::kOk);
  ASSERT_EQ(dev.write(Vec3(0.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_TRUE(dev.service());
  rig.backend->unplug();
  EXPECT_TRUE(dev.service());  // the removal is handed to the servo thread...
  EXPECT_EQ(dev.read(0.001, s), DeviceStatus::kLost);  // ...which stops at once
  EXPECT_FALSE(dev.connected());
  EXPECT_EQ(dev.write(Vec3(1.0), Vec3(0.0)), DeviceStatus::kLost);
  EXPECT_EQ(dev.disconnects(), 1u);
  EXPECT_FALSE(dev.service());  // still away
  EXPECT_FALSE(dev.service());
  EXPECT_EQ(dev.read(0.002, s), DeviceStatus::kLost);
  rig.backend->plug();
  rig.falcon->firmware_loaded = true;  // (loaded by another tool; see FirmwareLoadedWhenSilent)
  EXPECT_TRUE(dev.service());
  EXPECT_TRUE(dev.connected());
  EXPECT_EQ(rig.backend->opens, 2);
  rig.moveTo(homePosition(Geometry{}) + Vec3(0.0, 0.01, 0.0));
  ASSERT_EQ(dev.read(0.5, s), DeviceStatus::kOk);  // the primed reply
  dev.write(Vec3(0.0), Vec3(0.0));
  ASSERT_EQ(dev.read(0.501, s), DeviceStatus::kOk);
  EXPECT_NEAR(s.X_WD.translation.y, 0.01, 2e-4);
  EXPECT_FALSE(dev.homed());  // homing starts over after a reconnection
  EXPECT_EQ(dev.disconnects(), 1u);
}

TEST(FalconDevice, HotplugLostAndBack) {
  lostAndBack(true);
}
TEST(FalconDevice, PolledLostAndBackWithoutHotplug) {
  lostAndBack(false);
}

TEST(FalconDevice, SilenceAndIoErrorsAreLosses) {
  Rig rig;
  FalconDevice& dev = *rig.dev;
  DeviceSample s;
  ASSERT_EQ(dev.read(0.0, s), DeviceStatus::kOk);
  rig.falcon->mute = true;
  int t = 1;
  for (; t <= 1000; ++t) {
    dev.write(Vec3(0.0), Vec3(0.0));
    if (dev.read(t * 1e-3, s) == DeviceStatus::kLost)
      break;
  }
  EXPECT_EQ(t, 101);  // silent for more than usb_silence_lost_s = 0.1 s
  EXPECT_EQ(dev.disconnects(), 1u);
  rig.falcon->mute = false;
  EXPECT_TRUE(dev.service());  // still plugged in: reopened
  ASSERT_EQ(dev.read(1.0, s), DeviceStatus::kOk);
  rig.falcon->io_error = true;
  EXPECT_EQ(dev.write(Vec3(0.0), Vec3(0.0)), DeviceStatus::kLost);
  EXPECT_EQ(dev.disconnects(), 2u);
}

TEST(FalconDevice, ServoCallsDoNotAllocate) {
  Rig rig;
  rig.falcon->state.homing_status = 7;
  DeviceSample s;
  const Vec3 home = homePosition(Geometry{});
  const std::uint64_t before = testing_alloc::count();
  for (int i = 0; i < 3000; ++i) {
    rig.moveTo(home + Vec3(0.02 * std::sin(i * 1e-3), 0.0, 0.01 * std::cos(i * 2e-3)));
    ASSERT_EQ(rig.dev->read(i * 1e-3, s), DeviceStatus::kOk);
    ASSERT_EQ(rig.dev->write(Vec3(1.0, -0.5, 0.2), Vec3(0.0)), DeviceStatus::kOk);
  }
  EXPECT_EQ(testing_alloc::count(), before);
  EXPECT_EQ(rig.dev->kinematicsFailures(), 0u);
  EXPECT_EQ(rig.dev->malformedPackets(), 0u);
}

TEST(FalconDevice, OpenErrors) {
  auto f = std::make_shared<FakeFalcon>();
  f->present = false;
  auto d = FalconDevice::open(std::make_unique<FakeUsbBackend>(f, true), DeviceOptions{});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("device 'usb:falcon': no device found"), std::string::npos)
      << d.error().message;
  DeviceOptions o;
  o.usb_falcon_max_motor_command = 40000;
  f->present = true;
  d = FalconDevice::open(std::make_unique<FakeUsbBackend>(f, true), o);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("usb_falcon_max_motor_command"), std::string::npos);
  // the real libusb backend on this machine (no Falcon attached): a clear error, no crash
  auto real = makeDevice("usb", DeviceOptions{});
  if (!real.ok()) {
    std::printf("  makeDevice(\"usb\") here: %s\n", real.error().message.c_str());
    EXPECT_NE(real.error().message.find("usb:falcon"), std::string::npos);
  }
  auto any_hid = makeDevice("hid", DeviceOptions{});  // the real hidapi backend here
  if (!any_hid.ok()) {
    std::printf("  makeDevice(\"hid\") here: %s\n", any_hid.error().message.c_str());
    EXPECT_EQ(any_hid.error().message.rfind("device 'hid': ", 0), 0u);
  }
  auto hid = makeDevice("hid:/dev/nonexistent-hidraw", DeviceOptions{});
  ASSERT_FALSE(hid.ok());
  std::printf("  makeDevice(\"hid:/dev/nonexistent-hidraw\") here: %s\n",
              hid.error().message.c_str());
  EXPECT_NE(hid.error().message.find("'hid:/dev/nonexistent-hidraw'"), std::string::npos);
}

// random bytes, and random encoder packets through the device: no crash, finite poses
TEST(FalconPackets, RandomBytesNeverCrash) {
  std::mt19937 rng(9);
  PacketReader r;
  std::array<std::uint8_t, 64> buf{};
  for (int k = 0; k < 20000; ++k) {
    const std::size_t n = rng() % buf.size();
    for (std::size_t i = 0; i < n; ++i)
      buf[i] = (rng() % 4 == 0) ? std::uint8_t{'<'} : static_cast<std::uint8_t>(0x41 + rng() % 18);
    r.feed(std::span(buf).first(n));
  }
  EXPECT_GT(r.malformed(), 0u);
}

TEST(FalconDevice, AnyEncoderValuesGiveFinitePoses) {
  Rig rig;
  std::mt19937 rng(13);
  DeviceSample s;
  rig.falcon->state.homing_status = 7;
  for (int k = 0; k < 3000; ++k) {
    for (auto& e : rig.falcon->state.encoders)
      e = static_cast<std::int16_t>(rng());
    ASSERT_EQ(rig.dev->read(k * 1e-3, s), DeviceStatus::kOk);
    ASSERT_TRUE(std::isfinite(s.X_WD.translation.x) && std::isfinite(s.X_WD.translation.y) &&
                std::isfinite(s.X_WD.translation.z));
    ASSERT_EQ(rig.dev->write(Vec3(5.0, -5.0, 5.0), Vec3(0.0)), DeviceStatus::kOk);
    for (std::int16_t m : rig.falcon->last.motor)
      ASSERT_LE(std::abs(m), 4096);
  }
  std::printf("  3000 random encoder packets: %llu forward kinematics solves failed (pose held)\n",
              static_cast<unsigned long long>(rig.dev->kinematicsFailures()));
}

// A Falcon in its bootloader, as the loading protocol describes it: it greets at 9600 baud with
// DTR high, confirms 'A' at 140 kbaud, then echoes every byte.
class FakeBootloader final : public FtdiLink {
 public:
  bool control(std::uint8_t request, std::uint16_t value) override {
    if (fail_controls)
      return false;
    if (request == kFtdiSetBaudRate)
      baud = value;
    if (request == kFtdiSetLatencyTimer)
      latency = value;
    if (request == kFtdiModemCtrl && (value & 0x0100))
      dtr_high = (value & 1) != 0;
    if (request == kFtdiReset && value == kFtdiPurgeRx)
      pending.clear();
    return true;
  }
  int write(std::span<const std::uint8_t> bytes, unsigned) override {
    const std::vector<std::uint8_t> b(bytes.begin(), bytes.end());
    if (uploading) {
      for (std::uint8_t x : b) {
        pending.push_back(received.size() == corrupt_at ? static_cast<std::uint8_t>(x ^ 0xff) : x);
        received.push_back(x);
      }
    } else if (b == std::vector<std::uint8_t>{0x0a, 0x43, 0x0d} && baud == kFtdiBaud9600 &&
               dtr_high && !silent) {
      if (++hellos >= 3)  // it takes a few tries to wake up
        pending.insert(pending.end(), {0x0a, 0x44, 0x2c, 0x0d});
    } else if (b == std::vector<std::uint8_t>{'A'} && baud == kFtdiBaud140k && !dtr_high) {
      pending.push_back('A');
      uploading = true;
    }
    return static_cast<int>(b.size());
  }
  int read(std::span<std::uint8_t> buf, unsigned) override {
    const std::size_t n = std::min({buf.size(), pending.size(), std::size_t{20}});
    std::copy_n(pending.begin(), n, buf.begin());
    pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(n));
    return static_cast<int>(n);
  }
  std::uint16_t baud = 0, latency = 0;
  bool dtr_high = false, uploading = false, silent = false, fail_controls = false;
  int hellos = 0;
  std::size_t corrupt_at = static_cast<std::size_t>(-1);
  std::vector<std::uint8_t> pending, received;
};

std::vector<std::uint8_t> someFirmware(std::size_t n) {
  std::vector<std::uint8_t> f(n);
  for (std::size_t i = 0; i < n; ++i)
    f[i] = static_cast<std::uint8_t>(i * 37 + 11);
  return f;
}

TEST(FalconFirmware, LoadsThroughTheBootloaderProtocol) {
  FakeBootloader link;
  const auto fw = someFirmware(1000);  // 16 chunks of 62 and a short one
  auto r = loadFirmware(link, fw);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(link.received, fw);
  EXPECT_EQ(link.hellos, 3);
  // left in the normal mode
  EXPECT_EQ(link.baud, kFtdiBaudNormal);
  EXPECT_EQ(link.latency, 1);
}

TEST(FalconFirmware, EachFailureSaysWhere) {
  const auto fw = someFirmware(300);
  {
    FakeBootloader link;
    link.corrupt_at = 130;
    auto r = loadFirmware(link, fw);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("echo mismatch at byte 130"), std::string::npos)
        << r.error().message;
  }
  {
    FakeBootloader link;
    link.silent = true;
    auto r = loadFirmware(link, fw);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("the bootloader did not answer"), std::string::npos);
  }
  {
    FakeBootloader link;
    link.fail_controls = true;
    auto r = loadFirmware(link, fw);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("FTDI request failed while entering the bootloader"),
              std::string::npos);
  }
  FakeBootloader link;
  EXPECT_FALSE(loadFirmware(link, {}).ok());
}

TEST(FalconDevice, FirmwareLoadedWhenSilent) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto path = dir / "hapticd_test_falcon_firmware.bin";
  const auto fw = someFirmware(500);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(fw.data()), static_cast<std::streamsize>(fw.size()));
  }
  auto falcon_state = std::make_shared<FakeFalcon>();
  falcon_state->firmware_loaded = false;
  // without a firmware file: a clear refusal
  {
    auto d =
        FalconDevice::open(std::make_unique<FakeUsbBackend>(falcon_state, true), DeviceOptions{});
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("its firmware is not loaded"), std::string::npos)
        << d.error().message;
  }
  // a missing file: named
  {
    DeviceOptions o;
    o.usb_falcon_firmware = "/nonexistent/falcon.bin";
    auto d = FalconDevice::open(std::make_unique<FakeUsbBackend>(falcon_state, true), o);
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("usb_falcon_firmware '/nonexistent/falcon.bin'"),
              std::string::npos);
    o.usb_falcon_firmware = "/dev/zero";  // never read forever
    d = FalconDevice::open(std::make_unique<FakeUsbBackend>(falcon_state, true), o);
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("not a regular file"), std::string::npos);
  }
  DeviceOptions o;
  o.usb_falcon_firmware = path.string();
  auto backend = std::make_unique<FakeUsbBackend>(falcon_state, true);
  FakeUsbBackend* b = backend.get();
  auto d = FalconDevice::open(std::move(backend), o);
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_EQ(b->firmware_loads, 1);
  EXPECT_EQ(falcon_state->firmware, fw);
  DeviceSample s;
  EXPECT_EQ(d.value()->read(0.0, s), DeviceStatus::kOk);
  // a power cycle (unplug, plug) loses the firmware: loaded again on reconnection
  b->unplug();
  d.value()->service();
  EXPECT_EQ(d.value()->read(0.001, s), DeviceStatus::kLost);
  b->plug();
  EXPECT_TRUE(d.value()->service());
  EXPECT_EQ(b->firmware_loads, 2);
  EXPECT_EQ(d.value()->read(0.5, s), DeviceStatus::kOk);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hapticd::device
