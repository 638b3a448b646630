// Pose streams as hapticctl replay reads them (client/replay_stream.h: the lenient dialect of
// protocol/pose_stream.h): parsing with errors that name file, line and what, and sampling: exact
// at the rows, lerp and slerp right at midpoints, the shorter arc when the quaternions flip sign,
// buttons of the row at or before, clamped outside the stream. The expected values come from
// closed forms (rotations about one axis), not from the code under test.
#include "client/replay_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/geometry/rotation.h"

namespace hapticd::client {
namespace {

using geom::Quat;
using geom::Vec3;

Result<std::vector<proto::PoseStreamRow>> parse(const std::string& text) {
  return parseReplayStream(text, "s.csv");
}

std::string errorOf(const std::string& text) {
  auto r = parse(text);
  return r ? std::string("(parsed)") : r.error().message;
}

// about z by `deg` degrees
Quat aboutZ(double deg) {
  const double h = 0.5 * deg * std::numbers::pi / 180.0;
  return Quat(std::cos(h), 0.0, 0.0, std::sin(h));
}

// 1 − |q·r|: 0 when q and r are the same rotation
double rotationGap(const Quat& q, const Quat& r) {
  return 1.0 - std::fabs(q.x * r.x + q.y * r.y + q.z * r.z + q.w * r.w);
}

const char* kStream =
    "t,px,py,pz,qx,qy,qz,qw,buttons\n"
    "0,0,0,0,0,0,0,1,1\n"
    "0.5,1,2,-4,0,0,0.70710678118654752,0.70710678118654752,2\n"
    // 180° about z written as -(0,0,1,0): q·q_prev < 0, the shorter arc is 90°→180°
    "1.5,3,2,-4,0,0,-1,0,4\n";

TEST(ReplayStream, ParsesRowsAndOptionalButtonsAndComments) {
  auto r = parse(
      "# a comment\nt,px,py,pz,qx,qy,qz,qw,buttons\n\n0,1,2,3,0,0,0,1,7\n"
      "0.25,1,2,3,0,0,0,1\r\n");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r.value().size(), 2u);
  EXPECT_EQ(r.value()[0].buttons, 7u);
  EXPECT_EQ(r.value()[1].buttons, 0u);
  EXPECT_EQ(r.value()[1].t_s, 0.25);
  EXPECT_EQ(r.value()[0].X_WD.translation.z, 3.0);
}

TEST(ReplayStream, BadRowsNameFileLineAndWhat) {
  EXPECT_EQ(errorOf("t,px,py,pz,qx,qy,qz,qw,buttons\n0,0,0,zero,0,0,0,1,0\n"),
            "s.csv:2: column 4 (pz): 'zero' is not a number");
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1,0\n0,0,0\n"),
            "s.csv:2: expected 9 columns t,px,py,pz,qx,qy,qz,qw,buttons (buttons may be left out), "
            "got 3");
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1,0\n1,0,0,inf,0,0,0,1,0\n"),
            "s.csv:2: column 4 (pz): 'inf' is not finite");
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1,x\n"),
            "s.csv:1: column 9 (buttons): 'x' is not an unsigned 32-bit integer");
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1,-1\n"),
            "s.csv:1: column 9 (buttons): '-1' is not an unsigned 32-bit integer");
  EXPECT_EQ(errorOf("t,x,y,z\n"), "s.csv:1: header must be t,px,py,pz,qx,qy,qz,qw,buttons");
  EXPECT_EQ(errorOf(""), "s.csv: no rows");
  EXPECT_EQ(errorOf("t,px,py,pz,qx,qy,qz,qw,buttons\n"), "s.csv: no rows");
}

TEST(ReplayStream, NonIncreasingTimeRefused) {
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n"),
            "s.csv:3: t 0.5 is not after the previous row's t 0.5 (t must increase)");
  EXPECT_NE(errorOf("1,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n").find("s.csv:2: t 0.5 is not after"),
            std::string::npos);
}

TEST(ReplayStream, NonUnitQuaternionRefusedNearUnitRenormalised) {
  const std::string e = errorOf("0,0,0,0,0,0,0,1.01\n");
  EXPECT_EQ(e.rfind("s.csv:1: quaternion (0, 0, 0, 1.01) has norm 1.01", 0), 0u) << e;
  EXPECT_NE(errorOf("0,0,0,0,0,0,0,0\n").find("has norm 0"), std::string::npos);
  auto r = parse("0,0,0,0,0,0,0.7071,0.7071\n");  // norm 0.99999: within 1e-3
  ASSERT_TRUE(r) << r.error().message;
  const Quat& q = r.value()[0].X_WD.rotation;
  EXPECT_NEAR(std::sqrt(q.z * q.z + q.w * q.w), 1.0, 1e-15);
}

TEST(ReplayStream, ExactAtTheRows) {
  auto r = parse(kStream);
  ASSERT_TRUE(r) << r.error().message;
  const auto& rows = r.value();
  for (const auto& row : rows) {
    const ReplaySample s = sampleReplayStream(rows, row.t_s);
    EXPECT_EQ(s.X_WD.translation, row.X_WD.translation) << row.t_s;
    EXPECT_EQ(s.X_WD.rotation, row.X_WD.rotation) << row.t_s;
    EXPECT_EQ(s.buttons, row.buttons) << row.t_s;
  }
}

