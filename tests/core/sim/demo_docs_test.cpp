// The demo scenes do what docs/demo-scenes.md says, replayed through the simulation (issue 17
// point 6): in `dynamic` the strike strikes Sphere3 at 7.5 s (not before) and the grab lifts
// Cube2, carries it and lets it drop; in `stress` the sweeper rides over the pillar tops,
// keeping up with its stream.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "scenes/demo_scenes.h"
#include "tests/core/sim/demo_streams.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

std::vector<Key> demoKeys(const std::string& name, double t_end = 1e9) {
  auto keys = readPoseStream(std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv");
  while (!keys.empty() && keys.back().t_s > t_end)
    keys.pop_back();
  return keys;
}

// the index in bodyPoses() of the body named `name`
std::size_t poseIndex(sim::Simulation& sim, const std::string& name) {
  const auto poses = sim.bodyPoses();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (sim.scene().bodies[poses[i].body].name == name)
      return i;
  }
  ADD_FAILURE() << "no body " << name;
  return 0;
}

TEST(DynamicDemo, TheStrikeHitsSphere3AtItsTimeAndTheGrabCarriesCube2) {
  using namespace scenes::dynamic;
  auto model = loadDemo("dynamic");
  ASSERT_TRUE(model);
  const auto keys = demoKeys("dynamic");
  ASSERT_GE(keys.size(), 2u);
  sim::SimOptions o;
  Runner run(make(model, o), o);
  const std::size_t sphere = poseIndex(run.sim(), "Sphere3");
  const std::size_t cube = poseIndex(run.sim(), "Cube2");
  std::int32_t cube_body = -1;
  for (std::size_t i = 0; i < model->bodies.size(); ++i) {
    if (model->bodies[i].name == "Cube2")
      cube_body = static_cast<std::int32_t>(i);
  }
  Vec3 sphere_rest{0.0}, sphere_prev{0.0}, cube_at_lift{0.0}, cube_carried{0.0};
  double first_sphere_move_s = -1.0, grab_start_s = -1.0, grab_end_s = -1.0;
  std::uint32_t grab_ticks = 0;
  run.run(Path(keys), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const auto poses = run.sim().bodyPoses();
    const Vec3 s = poses[sphere].X_WB.translation;
    if (std::abs(in.t_s - 1.0) < 1e-9)
      sphere_rest = s;  // dropped its 1 mm and at rest
    // struck: faster than 0.15 m/s (the strike is 0.35 m/s). Before it the four spheres drift
    // together by some 8 mm at under 0.1 m/s from 4.75 s, all of them at once: the dynamics'
    // solver (issue 17 point 1), not a touch
    if (in.t_s > 1.0 && first_sphere_move_s < 0.0 && glm::length(s - sphere_prev) > 1.5e-4)
      first_sphere_move_s = in.t_s;
    sphere_prev = s;
    if (out.attach_mode == 1 && out.attached_body == cube_body) {
      ++grab_ticks;
      if (grab_start_s < 0.0)
        grab_start_s = in.t_s;
      grab_end_s = in.t_s;
    }
    if (std::abs(in.t_s - 16.5) < 1e-9)
      cube_at_lift = poses[cube].X_WB.translation;
    if (std::abs(in.t_s - 17.5) < 1e-9)
      cube_carried = poses[cube].X_WB.translation;
  });
  const auto poses = run.sim().bodyPoses();
  const Vec3 sphere_end = poses[sphere].X_WB.translation;
  const Vec3 cube_end = poses[cube].X_WB.translation;
  std::printf(
      "  Sphere3 struck at %.3f s, ends %.1f mm along -x; Cube2 grabbed %.3f .. %.3f s "
      "(%u ticks), at 16.5 s its centre %.1f mm up, at 17.5 s at z = %.1f mm, at the end "
      "%.2f mm up at z = %.1f mm\n",
      first_sphere_move_s, 1e3 * (sphere_rest.x - sphere_end.x), grab_start_s, grab_end_s,
      grab_ticks, 1e3 * cube_at_lift.y, 1e3 * cube_carried.z, 1e3 * cube_end.y, 1e3 * cube_end.z);
  // the strike (7.5 to 7.8 s) is the first thing that moves Sphere3, and it rolls off towards -x
  EXPECT_GE(first_sphere_move_s, 7.5);
  EXPECT_LE(first_sphere_move_s, 7.8);
  EXPECT_GT(sphere_rest.x - sphere_end.x, 0.02);
  // the grab: from the press at 15 s to the release at 18 s; lifted 85 mm (its centre from
  // 20 mm on the floor), carried to z = 0.2 m, dropped on the floor there
  EXPECT_NEAR(grab_start_s, 15.0, 0.005);
  EXPECT_NEAR(grab_end_s, 18.0, 0.005);
  EXPECT_NEAR(cube_at_lift.y, 0.5 * kCubeSide_m + 0.085, 0.002);
  EXPECT_NEAR(cube_carried.z, 0.20, 0.002);
  EXPECT_NEAR(cube_end.y, 0.5 * kCubeSide_m, 0.001);
  EXPECT_NEAR(cube_end.z, 0.20, 0.01);
}

