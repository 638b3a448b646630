// The hid device: the generic report layout byte by byte and round trip, SpaceMouse reports per
// model and their integration, device selection, lost and back, no allocation — all through a
// fake transport.
#include "daemon/device/hid_device.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>

#include "core/geometry/rotation.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::device {
namespace {

// A fake HID device: input reports queued in a fixed buffer, output reports recorded in one;
// no allocation on the read/write path.
struct FakeHid {
  static constexpr std::size_t kCapacity = 8192;
  std::array<std::array<std::uint8_t, 64>, kCapacity> in{};
  std::array<int, kCapacity> in_size{};
  std::size_t in_head = 0, in_tail = 0;
  std::array<std::array<std::uint8_t, 64>, kCapacity> out{};
  std::size_t out_count = 0;
  bool present = true;
  bool open_fails = false;

  void push(std::span<const std::uint8_t> report) {
    ASSERT_LT(in_tail, kCapacity);
    std::copy(report.begin(), report.end(), in[in_tail].begin());
    in_size[in_tail++] = static_cast<int>(report.size());
  }
};

class FakeTransport final : public HidTransport {
 public:
  explicit FakeTransport(std::shared_ptr<FakeHid> d) : d_(std::move(d)) {}
  int readReport(std::span<std::uint8_t> buf) noexcept override {
    if (!d_->present)
      return -1;
    if (d_->in_head == d_->in_tail)
      return 0;
    const int n = std::min(d_->in_size[d_->in_head], static_cast<int>(buf.size()));
    std::copy_n(d_->in[d_->in_head].begin(), n, buf.begin());
    ++d_->in_head;
    return n;
  }
  int writeReport(std::span<const std::uint8_t> r) noexcept override {
    if (!d_->present)
      return -1;
    if (d_->out_count < FakeHid::kCapacity)
      std::copy(r.begin(), r.end(), d_->out[d_->out_count++].begin());
    return static_cast<int>(r.size());
  }

