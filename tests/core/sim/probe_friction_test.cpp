// Friction felt at the probe (issue 17 point 4): the held set's contacts carry Coulomb friction
// from the combined materials. A held block pressed on a flat surface and pushed along it sticks
// while the coupling's tangential pull is inside the friction cone and slides on its edge, the
// hand feeling mu N; off when the materials say no friction; passive on every demo stream with
// friction on every collider.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "tests/core/sim/demo_streams.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

struct FrictionRun {
  double stuck_proxy_move = 0.0;  // proxy travel along x while the device pulls within the cone
  double stuck_pull = 0.0;        // |F_t| / F_n then
  double slide_ratio_min = 1e9, slide_ratio_max = 0.0;  // |F_t| / F_n while sliding steadily
  double slide_normal = 0.0;                            // F_n then (N)
  double energy_to_hand = 0.0;
};

// a 20 mm block held 3 mm (of target) into a floor, then pulled 1.4 mm along x (kept), then
// pushed 60 mm along x at 60 mm/s; the floor and the block of material (mu_s, mu_d)
FrictionRun pushBlock(double mu_s, double mu_d) {
  scene::SceneModel sc;
  scene::Material mat;
  mat.name = "test";
  mat.static_friction = mu_s;
  mat.dynamic_friction = mu_d;
  sc.materials.push_back(mat);
  auto floor =
      makeBody("floor", scene::Motion::kStatic, at(0, -0.01, 0), {boxShape(Vec3{0.2, 0.01, 0.2})});
  floor.primitives[0].material = 0;
  sc.bodies.push_back(floor);
  auto block =
      makeBody("block", scene::Motion::kKinematic, at(-0.05, 0.02, 0), {boxShape(Vec3{0.01})});
  block.probe = true;
  block.primitives[0].material = 0;
  sc.bodies.push_back(block);
  scene::SceneModel copy = sc;
  auto model = finish(std::move(copy));
  auto planned = std::make_shared<scene::SceneModel>(*model);
  planned->plan.friction = mu_s > 0.0 || mu_d > 0.0;  // as makePlan says for these materials
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(planned, o), o);
  const double y = 0.01 - 0.003;  // the block's centre with its bottom 3 mm into the floor
  // the stuck pull: 1.4 mm of coupling stretch, k_c * 1.4 mm = 0.857 N = 0.467 F_n
  Path path({{0.0, at(-0.05, 0.02, 0)},
             {0.3, at(-0.05, y, 0)},
             {0.5, at(-0.05, y, 0)},
             {0.6, at(-0.05 + 0.0014, y, 0)},
             {0.9, at(-0.05 + 0.0014, y, 0)},
             {1.9, at(0.01, y, 0)},
             {2.0, at(0.01, y, 0)}});
  FrictionRun r;
  double proxy_x_at_pull = 0.0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const Vec3 F = out.force_W_n;
    const double fn = F.y, ft = std::sqrt(F.x * F.x + F.z * F.z);
    if (std::abs(in.t_s - 0.5) < 1e-9)
      proxy_x_at_pull = out.X_W_proxy.translation.x;
    if (in.t_s > 0.5 && in.t_s <= 0.9) {
      r.stuck_proxy_move =
          std::max(r.stuck_proxy_move, std::abs(out.X_W_proxy.translation.x - proxy_x_at_pull));
      r.stuck_pull = std::max(r.stuck_pull, ft / fn);
    }
    if (in.t_s > 1.2 && in.t_s < 1.8) {  // sliding at a steady 60 mm/s
      r.slide_ratio_min = std::min(r.slide_ratio_min, ft / fn);
      r.slide_ratio_max = std::max(r.slide_ratio_max, ft / fn);
      r.slide_normal = fn;
    }
  });
  r.energy_to_hand = f.energy_to_hand_j;
  return r;
}

