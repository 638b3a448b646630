// The replay device: exact at rows, lerp/slerp between rows against closed form, end of stream,
// velocities, the cursor against a brute-force lookup, every kind of bad file with its line and
// column, no allocation on the servo calls.
#include "daemon/device/replay_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "core/geometry/rotation.h"
#include "protocol/pose_stream.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::device {
namespace {

// the replay device's grammar: the strict one
Result<std::vector<proto::PoseStreamRow>> parsePoseStream(const std::string& text,
                                                          std::string_view source,
                                                          double quat_tolerance) {
  return proto::parsePoseStream(text, source, quat_tolerance, proto::PoseStreamDialect::kStrict);
}

constexpr const char* kHeader = "t,px,py,pz,qx,qy,qz,qw,buttons\n";

std::unique_ptr<ReplayDevice> fromText(const std::string& text) {
  auto rows = parsePoseStream(text, "test.csv", 0.01);
  EXPECT_TRUE(rows.ok()) << (rows.ok() ? "" : rows.error().message);
  return std::make_unique<ReplayDevice>("replay:test.csv", std::move(rows).value(),
                                        DeviceOptions{});
}

double angleBetween(const geom::Quat& a, const geom::Quat& b) {
  return glm::length(geom::rotationVector(a * glm::conjugate(b)));
}

TEST(ReplayDevice, ExactAtRowsAndLerpSlerpBetween) {
  // rotation about a fixed axis u: from 0.3 rad to 1.5 rad, so slerp's closed form is the angle
  // 0.3 + s * 1.2 about u
  const Vec3 u = glm::normalize(Vec3(1.0, -2.0, 0.5));
  auto quatText = [&](double angle) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g", u.x * std::sin(angle / 2),
                  u.y * std::sin(angle / 2), u.z * std::sin(angle / 2), std::cos(angle / 2));
    return std::string(buf);
  };
  const std::string text = std::string(kHeader) + "0.5,1,2,3," + quatText(0.3) + ",1\n" +
                           "0.75,2,0,3.5," + quatText(1.5) + ",2\n" + "1.25,-1,4,0," +
                           quatText(1.5) + ",6\n";
  auto dev = fromText(text);
  DeviceSample s;
  // before the first row: the first row
  ASSERT_EQ(dev->read(0.0, s), DeviceStatus::kOk);
  EXPECT_EQ(s.X_WD.translation, Vec3(1, 2, 3));
  EXPECT_EQ(s.buttons, 1u);
  // at rows: the rows
  const auto& rows = dev->rows();
  for (const auto& r : rows) {
    ASSERT_EQ(dev->read(r.t_s, s), DeviceStatus::kOk);
    EXPECT_EQ(s.X_WD.translation, r.X_WD.translation) << r.t_s;
    EXPECT_LT(angleBetween(s.X_WD.rotation, r.X_WD.rotation), 1e-15) << r.t_s;
    EXPECT_EQ(s.buttons, r.buttons);
  }
  // between: closed forms
  for (double s01 : {0.1, 0.25, 0.5, 0.9, 0.999}) {
    auto fresh = fromText(text);
    const double t = 0.5 + s01 * 0.25;
    ASSERT_EQ(fresh->read(t, s), DeviceStatus::kOk);
    const Vec3 expected = Vec3(1, 2, 3) + s01 * (Vec3(2, 0, 3.5) - Vec3(1, 2, 3));
    EXPECT_LT(glm::length(s.X_WD.translation - expected), 1e-14) << s01;
    const double angle = 0.3 + s01 * 1.2;
    const geom::Quat q(std::cos(angle / 2), u.x * std::sin(angle / 2), u.y * std::sin(angle / 2),
                       u.z * std::sin(angle / 2));
    EXPECT_LT(angleBetween(s.X_WD.rotation, q), 1e-14) << s01;
    EXPECT_EQ(s.buttons, 1u);  // the row at or before t
  }
  // end of stream after the last row, not at it
  auto d2 = fromText(text);
  EXPECT_EQ(d2->read(1.25, s), DeviceStatus::kOk);
  EXPECT_EQ(s.X_WD.translation, Vec3(-1, 4, 0));
  EXPECT_EQ(d2->read(1.25 + 1e-9, s), DeviceStatus::kEndOfStream);
  EXPECT_EQ(d2->read(7.0, s), DeviceStatus::kEndOfStream);
  // a NaN time reads as the previous time
  auto d3 = fromText(text);
  ASSERT_EQ(d3->read(std::nan(""), s), DeviceStatus::kOk);
  EXPECT_EQ(s.X_WD.translation, Vec3(1, 2, 3));
  ASSERT_EQ(d3->read(0.625, s), DeviceStatus::kOk);
  ASSERT_EQ(d3->read(std::nan(""), s), DeviceStatus::kOk);
  EXPECT_LT(glm::length(s.X_WD.translation - Vec3(1.5, 1.0, 3.25)), 1e-14);
  EXPECT_TRUE(geom::finite(s.linear_velocity));
  EXPECT_TRUE(d2->info().capabilities & kCapEndOfStream);
}

