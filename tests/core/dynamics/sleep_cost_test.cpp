// Sleeping islands in the collision world (Dynamics::syncSleep): a resting scene costs the
// world's step nothing whatever its size, and an island woken is solved with its own contacts in
// the tick it wakes. By counters, not by timing.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/core/alloc_counter.h"
#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

struct Counts {
  std::uint32_t listed_awake = 0;    // contacts listed while every box is awake
  std::uint32_t visited_asleep = 0;  // most pairs a step looked at once the scene slept
  std::uint32_t tested_asleep = 0;   // most pairs a step tested then
  std::uint32_t listed_asleep = 0;   // most contacts listed then
  std::uint32_t wake_points = 0;     // contact points the dynamics solved in the wake tick
  std::uint32_t visited_woken = 0;   // pairs the next step looked at
  std::uint64_t allocations = 0;     // while asleep and through the wake
  bool others_asleep = true;         // the boxes not pushed slept on
};

// n boxes of 2 cm resting on a floor, 6 cm apart (each its own island, no two within twice the
// box margin of each other at either size), and a kinematic probe
// moving in free space 20 cm above them; after the scene sleeps, one box is pushed (below the
// friction limit) and wakes alone
Counts run(int n) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(0.6, 0.0));
  const double h = 0.01;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  const double half = 0.03 * side + 0.05;
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{half, h, half}), at(Vec3{0, -h, 0}), 0));
  for (int i = 0; i < n; ++i) {
    s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}),
                                   at(Vec3{(i % side - 0.5 * side) * 0.06, h,
                                           (static_cast<double>(i / side) - 0.5 * side) * 0.06}),
                                   500.0, 0));
  }
  Body probe = staticBody("probe", boxShape(Vec3{0.005}), at(Vec3{0, 0.2, 0}));
  probe.motion = Motion::kKinematic;
  probe.probe = true;
  s.bodies.push_back(probe);
  s.probe_body = static_cast<std::int32_t>(s.bodies.size() - 1);
  s.length_scale = lengthScale(s);
  const auto scene = std::make_shared<SceneModel>(std::move(s));
  collision::WorldOptions wo;  // as the Simulation's: unmoved pairs keep their answers
  wo.skip_unmoved_pairs = true;
  wo.box_margin = 1e-3;
  auto world = buildCollisionWorld(*scene, wo).value();
  auto dyn = std::move(Dynamics::create(*scene, *world, DynamicsOptions{}).value());
  const auto probe_id = static_cast<std::uint32_t>(scene->probe_body);

  Counts c;
  HeldInput held;
  held.mode = HeldMode::kKinematic;
  const auto tick = [&](int k) {
    held.X_WB_target =
        Pose{Vec3{0.05 * std::sin(0.05 * k), 0.2, 0.05 * std::cos(0.05 * k)}, Quat{1, 0, 0, 0}};
    world->setPose(probe_id, held.X_WB_target);
    const collision::StepStats st = world->step();
    const StepReport r = dyn->step(*world, 0.001, &held);
    return std::make_pair(st, r);
  };
  // settle a few ticks, then sleep at once (as a scene swap's prewarm does)
  int k = 0;
  int still = 0;
  for (; k < 200 && still < 4; ++k) {
    tick(k);
    if (k == 0)
      c.listed_awake = static_cast<std::uint32_t>(world->contacts().size());
    still = dyn->stillNow(*world) ? still + 1 : 0;
  }
  EXPECT_TRUE(dyn->sleepIfStill(*world));
  dyn->syncSleep(*world);
  const std::uint64_t alloc0 = testing_alloc::count();
  for (int j = 0; j < 100; ++j, ++k) {
    const auto [st, r] = tick(k);
    EXPECT_NE(r.flags & kStepAsleep, 0u);
    c.visited_asleep = std::max(c.visited_asleep, st.pairs_visited);
    c.tested_asleep = std::max(c.tested_asleep, st.pairs_tested);
    c.listed_asleep =
        std::max(c.listed_asleep, static_cast<std::uint32_t>(world->contacts().size()));
  }
  // one box pushed sideways at a third of what friction holds: it wakes, and its contact with
  // the floor is solved in that very tick (listed again by the world's relist())
  const std::uint32_t pushed = 1 + static_cast<std::uint32_t>(n / 2);
  const double m = scene->bodies[pushed].mass;
  dyn->setExternalWrench(pushed, Vec3{0.2 * m * 9.81, 0, 0}, Vec3{0.0});
  const auto woke = tick(k++);
  c.wake_points = woke.second.contact_points;
  EXPECT_FALSE(dyn->asleep(pushed));
  c.visited_woken = tick(k++).first.pairs_visited;
  c.allocations = testing_alloc::count() - alloc0;
  for (std::uint32_t b = 1; b <= static_cast<std::uint32_t>(n); ++b)
    c.others_asleep = c.others_asleep && (b == pushed || dyn->asleep(b));
  return c;
}

TEST(Islands, ARestingSceneCostsTheCollisionStepNothingWhateverItsSize) {
  const Counts small = run(20), large = run(400);
  EXPECT_GE(small.listed_awake, 20u);  // awake: every box's pair with the floor
  EXPECT_GE(large.listed_awake, 400u);
  for (const Counts& c : {small, large}) {
    EXPECT_EQ(c.visited_asleep, 0u);
    EXPECT_EQ(c.tested_asleep, 0u);
    EXPECT_EQ(c.listed_asleep, 0u);
    EXPECT_GE(c.wake_points, 4u);  // the woken box on the floor: its four corners
    EXPECT_TRUE(c.others_asleep);
    EXPECT_EQ(c.allocations, 0u);
  }
  EXPECT_EQ(small.wake_points, large.wake_points);
  EXPECT_EQ(small.visited_woken, large.visited_woken);
  EXPECT_EQ(large.visited_woken, 1u);  // the woken box's pair with the floor (and none other)
}

}  // namespace
}  // namespace hapticd::dynamics::testing
