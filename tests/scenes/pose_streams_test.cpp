// The pose streams (tests/streams/*.csv): they parse in the format of docs/architecture.md, time
// runs from 0 and only forwards, quaternions are unit and continuous, nothing jumps, and each
// stream does what its scene is for (docs/demo-scenes.md).

#include "scenes/pose_streams.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "scenes/demo_scenes.h"

namespace hapticd::scenes {
namespace {

struct Row {
  double t;
  glm::dvec3 p;
  glm::dquat q;  // (w, x, y, z)
  unsigned buttons;
};

/// Parses a stream strictly: the exact header, nine fields a row, every number finite.
std::vector<Row> parse(const std::string& csv, std::vector<std::string>& problems) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  if (line != "t,px,py,pz,qx,qy,qz,qw,buttons")
    problems.push_back("header: " + line);
  std::vector<Row> rows;
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ','))
      f.push_back(cell);
    if (f.size() != 9) {
      problems.push_back("line " + std::to_string(number) + ": " + std::to_string(f.size()) +
                         " fields");
      continue;
    }
    double v[8];
    for (int k = 0; k < 8; ++k) {
      char* end = nullptr;
      v[k] = std::strtod(f[static_cast<std::size_t>(k)].c_str(), &end);
      if (*end != '\0' || !std::isfinite(v[k]))
        problems.push_back("line " + std::to_string(number) + ": bad number");
    }
    char* end = nullptr;
    const unsigned long b = std::strtoul(f[8].c_str(), &end, 10);
    if (*end != '\0' || f[8].empty())
      problems.push_back("line " + std::to_string(number) + ": bad buttons");
    rows.push_back(
        {v[0], {v[1], v[2], v[3]}, glm::dquat(v[7], v[4], v[5], v[6]), static_cast<unsigned>(b)});
  }
  return rows;
}

std::vector<Row> stream(std::string_view scene) {
  std::vector<std::string> problems;
  auto rows = parse(makePoseStream(scene), problems);
  EXPECT_TRUE(problems.empty()) << problems.front();
  return rows;
}

TEST(PoseStreams, ParseWithMonotonicTimeUnitQuaternionsAndNoJumps) {
  for (std::string_view name : demoSceneNames()) {
    SCOPED_TRACE(std::string(name));
    const std::string csv = makePoseStream(name);
    EXPECT_LT(csv.size(), 1u << 20);
    const std::vector<Row> rows = stream(name);
    ASSERT_GT(rows.size(), 2u);
    EXPECT_EQ(rows.front().t, 0.0);
    const double duration = rows.back().t;
    EXPECT_GE(duration, 10.0);
    EXPECT_LE(duration, 20.0);
    double max_speed = 0.0, max_turn_rate = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      EXPECT_NEAR(glm::length(rows[i].q), 1.0, 1e-8) << "row " << i;
      if (i == 0)
        continue;
      const double dt = rows[i].t - rows[i - 1].t;
      ASSERT_GT(dt, 0.0) << "row " << i;
      EXPECT_NEAR(dt, 1.0 / kPoseStreamRate_hz, 1e-9);
      max_speed = std::max(max_speed, glm::length(rows[i].p - rows[i - 1].p) / dt);
      // continuous: consecutive quaternions in the same hemisphere and close
      const double c = glm::dot(rows[i].q, rows[i - 1].q);
      EXPECT_GT(c, 0.0) << "row " << i;
      max_turn_rate = std::max(max_turn_rate, 2.0 * std::acos(std::min(1.0, c)) / dt);
    }
    std::printf("%s: %zu rows, %.2f s, peak speed %.3f m/s, peak turn rate %.3f rad/s\n",
                std::string(name).c_str(), rows.size(), duration, max_speed, max_turn_rate);
    // hand speeds: under 1 m/s and 2 rad/s everywhere
    EXPECT_LT(max_speed, 1.0);
    EXPECT_LT(max_turn_rate, 2.0);
  }
}

TEST(PoseStreams, UnknownSceneHasNoStream) {
  EXPECT_TRUE(makePoseStream("nothing").empty());
}