TEST(ReplayDevice, SlerpTakesTheShortPath) {
  // the second row is the same rotation written with the opposite sign: no motion between
  const std::string text =
      std::string(kHeader) + "0,0,0,0,0,0.6,0,0.8,0\n" + "1,0,0,0,0,-0.6,0,-0.8,0\n";
  auto dev = fromText(text);
  DeviceSample s;
  dev->read(0.5, s);
  EXPECT_LT(angleBetween(s.X_WD.rotation, dev->rows()[0].X_WD.rotation), 1e-15);
}

TEST(ReplayDevice, VelocitiesByFiniteDifference) {
  // constant linear velocity (0.2, -0.1, 0) m/s and 0.4 rad/s about y
  std::string text = kHeader;
  for (int i = 0; i <= 10; ++i) {
    const double t = 0.1 * i;
    char buf[200];
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,0,0,%.17g,0,%.17g,0\n", t, 0.2 * t, -0.1 * t,
                  std::sin(0.2 * t), std::cos(0.2 * t));
    text += buf;
  }
  auto dev = fromText(text);
  DeviceSample s;
  dev->read(0.0, s);
  EXPECT_EQ(s.linear_velocity, Vec3(0.0));  // first read
  for (int i = 1; i <= 900; ++i) {
    ASSERT_EQ(dev->read(i * 1e-3, s), DeviceStatus::kOk);
    EXPECT_LT(glm::length(s.linear_velocity - Vec3(0.2, -0.1, 0.0)), 1e-9) << i;
    EXPECT_LT(glm::length(s.angular_velocity - Vec3(0.0, 0.4, 0.0)), 1e-7) << i;
  }
}

TEST(ReplayDevice, CursorAgreesWithBinarySearchInAnyOrder) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> step(1e-4, 0.02);
  std::string text = kHeader;
  double t = 0.0;
  for (int i = 0; i < 2000; ++i) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g,0,0,0,1,%d\n", t, std::sin(t),
                  std::cos(3 * t), t * t, i);
    text += buf;
    t += step(rng);
  }
  auto dev = fromText(text);
  const auto& rows = dev->rows();
  std::uniform_real_distribution<double> when(-0.1, rows.back().t_s);
  for (int k = 0; k < 5000; ++k) {
    const double tq = (k % 3 == 0) ? when(rng) : rows.back().t_s * k / 5000.0;
    std::uint32_t buttons = 0;
    const Pose X = dev->poseAt(tq, &buttons);
    // reference: linear scan
    std::size_t i = 0;
    while (i + 1 < rows.size() && rows[i + 1].t_s <= tq)
      ++i;
    Vec3 expected = rows[i].X_WD.translation;
    if (i + 1 < rows.size() && tq > rows[0].t_s) {
      const double sa = (tq - rows[i].t_s) / (rows[i + 1].t_s - rows[i].t_s);
      expected =
          rows[i].X_WD.translation + sa * (rows[i + 1].X_WD.translation - rows[i].X_WD.translation);
    }
    ASSERT_EQ(X.translation, expected) << tq;
    ASSERT_EQ(buttons, rows[i].buttons) << tq;
  }
}

