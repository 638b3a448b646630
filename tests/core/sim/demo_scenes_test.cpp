// The demo scenes (scenes/*.glb, through the loader) replayed from their pose streams
// (tests/streams/*.csv) at 1 kHz: every tick finite, within the limits and the force step, the
// proxy's penetration within 1 mm; passivity where the stream comes back to where it started.
#include "scenes/demo_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <thread>

#include "core/scene/loader.h"
#include "core/sim/model.h"
#include "core/sim/scene_state.h"
#include "tests/core/alloc_counter.h"
#include "tests/core/sim/demo_streams.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

// The scene GetParam() through the loader, and its pose stream.
class DemoScene : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    const std::string dir = HAPTICD_SOURCE_DIR;
    auto report = scene::loadSceneFile(dir + "/scenes/" + name + ".glb");
    ASSERT_TRUE(report.ok()) << report.message();
    model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
    keys = readPoseStream(dir + "/tests/streams/" + name + ".csv");
    ASSERT_GE(keys.size(), 2u);
  }

  const std::string name = GetParam();
  std::shared_ptr<const scene::SceneModel> model;
  std::vector<Key> keys;
};

TEST_P(DemoScene, ReplaysItsPoseStreamWithinTheInvariants) {
  const bool closed =
      glm::length(keys.front().X.translation - keys.back().X.translation) < 1e-9 &&
      std::abs(glm::dot(keys.front().X.rotation, keys.back().X.rotation)) > 1.0 - 1e-12;
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  std::uint32_t max_pairs = 0, clamped = 0, backed_off = 0, clamped_without_contact = 0;
  const Path path(keys);
  run.sim().prepareThread();
  const std::uint64_t allocations_before = testing_alloc::count();
  const Figures f = run.run(path, [&](const sim::TickInput&, const sim::TickOutput& out) {
    max_pairs = std::max(max_pairs, out.pairs_tested);
    clamped += (out.flags & sim::kTickForceClamped) ? 1u : 0u;
    // the force at the device's limit needs a contact: a penalty row, or the dynamics touching
    // the held set (issue 17: the proxy keeps up in free space)
    const bool contact = out.contacts > 0 || glm::length(out.impact_force_W_n) > 0.0 ||
                         out.dynamics_contact_points > 0;
    clamped_without_contact += (out.flags & sim::kTickForceClamped) && !contact ? 1u : 0u;
    backed_off += (out.flags & sim::kTickBackedOff) ? 1u : 0u;
    EXPECT_EQ(out.flags & sim::kTickCapacityFull, 0u);
  });
  const std::uint64_t allocations = testing_alloc::count() - allocations_before;
  f.print(name.c_str());
  EXPECT_EQ(allocations, 0u);  // the whole stream, after prepareThread()
  EXPECT_EQ(clamped_without_contact, 0u);
  std::printf(
      "  %zu bodies, stream %s, most pairs tested in a tick %u, ticks clamped %u (%u without a "
      "contact), ticks whose step was bisected back %u\n",
      model->bodies.size(), closed ? "closed" : "open", max_pairs, clamped, clamped_without_contact,
      backed_off);
  if (!closed) {
    // an open path proves nothing about energy: check the rest
    EXPECT_TRUE(f.all_finite);
    EXPECT_LE(f.max_force_n, o.response.max_force_n * (1.0 + 1e-12));
    EXPECT_LE(f.max_torque_nm, o.response.max_torque_nm * (1.0 + 1e-12));
    EXPECT_LE(f.max_force_step_n, o.response.max_force_step_n * (1.0 + 1e-9));
    EXPECT_LE(f.max_torque_step_nm, o.response.max_torque_step_nm * (1.0 + 1e-9));
    EXPECT_LE(f.max_penetration, 1e-3);
    EXPECT_LE(f.longest_alternation, 3u);
  } else {
    expectInvariants(f, o, 1e-3);
  }
}

