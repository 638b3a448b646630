// The demo scenes (scenes/*.glb, through the loader) replayed from their pose streams
// (tests/streams/*.csv) at 1 kHz: every tick finite, within the limits and the force step, the
// proxy's penetration within 1 mm; passivity where the stream comes back to where it started.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/loader.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

class DemoScene : public ::testing::TestWithParam<const char*> {};

TEST_P(DemoScene, ReplaysItsPoseStreamWithinTheInvariants) {
  const std::string name = GetParam();
  const std::string dir = HAPTICD_SOURCE_DIR;
  auto report = scene::loadSceneFile(dir + "/scenes/" + name + ".glb");
  ASSERT_TRUE(report.ok()) << report.message();
  auto keys = readPoseStream(dir + "/tests/streams/" + name + ".csv");
  ASSERT_GE(keys.size(), 2u);
  const bool closed = glm::length(keys.front().X.translation - keys.back().X.translation) < 1e-9 &&
                      std::abs(glm::dot(keys.front().X.rotation, keys.back().X.rotation)) > 1.0 - 1e-12;
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  ASSERT_TRUE(created.ok()) << created.error().message;
  Runner run(std::move(created).value(), o);
  std::uint32_t max_pairs = 0, clamped = 0;
  const Figures f = run.run(Path(keys), [&](const sim::TickInput&, const sim::TickOutput& out) {
    max_pairs = std::max(max_pairs, out.pairs_tested);
    clamped += (out.flags & sim::kTickForceClamped) ? 1u : 0u;
    EXPECT_EQ(out.flags & sim::kTickCapacityFull, 0u);
  });
  f.print(name.c_str());
  std::printf("  %zu bodies, stream %s, most pairs tested in a tick %u, ticks clamped %u\n",
              model->bodies.size(), closed ? "closed" : "open", max_pairs, clamped);
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

INSTANTIATE_TEST_SUITE_P(Scenes, DemoScene,
                         ::testing::Values("peg_in_hole", "gears", "dynamic", "stress"),
                         [](const auto& param_info) { return std::string(param_info.param); });

}  // namespace
}  // namespace hapticd::simtest
