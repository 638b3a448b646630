// The pose-stream format (protocol/pose_stream.h) itself: both dialects read a demo stream to the
// same rows; sampling is the rows' own poses at and outside the ends, lerp and slerp between,
// and the cursor gives the same samples in any order as from scratch. The dialects' refusals are
// tested where they are used (tests/daemon/device/replay_device_test.cpp: strict, 27 kinds of
// bad file; tests/client/pose_stream_test.cpp: lenient).
#include "protocol/pose_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/geometry/rotation.h"

namespace hapticd::proto {
namespace {

const std::string kDemo = std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/gears.csv";

std::vector<PoseStreamRow> demoRows(PoseStreamDialect dialect) {
  auto text = readPoseStreamFile(kDemo);
  EXPECT_TRUE(text.ok()) << (text.ok() ? "" : text.error().message);
  auto rows = parsePoseStream(text.value(), kDemo, 1e-3, dialect);
  EXPECT_TRUE(rows.ok()) << (rows.ok() ? "" : rows.error().message);
  return rows.ok() ? rows.value() : std::vector<PoseStreamRow>{};
}

TEST(PoseStream, BothDialectsReadADemoStreamToTheSameRows) {
  const auto strict = demoRows(PoseStreamDialect::kStrict);
  const auto lenient = demoRows(PoseStreamDialect::kLenient);
  ASSERT_GT(strict.size(), 10u);
  ASSERT_EQ(strict.size(), lenient.size());
  for (std::size_t i = 0; i < strict.size(); ++i) {
    EXPECT_EQ(strict[i].t_s, lenient[i].t_s) << i;
    EXPECT_EQ(strict[i].X_WD.translation, lenient[i].X_WD.translation) << i;
    EXPECT_EQ(strict[i].X_WD.rotation, lenient[i].X_WD.rotation) << i;
    EXPECT_EQ(strict[i].buttons, lenient[i].buttons) << i;
  }
}

TEST(PoseStream, SamplesAreTheRowsAtTheEndsAndLerpSlerpBetween) {
  const std::string text =
      "t,px,py,pz,qx,qy,qz,qw,buttons\n"
      "0.5,0,0,0,0,0,0,1,1\n"
      "1.5,2,-4,6,0,0,1,0,2\n";  // 180 degrees about z
  auto parsed = parsePoseStream(text, "s.csv", 1e-3, PoseStreamDialect::kStrict);
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const auto& rows = parsed.value();
  std::size_t cursor = 0;
  for (double t : {-1.0, 0.5, std::nan("")}) {
    const PoseStreamRow s = samplePoseStream(rows, t, cursor);
    EXPECT_EQ(s.X_WD.translation, rows[0].X_WD.translation) << t;
    EXPECT_EQ(s.X_WD.rotation, rows[0].X_WD.rotation) << t;
    EXPECT_EQ(s.buttons, 1u);
    EXPECT_EQ(cursor, 0u);
  }
  for (double t : {1.5, 9.0}) {
    const PoseStreamRow s = samplePoseStream(rows, t, cursor);
    EXPECT_EQ(s.X_WD.translation, rows[1].X_WD.translation) << t;
    EXPECT_EQ(s.buttons, 2u);
    EXPECT_EQ(cursor, 1u);
  }
  const PoseStreamRow mid = samplePoseStream(rows, 0.75, cursor);  // a quarter of the way
  EXPECT_EQ(mid.t_s, 0.75);
  EXPECT_LT(glm::length(mid.X_WD.translation - geom::Vec3(0.5, -1.0, 1.5)), 1e-15);
  const double h = 0.25 * 0.5 * 3.14159265358979323846;  // half of 45 degrees
  const geom::Quat q45(std::cos(h), 0.0, 0.0, std::sin(h));
  EXPECT_LT(glm::length(geom::rotationVector(mid.X_WD.rotation * glm::conjugate(q45))), 1e-14);
  EXPECT_EQ(mid.buttons, 1u);  // the row at or before
}

TEST(PoseStream, TheCursorGivesTheSameSamplesInAnyOrder) {
  const auto rows = demoRows(PoseStreamDialect::kStrict);
  ASSERT_GT(rows.size(), 10u);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> when(-0.1, rows.back().t_s + 0.1);
  std::size_t cursor = 0;
  for (int k = 0; k < 4000; ++k) {
    const double t = k % 2 == 0 ? when(rng) : rows.back().t_s * k / 4000.0;
    std::size_t fresh = 0;
    const PoseStreamRow a = samplePoseStream(rows, t, cursor);
    const PoseStreamRow b = samplePoseStream(rows, t, fresh);
    ASSERT_EQ(a.X_WD.translation, b.X_WD.translation) << t;
    ASSERT_EQ(a.X_WD.rotation, b.X_WD.rotation) << t;
    ASSERT_EQ(a.buttons, b.buttons) << t;
    ASSERT_EQ(cursor, fresh) << t;
  }
}

}  // namespace
}  // namespace hapticd::proto