 private:
  std::shared_ptr<FakeHid> d_;
};

class FakeBackend final : public HidBackend {
 public:
  struct Slot {
    HidDeviceEntry entry;
    std::shared_ptr<FakeHid> dev;
  };
  std::vector<Slot> slots;
  std::vector<HidDeviceEntry> enumerate() override {
    std::vector<HidDeviceEntry> out;
    for (const Slot& s : slots)
      if (s.dev->present)
        out.push_back(s.entry);
    return out;
  }
  Result<std::unique_ptr<HidTransport>> open(const std::string& path) override {
    for (const Slot& s : slots)
      if (s.entry.path == path && s.dev->present) {
        if (s.dev->open_fails)
          return Error{"permission denied"};
        return std::unique_ptr<HidTransport>(std::make_unique<FakeTransport>(s.dev));
      }
    return Error{"no such device"};
  }
};

HidDeviceEntry genericEntry(std::string path) {
  return {std::move(path), 0x1209, 0x0001, kGenericUsagePage, kGenericUsage, "test arm"};
}

std::array<std::uint8_t, kGenericInputReportSize> inputReport(const Vec3& p,
                                                              const geom::Quat& q,
                                                              std::uint32_t buttons,
                                                              std::uint16_t seq) {
  GenericInputReport r;
  r.sequence = seq;
  r.X_WD = Pose{p, q};
  r.buttons = buttons;
  r.flags = kGenericFlagArmed;
  std::array<std::uint8_t, kGenericInputReportSize> bytes{};
  composeGenericInput(r, bytes);
  return bytes;
}

TEST(HidReports, GenericInputLayoutAndRoundTrip) {
  const geom::Quat q = glm::normalize(geom::Quat(0.9, 0.1, -0.3, 0.2));
  const auto bytes = inputReport(Vec3(0.001, -0.25, 1.5), q, 0x80000005u, 0xbeef);
  // the documented layout, byte by byte
  EXPECT_EQ(bytes[0], 0x01);
  EXPECT_EQ(bytes[1], 0xef);
  EXPECT_EQ(bytes[2], 0xbe);
  // x = 1000 um, little-endian int32
  EXPECT_EQ((std::array<std::uint8_t, 4>{bytes[3], bytes[4], bytes[5], bytes[6]}),
            (std::array<std::uint8_t, 4>{0xe8, 0x03, 0x00, 0x00}));
  // y = -250000 um = 0xfffc2f70
  EXPECT_EQ((std::array<std::uint8_t, 4>{bytes[7], bytes[8], bytes[9], bytes[10]}),
            (std::array<std::uint8_t, 4>{0x70, 0x2f, 0xfc, 0xff}));
  // qw at bytes 21-22
  const auto qw = static_cast<std::int16_t>(bytes[21] | (bytes[22] << 8));
  EXPECT_EQ(qw, static_cast<std::int16_t>(std::lround(q.w * 32767.0)));
  EXPECT_EQ(bytes[23], 0x05);
  EXPECT_EQ(bytes[26], 0x80);
  EXPECT_EQ(bytes[27], kGenericFlagArmed);

  GenericInputReport back;
  ASSERT_EQ(parseGenericInput(bytes, back), HidReportStatus::kOk);
  EXPECT_EQ(back.sequence, 0xbeef);
  EXPECT_LT(glm::length(back.X_WD.translation - Vec3(0.001, -0.25, 1.5)), 1e-12);
  EXPECT_LT(glm::length(geom::rotationVector(back.X_WD.rotation * glm::conjugate(q))), 1e-4);
  EXPECT_EQ(back.buttons, 0x80000005u);
  EXPECT_EQ(back.flags, kGenericFlagArmed);
  // compose(parse(bytes)) gives the same bytes
  std::array<std::uint8_t, kGenericInputReportSize> again{};
  composeGenericInput(back, again);
  EXPECT_EQ(again, bytes);
}

TEST(HidReports, GenericInputRefusals) {
  auto bytes = inputReport(Vec3(0.0), geom::Quat(1, 0, 0, 0), 0, 1);
  GenericInputReport r;
  EXPECT_EQ(parseGenericInput(std::span(bytes).first(27), r), HidReportStatus::kWrongSize);
  auto other = bytes;
  other[0] = 0x05;
  EXPECT_EQ(parseGenericInput(other, r), HidReportStatus::kIgnored);
  auto zero_q = bytes;
  for (int i = 15; i < 23; ++i)
    zero_q[static_cast<std::size_t>(i)] = 0;
  EXPECT_EQ(parseGenericInput(zero_q, r), HidReportStatus::kBadQuaternion);
  auto long_q = bytes;  // (1, 1, 0, 0) in int16 units: length sqrt(2)
  long_q[15] = 0xff;
  long_q[16] = 0x7f;
  EXPECT_EQ(parseGenericInput(long_q, r), HidReportStatus::kBadQuaternion);
}

TEST(HidReports, GenericOutputLayoutClampAndRoundTrip) {
  GenericOutputReport r;
  r.sequence = 7;
  r.force_n = Vec3(1.5, -40.0, 0.0004);
  r.torque_nm = Vec3(0.25, 0.0, -9.0);
  r.flags = kGenericFlagEnable;
  std::array<std::uint8_t, kGenericOutputReportSize> bytes{};
  composeGenericOutput(r, bytes);
  EXPECT_EQ(bytes[0], 0x02);
  EXPECT_EQ(bytes[1], 7);
  EXPECT_EQ(bytes[3], 0xdc);  // 1500 mN = 0x05dc
  EXPECT_EQ(bytes[4], 0x05);
  EXPECT_EQ(bytes[15], kGenericFlagEnable);
  GenericOutputReport back;
  ASSERT_EQ(parseGenericOutput(bytes, back), HidReportStatus::kOk);
  EXPECT_DOUBLE_EQ(back.force_n.x, 1.5);
  EXPECT_DOUBLE_EQ(back.force_n.y, -32.767);  // clamped to int16
  EXPECT_DOUBLE_EQ(back.force_n.z, 0.0);      // below 0.5 mN rounds to 0
  EXPECT_DOUBLE_EQ(back.torque_nm.x, 0.25);
  EXPECT_DOUBLE_EQ(back.torque_nm.z, -3.2767);
  r.force_n.x = std::nan("");
  composeGenericOutput(r, bytes);
  ASSERT_EQ(parseGenericOutput(bytes, back), HidReportStatus::kOk);
  EXPECT_EQ(back.force_n.x, 0.0);
}

std::vector<std::uint8_t> axes(std::uint8_t id, std::initializer_list<int> values) {
  std::vector<std::uint8_t> r{id};
  for (int v : values) {
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
    r.push_back(static_cast<std::uint8_t>(u & 0xff));
    r.push_back(static_cast<std::uint8_t>(u >> 8));
  }
  return r;
}

TEST(HidReports, SpaceMouseReportsPerModel) {
  const SpaceMouseModel* navigator = findSpaceMouse(0x046d, 0xc626);
  const SpaceMouseModel* wireless = findSpaceMouse(0x256f, 0xc62e);
  const SpaceMouseModel* pro = findSpaceMouse(0x046d, 0xc62b);
  const SpaceMouseModel* compact = findSpaceMouse(0x256f, 0xc635);
  ASSERT_TRUE(navigator && wireless && pro && compact);
  EXPECT_EQ(findSpaceMouse(0x046d, 0xc077), nullptr);  // a plain Logitech mouse
  EXPECT_EQ(navigator->reports, SpaceMouseReports::kSeparate);
  EXPECT_EQ(wireless->reports, SpaceMouseReports::kCombined);

  for (const SpaceMouseModel* m : {navigator, pro}) {  // separate translation and rotation
    SpaceMouseState s;
    ASSERT_EQ(parseSpaceMouse(*m, axes(1, {100, -200, 350}), s), HidReportStatus::kOk);
    ASSERT_EQ(parseSpaceMouse(*m, axes(2, {-5, 6, -32768}), s), HidReportStatus::kOk);
    EXPECT_EQ(s.translation, (std::array<std::int16_t, 3>{100, -200, 350}));
    EXPECT_EQ(s.rotation, (std::array<std::int16_t, 3>{-5, 6, -32768}));
    ASSERT_EQ(parseSpaceMouse(*m, std::vector<std::uint8_t>{3, 0x03, 0x10}, s),
              HidReportStatus::kOk);
    EXPECT_EQ(s.buttons, 0x1003u);
    EXPECT_EQ(parseSpaceMouse(*m, axes(2, {1, 2}), s), HidReportStatus::kWrongSize);
    EXPECT_EQ(parseSpaceMouse(*m, std::vector<std::uint8_t>{3}, s), HidReportStatus::kWrongSize);
    EXPECT_EQ(parseSpaceMouse(*m, axes(0x17, {1}), s), HidReportStatus::kIgnored);
  }
  for (const SpaceMouseModel* m : {wireless, compact}) {  // one combined report
    SpaceMouseState s;
    ASSERT_EQ(parseSpaceMouse(*m, axes(1, {1, 2, 3, 4, 5, 6}), s), HidReportStatus::kOk);
    EXPECT_EQ(s.translation, (std::array<std::int16_t, 3>{1, 2, 3}));
    EXPECT_EQ(s.rotation, (std::array<std::int16_t, 3>{4, 5, 6}));
    // a translation-only report is too short for these models
    EXPECT_EQ(parseSpaceMouse(*m, axes(1, {1, 2, 3}), s), HidReportStatus::kWrongSize);
    EXPECT_EQ(parseSpaceMouse(*m, axes(2, {9, 9, 9}), s), HidReportStatus::kIgnored);
    EXPECT_EQ(s.rotation, (std::array<std::int16_t, 3>{4, 5, 6}));
  }
}

TEST(HidReports, SpaceMouseIntegration) {
  DeviceOptions o;
  o.sim_home.translation = Vec3(0.0, 0.1, 0.0);
  SpaceMouseState s;
  integrateSpaceMouse(s, o, 0.0);  // starts at home
  EXPECT_EQ(s.X_WD.translation, o.sim_home.translation);
  // full deflection along HID x for 1 s: 0.1 m along device x
  s.translation = {350, 0, 0};
  for (int i = 1; i <= 1000; ++i)
    integrateSpaceMouse(s, o, i * 1e-3);
  EXPECT_NEAR(s.X_WD.translation.x, 0.1, 1e-12);
  EXPECT_NEAR(s.linear_velocity.x, 0.1, 1e-12);
  // HID y (toward the user) is device +z; HID z (down) is device -y; half deflection
  s.translation = {0, 175, 175};
  for (int i = 1001; i <= 2000; ++i)
    integrateSpaceMouse(s, o, i * 1e-3);
  EXPECT_NEAR(s.X_WD.translation.z, 0.05, 1e-12);
  EXPECT_NEAR(s.X_WD.translation.y, 0.1 - 0.05, 1e-12);
  // the deadband reads zero
  s.translation = {8, -8, 0};
  const Vec3 before = s.X_WD.translation;
  for (int i = 2001; i <= 3000; ++i)
    integrateSpaceMouse(s, o, i * 1e-3);
  EXPECT_EQ(s.X_WD.translation, before);
  // rotation about HID z (down) at full deflection for 0.5 s: 0.5 rad about device -y
  s.translation = {0, 0, 0};
  s.rotation = {0, 0, 350};
  for (int i = 3001; i <= 3500; ++i)
    integrateSpaceMouse(s, o, i * 1e-3);
  const Vec3 r = geom::rotationVector(s.X_WD.rotation);
  EXPECT_LT(glm::length(r - Vec3(0.0, -0.5, 0.0)), 1e-9);
  // the workspace box stops the integration
  s.rotation = {0, 0, 0};
  s.translation = {700, 0, 0};  // 0.2 m/s
  for (int i = 3501; i <= 6000; ++i)
    integrateSpaceMouse(s, o, i * 1e-3);
  EXPECT_DOUBLE_EQ(s.X_WD.translation.x, 0.2);
  EXPECT_EQ(s.linear_velocity.x, 0.0);
}

struct Rig {
  FakeBackend* backend = nullptr;
  std::shared_ptr<FakeHid> dev;
  std::unique_ptr<HidDevice> hid;
};

Rig openGeneric() {
  Rig rig;
  auto backend = std::make_unique<FakeBackend>();
  rig.backend = backend.get();
  rig.dev = std::make_shared<FakeHid>();
  // a keyboard first: "hid" must skip it
  backend->slots.push_back(
      {{"/dev/hidraw0", 0x046d, 0xc31c, 0x0001, 0x0006, "Keyboard"}, std::make_shared<FakeHid>()});
  backend->slots.push_back({genericEntry("/dev/hidraw3"), rig.dev});
  auto d = HidDevice::open(std::move(backend), "", DeviceOptions{});
  EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
  rig.hid = std::move(d).value();
  return rig;
}

TEST(HidDevice, GenericPoseInForceOut) {
  Rig rig = openGeneric();
  HidDevice& dev = *rig.hid;
  EXPECT_NE(dev.info().name.find("generic 6-DOF"), std::string::npos) << dev.info().name;
  EXPECT_NE(dev.info().name.find("/dev/hidraw3"), std::string::npos);
  EXPECT_TRUE(dev.info().capabilities & kCapForce);
  DeviceSample s;
  ASSERT_EQ(dev.read(0.0, s), DeviceStatus::kOk);  // no report yet: home
  EXPECT_EQ(s.X_WD.translation, Vec3(0.0));
  // three reports pending: the latest wins; a bad one in between is counted and skipped
  rig.dev->push(inputReport(Vec3(0.01, 0, 0), geom::Quat(1, 0, 0, 0), 1, 1));
  auto bad = inputReport(Vec3(0.5, 0, 0), geom::Quat(1, 0, 0, 0), 1, 2);
  for (int i = 15; i < 23; ++i)
    bad[static_cast<std::size_t>(i)] = 0;
  rig.dev->push(bad);
  rig.dev->push(inputReport(Vec3(0.02, 0, 0), geom::Quat(1, 0, 0, 0), 3, 3));
  ASSERT_EQ(dev.read(0.001, s), DeviceStatus::kOk);
  EXPECT_NEAR(s.X_WD.translation.x, 0.02, 1e-12);
  EXPECT_EQ(s.buttons, 3u);
  EXPECT_NEAR(s.linear_velocity.x, 20.0, 1e-6);  // 2 cm in 1 ms
  EXPECT_EQ(dev.badReports(), 1u);
  ASSERT_EQ(dev.write(Vec3(1.0, 2.0, -3.0), Vec3(0.0, 0.1, 0.0)), DeviceStatus::kOk);
  ASSERT_EQ(rig.dev->out_count, 1u);
  GenericOutputReport out;
  ASSERT_EQ(parseGenericOutput(std::span(rig.dev->out[0]).first(kGenericOutputReportSize), out),
            HidReportStatus::kOk);
  EXPECT_EQ(out.force_n, Vec3(1.0, 2.0, -3.0));
  EXPECT_DOUBLE_EQ(out.torque_nm.y, 0.1);
  EXPECT_EQ(out.flags, kGenericFlagEnable);
  EXPECT_EQ(out.sequence, 1u);
}

TEST(HidDevice, LostAndBack) {
  Rig rig = openGeneric();
  HidDevice& dev = *rig.hid;
  DeviceSample s;
  ASSERT_EQ(dev.read(0.0, s), DeviceStatus::kOk);
  EXPECT_TRUE(dev.connected());
  rig.dev->present = false;  // unplugged
  EXPECT_EQ(dev.read(0.001, s), DeviceStatus::kLost);
  EXPECT_FALSE(dev.connected());
  EXPECT_EQ(dev.disconnects(), 1u);
  EXPECT_EQ(dev.write(Vec3(1.0), Vec3(0.0)), DeviceStatus::kLost);
  EXPECT_EQ(dev.read(0.002, s), DeviceStatus::kLost);
  EXPECT_FALSE(dev.service());  // still away
  EXPECT_FALSE(dev.connected());
  // back, under another hidraw node
  auto again = std::make_shared<FakeHid>();
  rig.backend->slots.push_back({genericEntry("/dev/hidraw7"), again});
  EXPECT_TRUE(dev.service());
  EXPECT_TRUE(dev.connected());
  again->push(inputReport(Vec3(0.0, 0.03, 0.0), geom::Quat(1, 0, 0, 0), 0, 9));
  ASSERT_EQ(dev.read(0.5, s), DeviceStatus::kOk);
  EXPECT_NEAR(s.X_WD.translation.y, 0.03, 1e-12);
  EXPECT_EQ(s.linear_velocity, Vec3(0.0));  // no difference across the gap
  EXPECT_EQ(dev.write(Vec3(0.5), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_EQ(again->out_count, 1u);
  EXPECT_EQ(dev.disconnects(), 1u);
  // a write error is a loss too
  again->present = false;
  EXPECT_EQ(dev.write(Vec3(0.5), Vec3(0.0)), DeviceStatus::kLost);
  EXPECT_EQ(dev.disconnects(), 2u);
}

TEST(HidDevice, SpaceMouseIsPoseOnly) {
  auto backend = std::make_unique<FakeBackend>();
  auto fake = std::make_shared<FakeHid>();
  backend->slots.push_back(
      {{"/dev/hidraw2", 0x256f, 0xc635, 0x0001, 0x0008, "SpaceMouse Compact"}, fake});
  auto d = HidDevice::open(std::move(backend), "/dev/hidraw2", DeviceOptions{});
  ASSERT_TRUE(d.ok()) << d.error().message;
  HidDevice& dev = *d.value();
  EXPECT_NE(dev.info().name.find("SpaceMouse Compact"), std::string::npos);
  EXPECT_FALSE(dev.info().capabilities & kCapForce);
  DeviceSample s;
  dev.read(0.0, s);
  const auto r = axes(1, {350, 0, 0, 0, 0, 0});
  fake->push(r);
  for (int i = 1; i <= 100; ++i)
    ASSERT_EQ(dev.read(i * 1e-3, s), DeviceStatus::kOk);
  EXPECT_NEAR(s.X_WD.translation.x, 0.01, 1e-12);  // 0.1 m/s for 0.1 s
  EXPECT_EQ(dev.write(Vec3(3.0), Vec3(0.0)), DeviceStatus::kOk);
  EXPECT_EQ(fake->out_count, 0u);  // nothing is sent to a SpaceMouse
}

TEST(HidDevice, OpenErrorsNameWhatIsWrong) {
  {
    auto backend = std::make_unique<FakeBackend>();
    backend->slots.push_back(
        {{"/dev/hidraw0", 0x046d, 0xc31c, 1, 6, "Keyboard"}, std::make_shared<FakeHid>()});
    auto d = HidDevice::open(std::move(backend), "", DeviceOptions{});
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("device 'hid': no device found"), std::string::npos)
        << d.error().message;
  }
  {
    auto d = HidDevice::open(std::make_unique<FakeBackend>(), "/dev/hidraw9", DeviceOptions{});
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("'hid:/dev/hidraw9': no HID device at this path"),
              std::string::npos)
        << d.error().message;
  }
  {
    auto backend = std::make_unique<FakeBackend>();
    auto fake = std::make_shared<FakeHid>();
    fake->open_fails = true;
    backend->slots.push_back({genericEntry("/dev/hidraw4"), fake});
    auto d = HidDevice::open(std::move(backend), "", DeviceOptions{});
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("cannot open /dev/hidraw4: permission denied"),
              std::string::npos)
        << d.error().message;
  }
  {
    DeviceOptions o;
    o.hid_spacemouse_full_scale = 0.0;
    auto d = HidDevice::open(std::make_unique<FakeBackend>(), "", o);
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("hid_spacemouse_full_scale"), std::string::npos);
  }
}