TEST(ReplayDevice, AcceptsCrlfSignsAndNearUnitQuaternions) {
  const std::string text =
      "t,px,py,pz,qx,qy,qz,qw,buttons\r\n0,+1,-2,3e-3,0,0,0,1.005,4294967295\r\n"
      "1,1,2,3,0,0,0,1,0\r\n\r\n";
  auto rows = parsePoseStream(text, "x.csv", 0.01);
  ASSERT_TRUE(rows.ok()) << rows.error().message;
  ASSERT_EQ(rows.value().size(), 2u);
  EXPECT_EQ(rows.value()[0].X_WD.translation, Vec3(1, -2, 3e-3));
  EXPECT_DOUBLE_EQ(rows.value()[0].X_WD.rotation.w, 1.0);  // normalised
  EXPECT_EQ(rows.value()[0].buttons, 4294967295u);
}

struct BadCase {
  const char* name;
  std::string text;
  std::string expect;  // a substring of the message
};

TEST(ReplayDevice, EveryBadFileNamesLineAndColumn) {
  const std::string h = kHeader;
  const std::string ok = "0,0,0,0,0,0,0,1,0\n";
  const BadCase cases[] = {
      {"empty file", "", "test.csv: empty file"},
      {"header only", h, "no rows after the header"},
      {"short header", "t,px,py,pz,qx,qy,qz,qw\n" + ok, "line 1: the header must be exactly"},
      {"spaced header", "t, px,py,pz,qx,qy,qz,qw,buttons\n" + ok, "line 1: the header"},
      {"reordered header", "t,px,py,pz,qw,qx,qy,qz,buttons\n" + ok, "line 1: the header"},
      {"word", h + "0,abc,0,0,0,0,0,1,0\n", "line 2, column 2 (px): not a number: 'abc'"},
      {"trailing space", h + "0,0,0 ,0,0,0,0,1,0\n", "line 2, column 3 (py): not a number"},
      {"trailing junk", h + "0,0,0,1x,0,0,0,1,0\n", "line 2, column 4 (pz): not a number"},
      {"nan", h + "0,0,0,0,nan,0,0,1,0\n", "line 2, column 5 (qx): not a finite number"},
      {"inf", h + "0,0,inf,0,0,0,0,1,0\n", "line 2, column 3 (py): not a finite number"},
      {"overflow", h + "0,1e999,0,0,0,0,0,1,0\n", "line 2, column 2 (px): number out of range"},
      {"empty field", h + "0,,0,0,0,0,0,1,0\n", "line 2, column 2 (px): empty field"},
      {"too few", h + "0,0,0,0,0,0,0,1\n", "line 2: 8 fields, expected 9"},
      {"too many", h + "0,0,0,0,0,0,0,1,0,7\n", "line 2: more than 9 fields"},
      {"negative t", h + "-0.5,0,0,0,0,0,0,1,0\n", "line 2, column 1 (t): time before 0"},
      {"t repeats", h + ok + "0.1,0,0,0,0,0,0,1,0\n0.1,0,0,0,0,0,0,1,0\n",
       "line 4, column 1 (t): time not after the previous row's"},
      {"t goes back", h + "1,0,0,0,0,0,0,1,0\n0.5,0,0,0,0,0,0,1,0\n",
       "line 3, column 1 (t): time not after"},
      {"long quaternion", h + "0,0,0,0,0,0,0,2,0\n", "line 2, column 5 (qx): quaternion"},
      {"zero quaternion", h + "0,0,0,0,0,0,0,0,0\n", "line 2, column 5 (qx): quaternion"},
      {"short quaternion", h + "0,0,0,0,0.5,0,0,0.5,0\n", "of length 0.707"},
      {"fractional buttons", h + "0,0,0,0,0,0,0,1,1.5\n",
       "line 2, column 9 (buttons): not a non-negative integer bit mask: '1.5'"},
      {"negative buttons", h + "0,0,0,0,0,0,0,1,-1\n", "line 2, column 9 (buttons): not a non"},
      {"wide buttons", h + "0,0,0,0,0,0,0,1,4294967296\n",
       "line 2, column 9 (buttons): button mask out of range"},
      {"float buttons", h + "0,0,0,0,0,0,0,1,1e3\n", "column 9 (buttons)"},
      {"blank inside", h + ok + "\n0.5,0,0,0,0,0,0,1,0\n", "line 3: empty line inside"},
      {"binary", h + std::string("0,\x01\xff\x00,0", 8) + ",0,0,0,1,0\n",
       "line 2, column 2 (px): not a number"},
      {"long garbage", h + std::string(5000, 'x') + "\n",
       "line 2, column 1 (t): not a number: 'xxxx"},
  };
  for (const BadCase& c : cases) {
    auto r = parsePoseStream(c.text, "test.csv", 0.01);
    ASSERT_FALSE(r.ok()) << c.name;
    EXPECT_NE(r.error().message.find(c.expect), std::string::npos)
        << c.name << ": got '" << r.error().message << "'";
    EXPECT_LT(r.error().message.size(), 300u) << c.name;  // long fields are cut
  }
}