TEST(ProbeFriction, ABlockPushedAlongAFloorSticksThenSlidesFeelingMuN) {
  struct Case {
    double mu_s, mu_d;
  };
  for (const Case c : {Case{0.5, 0.5}, Case{0.6, 0.4}, Case{0.0, 0.0}}) {
    const FrictionRun r = pushBlock(c.mu_s, c.mu_d);
    std::printf(
        "  mu_s %.1f mu_d %.1f: pulled within the cone the proxy moved %.3g mm (pull %.3f N_n); "
        "sliding |F_t| / F_n from %.4f to %.4f (F_n %.3f N); energy to the hand %.3g J\n",
        c.mu_s, c.mu_d, 1e3 * r.stuck_proxy_move, r.stuck_pull, r.slide_ratio_min,
        r.slide_ratio_max, r.slide_normal, r.energy_to_hand);
    EXPECT_GT(r.slide_normal, 1.0);
    if (c.mu_s > 0.0) {
      // the pull (0.467 F_n) is inside the static cone: the proxy sticks, with mu_s = 0.6 even
      // though the pull is beyond mu_d = 0.4 (a body at rest breaks away only beyond mu_s N)
      EXPECT_LT(r.stuck_pull, c.mu_s);
      EXPECT_GT(r.stuck_pull, 0.45);
      EXPECT_LT(r.stuck_proxy_move, 1e-9);
    } else {
      EXPECT_GT(r.stuck_proxy_move, 0.0013);  // frictionless: it follows the pull
    }
    // sliding: mu_d N within 2 %
    EXPECT_NEAR(r.slide_ratio_min, c.mu_d, 0.02 * c.mu_d + 1e-6);
    EXPECT_NEAR(r.slide_ratio_max, c.mu_d, 0.02 * c.mu_d + 1e-6);
    EXPECT_LE(r.energy_to_hand, 0.0);
  }
}

// A held 20 mm block pressed 3 mm (of target) onto a floor of flush tiles (25 mm static boxes,
// their tops in one plane) and pushed 150 mm across six seams at 60 mm/s and at 0.6 m/s,
// frictionless: it slides as over one floor, no force along the push beyond the coupling's lag
// over one floor. Before the levelling of contacts at flush seams (docs/collision-pipeline.md
// "Flush seams") the proxy stuck at the first seam, the device pulling away at the force limit;
// with it, but the next tile's side, 0.1 mm ahead of the block, taken for a plane the block
// rested on and so left as answered, 0.07 N at each seam at 60 mm/s.
TEST(Seams, TheProbeSlidesOverFlushTilesAsOverOneFloor) {
  const auto run = [](bool tiles, double speed) {
    scene::SceneModel sc;
    if (tiles) {
      for (int i = 0; i < 12; ++i)
        sc.bodies.push_back(makeBody("tile", scene::Motion::kStatic, at(-0.1 + 0.025 * i, -0.01, 0),
                                     {boxShape(Vec3{0.0125, 0.01, 0.2})}));
    } else {
      sc.bodies.push_back(makeBody("floor", scene::Motion::kStatic, at(0.0375, -0.01, 0),
                                   {boxShape(Vec3{0.15, 0.01, 0.2})}));
    }
    auto block =
        makeBody("block", scene::Motion::kKinematic, at(-0.05, 0.02, 0), {boxShape(Vec3{0.01})});
    block.probe = true;
    sc.bodies.push_back(block);
    auto model = finish(std::move(sc));
    sim::SimOptions o;
    o.response.ramp_s = 0.0;
    Runner r(make(model, o), o);
    const double y = 0.01 - 0.003;
    const double t_push = 0.15 / speed;
    Path path({{0.0, at(-0.05, 0.02, 0)},
               {0.3, at(-0.05, y, 0)},
               {0.5, at(-0.05, y, 0)},
               {0.5 + t_push, at(0.1, y, 0)},
               {0.6 + t_push, at(0.1, y, 0)}});
    double fx_max = 0.0, proxy_end = 0.0;
    r.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
      if (in.t_s > 0.5)
        fx_max = std::max(fx_max, std::abs(out.force_W_n.x));
      proxy_end = out.X_W_proxy.translation.x;
    });
    return std::pair{fx_max, proxy_end};
  };
  for (const double speed : {0.06, 0.6}) {
    const auto [fx_one, end_one] = run(false, speed);
    const auto [fx_tiles, end_tiles] = run(true, speed);
    std::printf(
        "  %.2f m/s: largest |F_x| one floor %.4f N, tiles %.4f N; proxy at %.6f / %.6f m\n", speed,
        fx_one, fx_tiles, end_one, end_tiles);
    EXPECT_NEAR(end_tiles, 0.1, 1e-6) << speed;
    // (0.05 % of the normal force, 1.84 N)
    EXPECT_LE(fx_tiles, fx_one + 1e-3) << speed;
  }
}