// Without prepareThread() and on a thread that has queried nothing before, the whole stream
// allocates nothing from its first tick (the narrow phase's scratch is the state's, sized at
// create()).
TEST_P(DemoScene, AFreshThreadStepsTheStreamWithoutAllocating) {
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  const Path path(keys);
  std::uint64_t allocations = 0, pairs_tested = 0;
  std::uint64_t certified = 0, fallbacks = 0, cold = 0, untracked = 0;
  std::thread servo([&] {
    const std::uint64_t before = testing_alloc::count();
    run.run(path, [&](const sim::TickInput&, const sim::TickOutput& out) {
      pairs_tested += out.pairs_tested;
      certified += out.depth_certified;
      fallbacks += out.depth_fallbacks;
      cold += out.depth_cold;
      untracked += out.depth_untracked;
    });
    allocations = testing_alloc::count() - before;
  });
  servo.join();
  // the penetration depths of the replay (docs/narrow-phase.md "In the collision world")
  const sim::SceneState* state = run.sim().state();
  ASSERT_NE(state, nullptr);
  const collision::CollisionWorld::DepthCounters& d = state->world.depthCounters();
  std::printf(
      "[figures] %s: depths %llu certified from the pairs' trackers, %llu fallbacks (%.2g of the "
      "tracked), %llu cold, %llu untracked; trackers taken %llu (%llu lent), at most %u at once\n",
      name.c_str(), static_cast<unsigned long long>(certified),
      static_cast<unsigned long long>(fallbacks),
      certified + fallbacks > 0
          ? static_cast<double>(fallbacks) / static_cast<double>(certified + fallbacks)
          : 0.0,
      static_cast<unsigned long long>(cold), static_cast<unsigned long long>(untracked),
      static_cast<unsigned long long>(d.taken), static_cast<unsigned long long>(d.stolen), d.peak);
  EXPECT_GT(pairs_tested, 0u);  // the narrow phase ran
  // the depth trackers were taken and used on this thread (every stream but the decomposed one,
  // which never penetrates, has penetrating pairs)
  if (name != "decomposed") {
    EXPECT_GT(certified, 0u);
  }
  EXPECT_EQ(allocations, 0u);  // trackers included: taken from the pool reserved at create()
}

// The collision world's pool of depth trackers (collision::WorldOptions::depth_trackers) stays
// within its byte budget whatever the number of pieces (the decomposed scene: 600 pieces): every
// tracker is sized for the largest tracked shape, and the pool grows with the primitives only
// while the budget holds it.
TEST_P(DemoScene, TheDepthTrackerPoolIsSmallBesideThePairs) {
  sim::SimOptions o;
  auto compiled = sim::SimModel::compile(model, o);
  ASSERT_TRUE(compiled.ok()) << compiled.error().message;
  auto made = sim::makeState(*compiled.value());
  ASSERT_TRUE(made.ok()) << made.error().message;
  const collision::CollisionWorld& world = made.value().world;
  const double pool_mib = static_cast<double>(world.depthTrackerBytes()) / (1024.0 * 1024.0);
  std::printf("[figures] %s: %zu depth trackers, %.2f MiB (%zu reserved pairs)\n", name.c_str(),
              world.depthTrackers(), pool_mib, world.reservedPairs());
  // the automatic pool: two trackers per primitive, at least 64, within its 4 MiB budget
  EXPECT_GE(world.depthTrackers(), collision::WorldOptions::kMinAutoTrackers);
  EXPECT_LE(pool_mib, 4.0);
}

INSTANTIATE_TEST_SUITE_P(Scenes, DemoScene, demoStreams(), demoStreamName);

}  // namespace
}  // namespace hapticd::simtest