TEST(ReplayStream, MidpointLerpAndSlerp) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  // first segment: p from (0,0,0) to (1,2,-4), q from 0° to 90° about z
  ReplaySample s = sampleReplayStream(rows, 0.25);
  EXPECT_NEAR(s.X_WD.translation.x, 0.5, 1e-15);
  EXPECT_NEAR(s.X_WD.translation.y, 1.0, 1e-15);
  EXPECT_NEAR(s.X_WD.translation.z, -2.0, 1e-15);
  EXPECT_LT(rotationGap(s.X_WD.rotation, aboutZ(45.0)), 1e-15);
  // at a quarter: 22.5° (slerp is uniform in angle, unlike normalised lerp)
  s = sampleReplayStream(rows, 0.125);
  EXPECT_LT(rotationGap(s.X_WD.rotation, aboutZ(22.5)), 1e-15);
  EXPECT_NEAR(s.X_WD.translation.z, -1.0, 1e-15);
  // segment velocities
  EXPECT_NEAR(s.v_W.x, 2.0, 1e-12);
  EXPECT_NEAR(s.v_W.z, -8.0, 1e-12);
  EXPECT_NEAR(s.w_W.z, (std::numbers::pi / 2) / 0.5, 1e-9);
  EXPECT_NEAR(s.w_W.x, 0.0, 1e-12);
}

TEST(ReplayStream, ShortestArcWhenTheQuaternionsFlipSign) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  // second segment: 90° → -(180°) = 180°: the short way passes 135°, the long way 315°
  const ReplaySample s = sampleReplayStream(rows, 1.0);
  const Quat& q = s.X_WD.rotation;
  EXPECT_LT(rotationGap(q, aboutZ(135.0)), 1e-15);
  EXPECT_GT(rotationGap(q, aboutZ(315.0)), 0.5);
  EXPECT_NEAR(std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w), 1.0, 1e-15);
  EXPECT_NEAR(s.w_W.z, (std::numbers::pi / 2) / 1.0, 1e-9);  // +90° in 1 s, not −270°
  // slerp itself (the stream's, geom::slerp), both signs of the end give the same path
  for (double u : {0.1, 0.5, 0.9}) {
    const Quat a = geom::slerp(aboutZ(90.0), Quat(0.0, 0.0, 0.0, 1.0), u);
    const Quat b = geom::slerp(aboutZ(90.0), Quat(0.0, 0.0, 0.0, -1.0), u);
    EXPECT_LT(rotationGap(a, b), 1e-15) << u;
    EXPECT_LT(rotationGap(a, aboutZ(90.0 + 90.0 * u)), 1e-15) << u;
  }
}

TEST(ReplayStream, NearlyEqualQuaternionsDoNotDivideByZero) {
  const Quat q = geom::slerp(aboutZ(10.0), aboutZ(10.0 + 1e-9), 0.5);
  EXPECT_LT(rotationGap(q, aboutZ(10.0)), 1e-15);
  EXPECT_TRUE(geom::finite(q));
}

TEST(ReplayStream, ButtonsOfTheRowAtOrBeforeAndClampedOutside) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  EXPECT_EQ(sampleReplayStream(rows, 0.0).buttons, 1u);
  EXPECT_EQ(sampleReplayStream(rows, 0.4999).buttons, 1u);
  EXPECT_EQ(sampleReplayStream(rows, 0.5).buttons, 2u);
  EXPECT_EQ(sampleReplayStream(rows, 1.4999).buttons, 2u);
  EXPECT_EQ(sampleReplayStream(rows, 1.5).buttons, 4u);
  const ReplaySample before = sampleReplayStream(rows, -1.0);
  EXPECT_EQ(before.X_WD.translation, rows.front().X_WD.translation);
  EXPECT_EQ(before.v_W, Vec3(0.0));
  const ReplaySample after = sampleReplayStream(rows, 9.0);
  EXPECT_EQ(after.X_WD.translation, rows.back().X_WD.translation);
  EXPECT_EQ(after.X_WD.rotation, rows.back().X_WD.rotation);
  EXPECT_EQ(after.buttons, 4u);
  EXPECT_EQ(after.v_W, Vec3(0.0));
}

TEST(ReplayStream, HintGivesTheSameSamplesAsASearch) {
  std::string text;
  for (int i = 0; i < 50; ++i)
    text += std::to_string(0.1 * i) + "," + std::to_string(i % 7) + ",0,0,0,0,0,1," +
            std::to_string(i) + "\n";
  auto r = parse(text);
  ASSERT_TRUE(r) << r.error().message;
  std::size_t hint = 0;
  for (double t = -0.05; t < 5.1; t += 0.013) {
    const ReplaySample a = sampleReplayStream(r.value(), t, &hint);
    const ReplaySample b = sampleReplayStream(r.value(), t);
    EXPECT_EQ(a.X_WD.translation, b.X_WD.translation) << t;
    EXPECT_EQ(a.buttons, b.buttons) << t;
  }
}

}  // namespace
}  // namespace hapticd::client
