// Pose streams (client/pose_stream.h): parsing with errors that name file, line and what, and
// sampling: exact at the rows, lerp and slerp right at midpoints, the shorter arc when the
// quaternions flip sign, buttons of the row at or before, clamped outside the stream. The
// expected values come from closed forms (rotations about one axis), not from the code under
// test.
#include "client/pose_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

namespace hapticd::client {
namespace {

Result<std::vector<PoseSample>> parse(const std::string& text) {
  std::istringstream in(text);
  return parsePoseStream(in, "s.csv");
}

std::string errorOf(const std::string& text) {
  auto r = parse(text);
  return r ? std::string("(parsed)") : r.error().message;
}

// about z by `deg` degrees, glTF order
std::array<double, 4> aboutZ(double deg) {
  const double h = 0.5 * deg * std::numbers::pi / 180.0;
  return {0.0, 0.0, std::sin(h), std::cos(h)};
}

// 1 − |q·r|: 0 when q and r are the same rotation
double rotationGap(const std::array<double, 4>& q, const std::array<double, 4>& r) {
  return 1.0 - std::fabs(q[0] * r[0] + q[1] * r[1] + q[2] * r[2] + q[3] * r[3]);
}

const char* kStream =
    "t,px,py,pz,qx,qy,qz,qw,buttons\n"
    "0,0,0,0,0,0,0,1,1\n"
    "0.5,1,2,-4,0,0,0.70710678118654752,0.70710678118654752,2\n"
    // 180° about z written as -(0,0,1,0): q·q_prev < 0, the shorter arc is 90°→180°
    "1.5,3,2,-4,0,0,-1,0,4\n";

TEST(PoseStream, ParsesRowsAndOptionalButtonsAndComments) {
  auto r = parse(
      "# a comment\nt,px,py,pz,qx,qy,qz,qw,buttons\n\n0,1,2,3,0,0,0,1,7\n"
      "0.25,1,2,3,0,0,0,1\r\n");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r.value().size(), 2u);
  EXPECT_EQ(r.value()[0].buttons, 7u);
  EXPECT_EQ(r.value()[1].buttons, 0u);
  EXPECT_EQ(r.value()[1].t_s, 0.25);
  EXPECT_EQ(r.value()[0].p_W[2], 3.0);
}

TEST(PoseStream, BadRowsNameFileLineAndWhat) {
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

TEST(PoseStream, NonIncreasingTimeRefused) {
  EXPECT_EQ(errorOf("0,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n"),
            "s.csv:3: t 0.5 is not after the previous row's t 0.5 (t must increase)");
  EXPECT_NE(errorOf("1,0,0,0,0,0,0,1\n0.5,0,0,0,0,0,0,1\n").find("s.csv:2: t 0.5 is not after"),
            std::string::npos);
}

TEST(PoseStream, NonUnitQuaternionRefusedNearUnitRenormalised) {
  const std::string e = errorOf("0,0,0,0,0,0,0,1.01\n");
  EXPECT_EQ(e.rfind("s.csv:1: quaternion (0, 0, 0, 1.01) has norm 1.01", 0), 0u) << e;
  EXPECT_NE(errorOf("0,0,0,0,0,0,0,0\n").find("has norm 0"), std::string::npos);
  auto r = parse("0,0,0,0,0,0,0.7071,0.7071\n");  // norm 0.99999: within 1e-3
  ASSERT_TRUE(r) << r.error().message;
  const auto& q = r.value()[0].q_W;
  EXPECT_NEAR(std::sqrt(q[2] * q[2] + q[3] * q[3]), 1.0, 1e-15);
}

TEST(PoseStream, ExactAtTheRows) {
  auto r = parse(kStream);
  ASSERT_TRUE(r) << r.error().message;
  const auto& rows = r.value();
  for (const auto& row : rows) {
    const PoseSample s = samplePoseStream(rows, row.t_s);
    EXPECT_EQ(s.p_W, row.p_W) << row.t_s;
    EXPECT_EQ(s.q_W, row.q_W) << row.t_s;
    EXPECT_EQ(s.buttons, row.buttons) << row.t_s;
  }
}

TEST(PoseStream, MidpointLerpAndSlerp) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  // first segment: p from (0,0,0) to (1,2,-4), q from 0° to 90° about z
  PoseSample s = samplePoseStream(rows, 0.25);
  EXPECT_NEAR(s.p_W[0], 0.5, 1e-15);
  EXPECT_NEAR(s.p_W[1], 1.0, 1e-15);
  EXPECT_NEAR(s.p_W[2], -2.0, 1e-15);
  EXPECT_LT(rotationGap(s.q_W, aboutZ(45.0)), 1e-15);
  // at a quarter: 22.5° (slerp is uniform in angle, unlike normalised lerp)
  s = samplePoseStream(rows, 0.125);
  EXPECT_LT(rotationGap(s.q_W, aboutZ(22.5)), 1e-15);
  EXPECT_NEAR(s.p_W[2], -1.0, 1e-15);
  // segment velocities
  EXPECT_NEAR(s.v_W[0], 2.0, 1e-12);
  EXPECT_NEAR(s.v_W[2], -8.0, 1e-12);
  EXPECT_NEAR(s.w_W[2], (std::numbers::pi / 2) / 0.5, 1e-9);
  EXPECT_NEAR(s.w_W[0], 0.0, 1e-12);
}

TEST(PoseStream, ShortestArcWhenTheQuaternionsFlipSign) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  // second segment: 90° → -(180°) = 180°: the short way passes 135°, the long way 315°
  const PoseSample s = samplePoseStream(rows, 1.0);
  EXPECT_LT(rotationGap(s.q_W, aboutZ(135.0)), 1e-15);
  EXPECT_GT(rotationGap(s.q_W, aboutZ(315.0)), 0.5);
  EXPECT_NEAR(std::sqrt(s.q_W[0] * s.q_W[0] + s.q_W[1] * s.q_W[1] + s.q_W[2] * s.q_W[2] +
                        s.q_W[3] * s.q_W[3]),
              1.0, 1e-15);
  EXPECT_NEAR(s.w_W[2], (std::numbers::pi / 2) / 1.0, 1e-9);  // +90° in 1 s, not −270°
  // slerp itself, both signs of the end give the same path
  for (double u : {0.1, 0.5, 0.9}) {
    const auto a = slerp(aboutZ(90.0), {0.0, 0.0, 1.0, 0.0}, u);
    const auto b = slerp(aboutZ(90.0), {0.0, 0.0, -1.0, 0.0}, u);
    EXPECT_LT(rotationGap(a, b), 1e-15) << u;
    EXPECT_LT(rotationGap(a, aboutZ(90.0 + 90.0 * u)), 1e-15) << u;
  }
}