namespace hapticd::simtest {
namespace {

double angleZ(const Quat& q) {
  return 2.0 * std::atan2(q.z, q.w);
}

// gears.glb and its stream: the rod pushes a tooth of gear A round; A and B are dynamic bodies on
// hinges, so the dynamics turn them (with their inertia, only about their axes) and A drives B
// through the mesh.
TEST(GearsScene, TheProbeTurnsOneGearAndItTurnsTheOther) {
  const std::string dir = HAPTICD_SOURCE_DIR;
  auto report = scene::loadSceneFile(dir + "/scenes/gears.glb");
  ASSERT_TRUE(report.ok()) << report.message();
  auto keys = readPoseStream(dir + "/tests/streams/gears.csv");
  ASSERT_GE(keys.size(), 2u);
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  const auto poses = run.sim().bodyPoses();
  ASSERT_GE(poses.size(), 2u);
  std::size_t ia = poses.size(), ib = poses.size();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string& n = model->bodies[poses[i].body].name;
    if (n.find("GearA") != std::string::npos)
      ia = i;
    if (n.find("GearB") != std::string::npos)
      ib = i;
  }
  ASSERT_LT(ia, poses.size());
  ASSERT_LT(ib, poses.size());
  double a_min = 0.0, a_max = 0.0, worst_ratio_err = 0.0, max_force = 0.0;
  const Figures f = run.run(Path(keys), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const auto p = run.sim().bodyPoses();
    const double a = angleZ(p[ia].X_WB.rotation), b = angleZ(p[ib].X_WB.rotation);
    a_min = std::min(a_min, a);
    a_max = std::max(a_max, a);
    // once A has turned more than the backlash (about 0.6 degrees), B turns the other way by
    // the same angle (19 teeth each), less the backlash
    if (std::abs(a) > 2.0 * std::numbers::pi / 180.0) {
      worst_ratio_err =
          std::max(worst_ratio_err, std::abs(std::abs(b) - std::abs(a)) * 180.0 / std::numbers::pi);
      EXPECT_LT(a * b, 0.0) << "at t = " << in.t_s;
    }
    max_force = std::max(max_force, glm::length(out.force_W_n));
  });
  f.print("gears turned by the probe");
  std::printf(
      "  gear A turned from %.2f to %.2f deg; | |B| - |A| | at most %.3f deg (backlash ~0.6); "
      "largest force %.3f N\n",
      a_min * 180 / std::numbers::pi, a_max * 180 / std::numbers::pi, worst_ratio_err, max_force);
  EXPECT_LT(a_min * 180 / std::numbers::pi, -20.0);  // the stream sweeps 30 degrees clockwise
  EXPECT_GT(a_max * 180 / std::numbers::pi, 10.0);   // and 60 back
  EXPECT_LT(worst_ratio_err, 1.0);
  EXPECT_TRUE(f.all_finite);
  EXPECT_LE(f.max_force_step_n, o.response.max_force_step_n * (1.0 + 1e-9));
  EXPECT_LE(f.max_penetration, 1e-3);
}