// Every demo stream with friction on every collider (static 0.6, dynamic 0.5; the default the
// scenes without materials will get): the energy the device gives the hand never exceeds what
// the coupling can hold at the end of the stream (1/2 F^2 / k_c: zero for a stream that ends in
// free space), so friction makes the coupling no less passive. decomposed and stress are cut to
// their first 5 s and 8 s (into the groove and along it; three passes over the pillars), to keep
// the suite light.
class ProbeFrictionDemo : public ::testing::TestWithParam<const char*> {};

TEST_P(ProbeFrictionDemo, TheEnergyIntoTheHandStaysNonPositive) {
  const std::string name = GetParam();
  auto demo = loadDemo(name);
  ASSERT_TRUE(demo);
  scene::SceneModel sc = *demo;
  scene::Material rough;
  rough.name = "rough";
  rough.static_friction = 0.6;
  rough.dynamic_friction = 0.5;
  sc.materials.push_back(rough);
  for (scene::Body& b : sc.bodies) {
    for (scene::Primitive& p : b.primitives)
      p.material = static_cast<std::int32_t>(sc.materials.size() - 1);
  }
  sc.plan = scene::makePlan(sc);
  ASSERT_TRUE(sc.plan.friction);
  auto keys = readPoseStream(std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv");
  const double t_end = name == "decomposed" ? 5.0 : (name == "stress" ? 8.0 : 1e9);
  while (keys.back().t_s > t_end)
    keys.pop_back();
  ASSERT_GE(keys.size(), 2u);
  sim::SimOptions o;
  Runner run(make(std::make_shared<const scene::SceneModel>(std::move(sc)), o), o);
  std::uint64_t stuck = 0, slid = 0;
  sim::TickOutput last;
  const Figures f = run.run(Path(keys), [&](const sim::TickInput&, const sim::TickOutput& out) {
    stuck += out.proxy_stuck ? 1u : 0u;
    slid += out.proxy_sliding ? 1u : 0u;
    last = out;
  });
  const double stored = 0.5 * glm::dot(last.force_W_n, last.force_W_n) /
                        (o.response.stiffness_n_per_m * o.response.proxy_stiffness_ratio /
                         (o.response.proxy_stiffness_ratio - 1.0));
  std::printf(
      "  %s with friction: %llu ticks stuck, %llu sliding; energy to the hand %.4g J of %.4g J "
      "moved (%.2f%%), the coupling holds %.3g J at the end; largest |F| %.3f N\n",
      name.c_str(), static_cast<unsigned long long>(stuck), static_cast<unsigned long long>(slid),
      f.energy_to_hand_j, f.energy_abs_j, 100.0 * f.energy_to_hand_j / f.energy_abs_j, stored,
      f.max_force_n);
  EXPECT_TRUE(f.all_finite);
  EXPECT_LE(f.energy_to_hand_j, stored);
  EXPECT_LE(f.max_force_n, o.response.max_force_n * (1.0 + 1e-12));
}

INSTANTIATE_TEST_SUITE_P(
    Demo,
    ProbeFrictionDemo,
    ::testing::Values("peg_in_hole", "gears", "dynamic", "stress", "decomposed"),
    [](const ::testing::TestParamInfo<const char*>& param) { return std::string(param.param); });

}  // namespace
}  // namespace hapticd::simtest