TEST(PoseStream, NearlyEqualQuaternionsDoNotDivideByZero) {
  const auto q = slerp(aboutZ(10.0), aboutZ(10.0 + 1e-9), 0.5);
  EXPECT_LT(rotationGap(q, aboutZ(10.0)), 1e-15);
  for (double c : q)
    EXPECT_TRUE(std::isfinite(c));
}

TEST(PoseStream, ButtonsOfTheRowAtOrBeforeAndClampedOutside) {
  auto r = parse(kStream);
  ASSERT_TRUE(r);
  const auto& rows = r.value();
  EXPECT_EQ(samplePoseStream(rows, 0.0).buttons, 1u);
  EXPECT_EQ(samplePoseStream(rows, 0.4999).buttons, 1u);
  EXPECT_EQ(samplePoseStream(rows, 0.5).buttons, 2u);
  EXPECT_EQ(samplePoseStream(rows, 1.4999).buttons, 2u);
  EXPECT_EQ(samplePoseStream(rows, 1.5).buttons, 4u);
  const PoseSample before = samplePoseStream(rows, -1.0);
  EXPECT_EQ(before.p_W, rows.front().p_W);
  EXPECT_EQ(before.v_W, (std::array<double, 3>{0.0, 0.0, 0.0}));
  const PoseSample after = samplePoseStream(rows, 9.0);
  EXPECT_EQ(after.p_W, rows.back().p_W);
  EXPECT_EQ(after.q_W, rows.back().q_W);
  EXPECT_EQ(after.buttons, 4u);
  EXPECT_EQ(after.v_W, (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(PoseStream, HintGivesTheSameSamplesAsASearch) {
  std::string text;
  for (int i = 0; i < 50; ++i)
    text += std::to_string(0.1 * i) + "," + std::to_string(i % 7) + ",0,0,0,0,0,1," +
            std::to_string(i) + "\n";
  auto r = parse(text);
  ASSERT_TRUE(r) << r.error().message;
  std::size_t hint = 0;
  for (double t = -0.05; t < 5.1; t += 0.013) {
    const PoseSample a = samplePoseStream(r.value(), t, &hint);
    const PoseSample b = samplePoseStream(r.value(), t);
    EXPECT_EQ(a.p_W, b.p_W) << t;
    EXPECT_EQ(a.buttons, b.buttons) << t;
  }
}

}  // namespace
}  // namespace hapticd::client