// decomposed.glb and its stream: the held plate's first column of pins runs along a groove of
// the static plate (both ~100 and ~500 convex pieces of a decomposition) without leaving it, and
// pressed sideways the pins stop at the groove's wall.
TEST(DecomposedScene, ThePinsSlideInTheGrooveAndStopAtItsWall) {
  using namespace scenes::decomposed;
  const std::string dir = HAPTICD_SOURCE_DIR;
  auto report = scene::loadSceneFile(dir + "/scenes/decomposed.glb");
  ASSERT_TRUE(report.ok()) << report.message();
  auto keys = readPoseStream(dir + "/tests/streams/decomposed.csv");
  ASSERT_GE(keys.size(), 2u);
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  // the groove the first pins run in: x from -30 to -26 mm (the ridges' faces)
  const double groove_lo = kGrooveX_m - 0.5 * (kCell_m - kRidgeWidth_m);
  const double groove_hi = kGrooveX_m + 0.5 * (kCell_m - kRidgeWidth_m);
  double z_min = 1.0, z_max = -1.0, deepest = 0.0, widest_out = -1.0, push_x = 0.0;
  std::uint64_t run_ticks = 0, touching = 0, pushed = 0;
  const Figures f = run.run(Path(keys), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const bool along = in.t_s > 3.0 && in.t_s < 10.0;  // on the ridges, in the groove
    if (!along)
      return;
    ++run_ticks;
    touching += out.contacts > 0 ? 1u : 0u;
    z_min = std::min(z_min, out.X_W_proxy.translation.z);
    z_max = std::max(z_max, out.X_W_proxy.translation.z);
    // every corner of every first-column pin below the ridge tops is inside the groove
    const double h = 0.5 * kPinSide_m;
    for (int j = 0; j < kPinCellsZ; ++j) {
      const double z = (j - 0.5 * (kPinCellsZ - 1)) * kCell_m;
      for (int c = 0; c < 8; ++c) {
        const Vec3 p_B{(c & 1) ? h : -h, (c & 2) ? 0.0 : -kPinLength_m, z + ((c & 4) ? h : -h)};
        const Vec3 p_W = out.X_W_proxy.translation + out.X_W_proxy.rotation * p_B;
        deepest = std::min(deepest, p_W.y);
        if (p_W.y < 0.0)
          widest_out = std::max(widest_out, std::max(groove_lo - p_W.x, p_W.x - groove_hi));
      }
    }
    if (in.t_s > 7.5 && in.t_s < 9.5) {  // pressed 1 mm towards +X
      ++pushed;
      push_x = std::max(push_x, out.X_W_proxy.translation.x - kRunX_m);
      EXPECT_LT(out.force_W_n.x, 0.0) << "t = " << in.t_s;  // the wall pushes the hand back
    }
  });
  f.print("decomposed: the pin plate along the groove");
  std::printf(
      "  proxy z from %.1f to %.1f mm, pins down to %.2f mm, at most %.3f mm outside the groove "
      "below the ridge tops, touching in %llu of %llu ticks; pressed 1 mm sideways the proxy "
      "moved %.3f mm\n",
      z_min * 1e3, z_max * 1e3, deepest * 1e3, widest_out * 1e3,
      static_cast<unsigned long long>(touching), static_cast<unsigned long long>(run_ticks),
      push_x * 1e3);
  EXPECT_GT(z_max - z_min, 0.9 * (kRunZ_m[1] - kRunZ_m[0]));  // it slid the run's length
  EXPECT_LT(deepest, -0.002);                                 // 2 mm deep in the groove
  EXPECT_LE(widest_out, 1e-3 * 0.1);  // within 0.1 mm (the proxy's penetration allowance)
  EXPECT_GT(touching, run_ticks / 2);
  EXPECT_GT(pushed, 0u);
  EXPECT_LT(push_x, 0.0006);  // the clearance to the wall is 0.42 mm; the device went 1 mm
  EXPECT_TRUE(f.all_finite);
  EXPECT_LE(f.max_penetration, 1e-3);
}

// decomposed.glb on its stream: the boxes' margin (twice the safe distance, which is relative to
// the probe's size: 3.1 mm for this plate of radius 79 mm) makes some 413 piece pairs' boxes
// overlap every tick, most of them farther apart than anything the proxy reads (its rows: two safe
// distances); the world tests only the pairs that may be nearer than that
// (WorldOptions::far_distance).
TEST(DecomposedScene, TestsOnlyThePiecePairsTheProxyMayRead) {
  auto model = loadDemo("decomposed");
  ASSERT_NE(model, nullptr);
  auto keys = readPoseStream(std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/decomposed.csv");
  ASSERT_GE(keys.size(), 2u);
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  std::uint64_t ticks = 0, pairs = 0, most = 0, touching = 0;
  run.run(Path(keys), [&](const sim::TickInput&, const sim::TickOutput& out) {
    ++ticks;
    pairs += out.pairs_tested;
    most = std::max<std::uint64_t>(most, out.pairs_tested);
    touching += out.contacts > 0 ? 1u : 0u;
  });
  const double mean = static_cast<double>(pairs) / static_cast<double>(ticks);
  std::printf(
      "  piece pairs tested: %.1f a tick on average, at most %llu; touching in %llu ticks\n", mean,
      static_cast<unsigned long long>(most), static_cast<unsigned long long>(touching));
  EXPECT_LT(mean, 100.0);  // 74 measured; 413 when every pair whose boxes overlap was tested
  // where the plate crosses its cells' boundaries, the pairs of every cell come near together
  // (215 measured)
  EXPECT_LT(most, 300u);
  EXPECT_GT(touching, ticks / 4);  // the pairs tested are those in contact
}

}  // namespace
}  // namespace hapticd::simtest