TEST(StressDemo, TheSweeperRidesOverThePillarsOfItsFirstPass) {
  using namespace scenes::stress;
  auto model = loadDemo("stress");
  ASSERT_TRUE(model);
  // the descent and the first pass (x from -0.52 to +0.52 m over row 4, 2 to 4 s)
  const auto keys = demoKeys("stress", 4.0);
  ASSERT_GE(keys.size(), 2u);
  sim::SimOptions o;
  Runner run(make(model, o), o);
  const double ride_y = kPillarSize_m[1] + kSweeperRadius_m;  // resting on the tops
  const double field = pillarCoordinate(kGrid - 1) + 0.5 * kPillarSize_m[0];
  std::int32_t pillars = -1;
  for (std::size_t i = 0; i < model->bodies.size(); ++i) {
    if (model->bodies[i].name == "Field")
      pillars = static_cast<std::int32_t>(i);
  }
  ASSERT_GE(pillars, 0);
  double lowest = 1.0, lowest_in_gap = 1.0, worst_lag_x = 0.0, deepest_in_pillars = 0.0;
  double lowest_pressed = 1.0;
  std::uint32_t over_field = 0, touching = 0, over_tops = 0, pressed_by_block = 0;
  run.run(Path(keys), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const Vec3 p = out.X_W_proxy.translation;
    if (in.t_s < 2.0 || std::abs(p.x) > field - 0.03)
      return;  // before the pass, or near the field's edges
    ++over_field;
    touching += out.contacts > 0 ? 1u : 0u;
    // a block the sweeper pushes may tilt and lean on it, its lower edge above the sweeper's
    // centre, and press it down into a gap (the contact's normal points down): such ticks are
    // counted apart; on them, too, the sweeper never goes into a pillar
    bool block_on_it = false;
    for (const sim::ContactPoint& cp : run.sim().contactPoints()) {
      if (cp.body == pillars)
        deepest_in_pillars = std::max(deepest_in_pillars, cp.depth_m);
      else if (cp.n_W.y < 0.0)
        block_on_it = true;
    }
    // over a pillar's top (its centre within the top's half width of a pillar's centre) the
    // sweeper rests on it; over a gap (18 mm) it may dip towards its target, 1 mm lower
    const double from_pillar = std::remainder(p.x - pillarCoordinate(0), kPitch_m);
    if (std::abs(from_pillar) < 0.5 * kPillarSize_m[0]) {
      ++over_tops;
      lowest = std::min(lowest, p.y);
    } else if (block_on_it) {
      ++pressed_by_block;
      lowest_pressed = std::min(lowest_pressed, p.y);
    } else {
      lowest_in_gap = std::min(lowest_in_gap, p.y);
    }
    worst_lag_x = std::max(worst_lag_x, std::abs(p.x - in.X_W_device.translation.x));
  });
  std::printf(
      "  over the field %u ticks (%u over a top), touching a pillar top %u; centre over a top "
      "never lower than %.3f mm (resting on the tops: %.1f mm), over a gap %.3f mm (%u ticks "
      "over a gap pressed down by a block: %.3f mm); deepest into a pillar %.4f mm; lag along "
      "the pass at most %.3f mm\n",
      over_field, over_tops, touching, 1e3 * lowest, 1e3 * ride_y, 1e3 * lowest_in_gap,
      pressed_by_block, 1e3 * lowest_pressed, 1e3 * deepest_in_pillars, 1e3 * worst_lag_x);
  EXPECT_GT(over_field, 1000u);
  EXPECT_GT(over_tops, 200u);
  EXPECT_GT(lowest_in_gap, ride_y - 0.0015);  // the target is 1 mm below the tops
  EXPECT_GT(touching, over_field / 4);        // it rides on the tops, losing contact over the gaps
  // never ploughs into a pillar: at most the proxy's penetration at the force limit (0.33 mm)
  EXPECT_GT(lowest, ride_y - 0.0005);
  EXPECT_LT(deepest_in_pillars, 0.0005);
  // pressed down by a block, it rests on the gap's two pillar edges at the lowest (18 mm apart
  // under a 15 mm radius: 3 mm below the tops' height)
  EXPECT_GT(lowest_pressed, ride_y - 0.003);
  // and keeps up with its stream (0.78 m/s at its peak): within 2 mm along the pass, except
  // where it pushes a block (the first pass pushes four)
  EXPECT_LT(worst_lag_x, 0.002 + kBlockSide_m);
}

}  // namespace
}  // namespace hapticd::simtest