double tiltDeg(const glm::dquat& q) {
  // angle between the body's Y axis and the scene's Y axis
  const glm::dvec3 y = q * glm::dvec3{0.0, 1.0, 0.0};
  return std::acos(std::clamp(y.y, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

TEST(PoseStreams, PegApproachesInsertsWithAWobbleJamsPushesAndPullsOut) {
  const std::vector<Row> rows = stream("peg_in_hole");
  const double half = 0.5 * peg::kPegLength_m;
  const double opening = 0.5 * peg::kPegSide_m + peg::kClearance_m;
  // phases by time (docs/demo-scenes.md): approach 1-3 s, insert 3-6, jam 6-8.5, push 8.5-11,
  // pull out 11-14.5
  double wobble_max = 0.0, jam_tilt = 0.0, lowest_end = 1e9, max_offset_inside = 0.0;
  double t_lowest = 0.0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const double end_y = r.p.y - half;
    if (r.t > 3.0 && r.t < 6.0)
      wobble_max = std::max(wobble_max, tiltDeg(r.q));
    if (r.t > 7.4 && r.t < 8.6)
      jam_tilt = std::max(jam_tilt, tiltDeg(r.q));
    if (end_y < lowest_end) {
      lowest_end = end_y;
      t_lowest = r.t;
    }
    if (end_y < peg::kHoleDepth_m)
      max_offset_inside = std::max(max_offset_inside, std::max(std::fabs(r.p.x), std::fabs(r.p.z)));
  }
  std::printf(
      "peg: wobble up to %.2f deg, jam tilt %.2f deg, lowest end %.2f mm, max offset in "
      "the hole %.3f mm, deepest at %.2f s\n",
      wobble_max, jam_tilt, lowest_end * 1e3, max_offset_inside * 1e3, t_lowest);
  EXPECT_GT(wobble_max, 0.5);
  EXPECT_LT(wobble_max, 3.0);
  EXPECT_GT(jam_tilt, 3.0);    // tilted past what the clearance allows at that depth
  EXPECT_LT(lowest_end, 0.0);  // pushed into the hole's floor
  EXPECT_GT(lowest_end, -0.005);
  EXPECT_LT(max_offset_inside, opening);  // the target stays over the opening while inside
  EXPECT_GT(rows.back().p.y - half, peg::kHoleDepth_m);  // out again at the end
  EXPECT_GT(t_lowest, 8.5);                              // deepest after the jam, in the push
  EXPECT_LT(t_lowest, 11.5);
}

TEST(PoseStreams, GearRodTurnsGearABothWays) {
  const std::vector<Row> rows = stream("gears");
  const SpurGear g = gears::gear();
  const glm::dvec3 centre{-0.5 * gears::kCentreDistance_m, 0.0, 0.0};
  const double gap = 4.5 * 2.0 * std::numbers::pi / g.teeth;
  double min_angle = 1e9, max_angle = -1e9, min_radius = 1e9;
  for (const Row& r : rows) {
    const glm::dvec3 d = r.p - centre;
    const double radius = std::hypot(d.x, d.y);
    EXPECT_NEAR(d.z, 0.0, 1e-12);
    EXPECT_GT(glm::dot(r.q, glm::dquat(1, 0, 0, 0)), 1.0 - 1e-12) << "the rod stays along the axis";
    if (radius < g.tipRadius()) {
      const double a = std::atan2(d.y, d.x) - gap;
      min_angle = std::min(min_angle, a);
      max_angle = std::max(max_angle, a);
    }
    min_radius = std::min(min_radius, radius);
  }
  std::printf(
      "gears: rod between the teeth from %.1f to %.1f deg about the gap, deepest %.2f mm "
      "from the axis (root %.2f, tip %.2f)\n",
      min_angle * 180 / std::numbers::pi, max_angle * 180 / std::numbers::pi, min_radius * 1e3,
      g.rootRadius() * 1e3, g.tipRadius() * 1e3);
  // in the tooth band, with the rod clear of the root circle
  EXPECT_LT(min_radius, g.pitchRadius());
  EXPECT_GT(min_radius - gears::kRodRadius_m, g.rootRadius());
  // pushes more than a tooth pitch each way
  EXPECT_LT(min_angle, -2.0 * std::numbers::pi / g.teeth);
  EXPECT_GT(max_angle, 2.0 * std::numbers::pi / g.teeth);
  EXPECT_GT(std::hypot(rows.back().p.x - centre.x, rows.back().p.y), g.tipRadius() + 0.01);
}

TEST(PoseStreams, StickPushesStrikesPressesAndGrabs) {
  const std::vector<Row> rows = stream("dynamic");
  const double half = 0.5 * dynamic::kStickSize_m[1];
  double pressed_s = 0.0, low_in_cube_row = 1e9, strike_speed = 0.0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const Row& r = rows[i];
    if (r.buttons & 1u)
      pressed_s += 1.0 / kPoseStreamRate_hz;
    if (std::fabs(r.p.z - dynamic::kCubeZ_m) < 1e-9)
      low_in_cube_row = std::min(low_in_cube_row, r.p.y - half);
    if (std::fabs(r.p.z - dynamic::kSphereZ_m) < 1e-9 && r.p.x < rows[i - 1].p.x)
      strike_speed = std::max(strike_speed, (rows[i - 1].p.x - r.p.x) * kPoseStreamRate_hz);
  }
  std::printf("dynamic: button held %.2f s, lowest end in the cube row %.1f mm, strike %.2f m/s\n",
              pressed_s, low_in_cube_row * 1e3, strike_speed);
  EXPECT_GT(pressed_s, 2.0);
  EXPECT_LT(low_in_cube_row, dynamic::kCubeSide_m);  // low enough to push a cube
  EXPECT_GT(low_in_cube_row, 0.0);                   // never into the floor
  EXPECT_GT(strike_speed, 0.2);
  EXPECT_EQ(rows.back().buttons, 0u);
}

TEST(PoseStreams, SweeperCrossesTheWholeField) {
  const std::vector<Row> rows = stream("stress");
  const double field = stress::pillarCoordinate(stress::kGrid - 1) + 0.5 * stress::kPillarSize_m[0];
  const double press_y = stress::kPillarSize_m[1] + stress::kSweeperRadius_m;
  double length = 0.0, low_length = 0.0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double step = glm::length(rows[i].p - rows[i - 1].p);
    length += step;
    if (rows[i].p.y < press_y)
      low_length += step;
  }
  std::printf("stress: path %.2f m, %.2f m of it pressing on the pillar tops\n", length,
              low_length);
  // seven passes across the field at pillar-top height
  EXPECT_GT(low_length, 7 * 2 * field);
  EXPECT_LT(rows.front().p.x, -field);
  EXPECT_GT(rows.back().p.y, press_y);
}

}  // namespace
}  // namespace hapticd::scenes