TEST(ReplayDevice, OpensFilesThroughMakeDevice) {
  auto missing = makeDevice("replay:/nonexistent/poses.csv", DeviceOptions{});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("'replay:/nonexistent/poses.csv'"), std::string::npos);
  EXPECT_NE(missing.error().message.find("cannot open"), std::string::npos);

  // a directory and a character device are refused without reading (a FIFO would block)
  auto dir_spec = makeDevice("replay:/tmp", DeviceOptions{});
  ASSERT_FALSE(dir_spec.ok());
  EXPECT_NE(dir_spec.error().message.find("not a regular file"), std::string::npos);
  auto zero = makeDevice("replay:/dev/zero", DeviceOptions{});
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.error().message.find("not a regular file"), std::string::npos);

  const auto dir = std::filesystem::temp_directory_path();
  const auto bad = dir / "hapticd_replay_bad.csv";
  std::ofstream(bad) << kHeader << "0,0,0,0,0,0,0,1,0\n0.1,0,zero,0,0,0,0,1,0\n";
  auto r = makeDevice("replay:" + bad.string(), DeviceOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("line 3, column 3 (py)"), std::string::npos)
      << r.error().message;
  std::filesystem::remove(bad);

  auto circle =
      makeDevice(std::string("replay:") + HAPTICD_TEST_DATA_DIR + "/circle.csv", DeviceOptions{});
  ASSERT_TRUE(circle.ok()) << circle.error().message;
  Device& dev = *circle.value();
  DeviceSample s;
  int ticks = 0;
  double farthest = 0.0;
  const std::uint64_t before = testing_alloc::count();
  while (dev.read(ticks * 1e-3, s) == DeviceStatus::kOk) {
    farthest = std::max(farthest, std::abs(glm::length(s.X_WD.translation) - 0.02));
    dev.write(Vec3(1.0), Vec3(0.0));
    ++ticks;
  }
  EXPECT_EQ(testing_alloc::count(), before);  // servo calls allocate nothing
  EXPECT_EQ(ticks, 2001);                     // 0 .. 2.000 s inclusive at 1 kHz
  EXPECT_LT(farthest, 1e-5);                  // chords of a 2 cm circle at 100 Hz
  EXPECT_EQ(s.buttons, 1u);
}

// mutated files: every outcome is a row list or an error with a line number; no crash (ASan)
TEST(ReplayDevice, MutatedFilesNeverCrash) {
  std::string good;
  {
    std::ifstream in(std::string(HAPTICD_TEST_DATA_DIR) + "/circle.csv", std::ios::binary);
    good.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(good.size(), 1000u);
  std::mt19937_64 rng(11);
  const char alphabet[] = "0123456789.,-+eE\n\r naif\x01\xff";
  int refused = 0;
  for (int k = 0; k < 3000; ++k) {
    std::string text = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[at] = alphabet[rng() % (sizeof alphabet - 1)];
          break;
        case 1:
          text.erase(at, 1 + rng() % 3);
          break;
        default:
          text.insert(at, 1, alphabet[rng() % (sizeof alphabet - 1)]);
          break;
      }
      if (text.empty())
        text = "x";
    }
    auto r = parsePoseStream(text, "m.csv", 0.01);
    if (!r.ok()) {
      ++refused;
      EXPECT_EQ(r.error().message.rfind("m.csv: ", 0), 0u) << r.error().message;
    } else {
      for (const auto& row : r.value()) {
        ASSERT_TRUE(std::isfinite(row.t_s));
        ASSERT_TRUE(geom::finite(row.X_WD.translation));
        ASSERT_NEAR(glm::length(row.X_WD.rotation), 1.0, 1e-12);
      }
    }
  }
  std::printf("  3000 mutated files: %d refused, %d accepted\n", refused, 3000 - refused);
  EXPECT_GT(refused, 1000);
}

}  // namespace
}  // namespace hapticd::device