TEST(HidDevice, ServoCallsDoNotAllocate) {
  Rig rig = openGeneric();
  for (int i = 0; i < 4000; ++i)
    rig.dev->push(inputReport(Vec3(0.001 * i, 0, 0), geom::Quat(1, 0, 0, 0), 0,
                              static_cast<std::uint16_t>(i)));
  DeviceSample s;
  const std::uint64_t before = testing_alloc::count();
  for (int i = 0; i < 4000; ++i) {
    ASSERT_EQ(rig.hid->read(i * 1e-3, s), DeviceStatus::kOk);
    ASSERT_EQ(rig.hid->write(Vec3(0.1), Vec3(0.01)), DeviceStatus::kOk);
  }
  rig.dev->present = false;
  rig.hid->read(5.0, s);  // the loss itself allocates nothing either
  EXPECT_EQ(testing_alloc::count(), before);
}

// random report bytes of every length: parsed or refused, never a non-finite pose
TEST(HidReports, RandomReportsNeverCrash) {
  std::mt19937 rng(5);
  SpaceMouseState sm;
  DeviceOptions o;
  for (int k = 0; k < 20000; ++k) {
    std::vector<std::uint8_t> r(rng() % 40);
    for (auto& b : r)
      b = static_cast<std::uint8_t>(rng());
    if (!r.empty() && k % 2)
      r[0] = static_cast<std::uint8_t>(1 + rng() % 3);
    GenericInputReport in;
    if (parseGenericInput(r, in) == HidReportStatus::kOk) {
      ASSERT_TRUE(geom::finite(in.X_WD.translation));
      ASSERT_NEAR(glm::length(in.X_WD.rotation), 1.0, 1e-12);
    }
    GenericOutputReport out;
    (void)parseGenericOutput(r, out);
    for (const SpaceMouseModel& m : spaceMouseModels())
      (void)parseSpaceMouse(m, r, sm);
    integrateSpaceMouse(sm, o, k * 1e-3);
    ASSERT_TRUE(geom::finite(sm.X_WD.translation));
  }
}

}  // namespace
}  // namespace hapticd::device
