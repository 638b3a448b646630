// hapticctl study: the decision (the most accurate expressible settings whose p99.9 tick fits the
// budget) on tables built by hand, the setting texts, and the built binary at --quick size on a
// demo scene: its snippet parses as a config, names the row its own table says fits, and runs
// through a headless hapticd replay on the virtual clock. No wall-clock figure is asserted: which
// row fits depends on the machine, so the test reads the study's own table and checks the
// decision against it.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/study/report.h"
#include "bench/study/scene_study.h"
#include "core/geometry/polytope.h"
#include "core/scene/loader.h"
#include "core/scene/scene.h"
#include "core/sim/simulation.h"
#include "daemon/config.h"
#include "protocol/pose_stream.h"
#include "tests/client/command_dir.h"
#include "tests/core/decomp/models.h"

namespace {

namespace fs = std::filesystem;
using hapticd::study::knobsOf;
using hapticd::study::recommend;
using hapticd::study::Summary;

Summary row(const std::string& setting, double p99_n, double mean_n, double p999_ns) {
  Summary s;
  s.part = "scene/x";
  s.method = "hapticd-tick";
  s.setting = setting;
  s.force_n.p99 = p99_n;
  s.force_n.mean = mean_n;
  s.time_ns.p999 = p999_ns;
  return s;
}

std::vector<const Summary*> pointers(const std::vector<Summary>& rows) {
  std::vector<const Summary*> out;
  for (const Summary& r : rows)
    out.push_back(&r);
  return out;
}

TEST(StudyDecision, MostAccurateExpressibleRowThatFits) {
  const std::vector<Summary> rows{row(hapticd::study::kTruthSetting, 0.0, 0.0, 900.0),
                                  row("budget=8 pairs/tick", 0.0, 1e-9, 500.0),
                                  row("budget=4 pairs/tick", 0.5, 0.1, 300.0),
                                  row("δ off", 0.0, 0.0, 100.0),  // not in the config
                                  row("tessellation=0.01", 0.2, 0.1, 400.0)};
  // everything fits: the truth (no error, then the smaller mean error)
  auto r = recommend(pointers(rows), 1000.0);
  ASSERT_NE(r.row, nullptr);
  EXPECT_TRUE(r.fits);
  EXPECT_EQ(r.row->setting, hapticd::study::kTruthSetting);
  EXPECT_EQ(r.knobs.max_pairs_per_tick, 0u);
  // 600 ns: budget=8 (error 0) over the rest
  r = recommend(pointers(rows), 600.0);
  EXPECT_TRUE(r.fits);
  EXPECT_EQ(r.row->setting, "budget=8 pairs/tick");
  EXPECT_EQ(r.knobs.max_pairs_per_tick, 8u);
  // 450 ns: the tessellation row (0.2 N) beats budget=4 (0.5 N); δ off is faster and exact but
  // cannot be configured
  r = recommend(pointers(rows), 450.0);
  EXPECT_TRUE(r.fits);
  EXPECT_EQ(r.row->setting, "tessellation=0.01");
  EXPECT_DOUBLE_EQ(r.knobs.tessellation_tolerance, 0.01);
  EXPECT_EQ(r.knobs.max_pairs_per_tick, 0u);
  // 200 ns: nothing expressible fits: the fastest expressible, marked as not fitting
  r = recommend(pointers(rows), 200.0);
  ASSERT_NE(r.row, nullptr);
  EXPECT_FALSE(r.fits);
  EXPECT_EQ(r.row->setting, "budget=4 pairs/tick");
}

TEST(StudyDecision, EqualErrorsGoToTheFasterRow) {
  const std::vector<Summary> rows{row("budget=2 pairs/tick", 0.1, 0.01, 300.0),
                                  row("budget=1 pairs/tick", 0.1, 0.01, 200.0)};
  const auto r = recommend(pointers(rows), 1000.0);
  EXPECT_EQ(r.row->setting, "budget=1 pairs/tick");
}

TEST(StudyDecision, SettingTexts) {
  EXPECT_EQ(knobsOf("budget=16 pairs/tick")->max_pairs_per_tick, 16u);
  EXPECT_DOUBLE_EQ(knobsOf("tessellation=0.003")->tessellation_tolerance, 0.003);
  EXPECT_FALSE(knobsOf("δ off"));
  EXPECT_FALSE(knobsOf("budget=0 pairs/tick"));
  EXPECT_FALSE(knobsOf("budget=x pairs/tick"));
  EXPECT_FALSE(knobsOf("budget=4"));
  EXPECT_FALSE(knobsOf("tessellation=0.7"));
  EXPECT_FALSE(knobsOf("tessellation=0.01mm"));
  EXPECT_FALSE(knobsOf(""));
  // every run the study plans reads back as its own knobs
  hapticd::scene::SceneModel empty;
  for (const auto& run : hapticd::study::planRuns(empty)) {
    const auto k = knobsOf(run.setting);
    if (!run.knobs.predictive) {
      EXPECT_FALSE(k) << run.setting;
      continue;
    }
    ASSERT_TRUE(k) << run.setting;
    EXPECT_EQ(k->max_pairs_per_tick, run.knobs.max_pairs_per_tick);
    EXPECT_EQ(k->tessellation_tolerance, run.knobs.tessellation_tolerance);
  }
}

TEST(StudyDecision, SnippetParsesAsTheDaemonsConfig) {
  hapticd::study::Knobs k;
  k.max_pairs_per_tick = 4;
  k.tessellation_tolerance = 0.003;
  const std::string text = hapticd::study::configSnippet(k, {"a comment", "another"});
  auto parsed = hapticd::daemon::parseConfig(text, "snippet");
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(hapticd::daemon::toSimOptions(parsed.value().config).max_pairs_per_tick, 4u);
  EXPECT_DOUBLE_EQ(
      hapticd::daemon::toLoadOptions(parsed.value().config).limits.tessellation_tolerance, 0.003);
}

// --- the generated approach stream
// ----------------------------------------------------------------

std::shared_ptr<const hapticd::geom::Polytope> box(const hapticd::geom::Vec3& lo,
                                                   const hapticd::geom::Vec3& hi) {
  std::vector<hapticd::geom::Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y,
                         (i & 4) != 0 ? hi.z : lo.z);
  return std::make_shared<const hapticd::geom::Polytope>(
      hapticd::geom::Polytope::fromPoints(corners).value());
}

// Distance from p to the axis-aligned box [lo, hi] (0 inside).
double distanceToBox(const hapticd::geom::Vec3& p,
                     const hapticd::geom::Vec3& lo,
                     const hapticd::geom::Vec3& hi) {
  return glm::length(glm::max(glm::max(lo - p, p - hi), hapticd::geom::Vec3(0.0)));
}

// A scene without a probe body whose bounding box is empty above its middle (an L: a tall post at
// one end of a low slab, as a dragon's back or an arch leaves the middle empty): the config's
// probe sphere (radius 0.01 m) must come down onto the scene's highest point and press into it,
// not into the empty middle of the bounding box (where the stream once pressed into nothing and
// the study compared forces that were all zero).
TEST(StudyApproach, WithoutAProbeBodyTheSphereComesDownOntoTheHighestPoint) {
  using hapticd::geom::Vec3;
  const Vec3 post_lo(0.0, 0.0, 0.0), post_hi(0.1, 0.5, 0.1);
  const Vec3 slab_lo(0.0, 0.0, 0.0), slab_hi(1.0, 0.1, 0.1);
  hapticd::scene::SceneModel model;
  model.name = "L";
  hapticd::scene::Body body;
  body.name = "L";
  for (const auto& [lo, hi] : {std::pair{post_lo, post_hi}, std::pair{slab_lo, slab_hi}}) {
    hapticd::scene::Primitive p;
    p.shape = box(lo, hi);
    body.primitives.push_back(p);
  }
  model.bodies.push_back(body);
  ASSERT_LT(model.probe_body, 0);
  const auto rows = hapticd::study::approachStream(model, 0.5);
  ASSERT_FALSE(rows.empty());
  const double r = 0.01;  // the config's default probe sphere
  const auto gap = [&](const Vec3& c) {
    return std::min(distanceToBox(c, post_lo, post_hi), distanceToBox(c, slab_lo, slab_hi)) - r;
  };
  EXPECT_GT(gap(rows.front().X_WD.translation), 0.0) << "the stream starts clear of the scene";
  EXPECT_GT(gap(rows.back().X_WD.translation), 0.0) << "and ends clear of it";
  double deepest = 0.0;
  for (const auto& row : rows)
    deepest = std::min(deepest, gap(row.X_WD.translation));
  // it presses in by about 4 N at 600 N/m, at most a quarter of the sphere's radius
  EXPECT_LT(deepest, -0.2 * r) << "the sphere never pressed into the scene";
  EXPECT_GE(deepest, -0.25 * r - 1e-9);
}

// --- the built binary ---------------------------------------------------------------------------

class StudyCommand : public hapticd::testing::CommandDirTest {
 protected:
  StudyCommand() : CommandDirTest("hapticd_study") {}
  static std::string scene(const std::string& name) {
    return std::string(HAPTICD_SOURCE_DIR) + "/scenes/" + name + ".glb";
  }
};

// What the study's own table says: the expressible row with the least p99 force error (then mean
// error, then p99.9 tick) among those whose p99.9 tick fits; none fitting: the fastest.
const Summary* fromTable(const std::vector<Summary>& rows, double budget_ns, bool& fits) {
  const Summary* best = nullptr;
  const Summary* fastest = nullptr;
  for (const Summary& r : rows) {
    if (!knobsOf(r.setting))
      continue;
    if (fastest == nullptr || r.time_ns.p999 < fastest->time_ns.p999)
      fastest = &r;
    if (r.time_ns.p999 > budget_ns)
      continue;
    if (best == nullptr || r.force_n.p99 < best->force_n.p99 ||
        (r.force_n.p99 == best->force_n.p99 &&
         (r.force_n.mean < best->force_n.mean ||
          (r.force_n.mean == best->force_n.mean && r.time_ns.p999 < best->time_ns.p999))))
      best = &r;
  }
  fits = best != nullptr;
  return fits ? best : fastest;
}

TEST_F(StudyCommand, RecommendsWhatItsTableSaysFitsAndTheDaemonReplaysIt) {
  const std::string out_dir = path("out");
  // exit 0 when a row fits the default budget (one tick at 1 kHz), 1 when none does: which it is
  // depends on this machine's speed, so it is checked against the table below
  const int rc = run(HAPTICCTL, {"study", scene("peg_in_hole"), "--quick", "--out", out_dir});
  ASSERT_TRUE(rc == 0 || rc == 1) << rc << err();
  // progress, the estimate first
  EXPECT_NE(err().find("runs of"), std::string::npos) << err();
  EXPECT_NE(err().find("[1/"), std::string::npos) << err();
  for (const char* f : {"results.csv", "tables.md", "measured.txt", "recommended.toml",
                        "stream.csv", "scene_peg_in_hole.png"})
    EXPECT_GT(fs::file_size(fs::path(out_dir) / f), 10u) << f;
  EXPECT_EQ(out(), slurp(out_dir + "/recommended.toml"));

  std::vector<Summary> rows;
  std::string error;
  ASSERT_TRUE(hapticd::study::readCsv(out_dir + "/results.csv", rows, error)) << error;
  ASSERT_GE(rows.size(), 6u);
  for (const Summary& r : rows)
    EXPECT_GT(r.configurations, 1000u) << r.setting;  // 3 s at 1 kHz
  bool fits = false;
  const Summary* want = fromTable(rows, 1e6, fits);  // the default budget: one tick at 1 kHz
  ASSERT_NE(want, nullptr);
  EXPECT_EQ(rc, fits ? 0 : 1) << err();
  EXPECT_NE(out().find("setting: " + want->setting + ";"), std::string::npos) << out();

  // the snippet as the daemon reads it: the row's knobs
  auto parsed = hapticd::daemon::parseConfig(out(), "recommended.toml");
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const auto knobs = knobsOf(want->setting);
  ASSERT_TRUE(knobs);
  EXPECT_EQ(hapticd::daemon::toSimOptions(parsed.value().config).max_pairs_per_tick,
            knobs->max_pairs_per_tick);
  EXPECT_DOUBLE_EQ(
      hapticd::daemon::toLoadOptions(parsed.value().config).limits.tessellation_tolerance,
      knobs->tessellation_tolerance);

  // fed back: a headless replay of the study's stream on the virtual clock runs to its end
  EXPECT_EQ(
      run(HAPTICD_BINARY, {"--config", out_dir + "/recommended.toml", "--scene",
                           scene("peg_in_hole"), "--device", "replay:" + out_dir + "/stream.csv",
                           "--clock", "virtual", "--record", path("record.csv")}),
      0)
      << err();
  EXPECT_GT(fs::file_size(path("record.csv")), 1000u);
}

TEST_F(StudyCommand, NothingFitsATinyBudgetTheFastestIsPrintedAndExitIsOne) {
  const std::string out_dir = path("out");
  ASSERT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), "--quick", "--out", out_dir,
                            "--budget-us", "0.001"}),
            1)
      << err();
  EXPECT_NE(err().find("no setting's p99.9 tick fits"), std::string::npos) << err();
  std::vector<Summary> rows;
  std::string error;
  ASSERT_TRUE(hapticd::study::readCsv(out_dir + "/results.csv", rows, error)) << error;
  bool fits = true;
  const Summary* want = fromTable(rows, 1.0, fits);
  ASSERT_NE(want, nullptr);
  EXPECT_FALSE(fits);
  EXPECT_NE(out().find("setting: " + want->setting + ";"), std::string::npos) << out();
  EXPECT_NE(out().find("NO setting fits"), std::string::npos) << out();
}

TEST_F(StudyCommand, BadInputGetsCheckMessagesAndNothingRuns) {
  // a file that is not a scene: the same lines as `hapticctl check`, exit 1 like check
  { std::ofstream(path("bad.glb")) << "not a glb"; }
  ASSERT_EQ(run(HAPTICCTL, {"check", path("bad.glb")}), 1);
  const std::string check_err = err();
  ASSERT_FALSE(check_err.empty());
  EXPECT_EQ(run(HAPTICCTL, {"study", path("bad.glb"), "--out", path("out")}), 1);
  EXPECT_EQ(err(), check_err);
  EXPECT_FALSE(fs::exists(path("out")));
  // a bad stream: its file and line
  {
    std::ofstream(path("bad.csv")) << "t,px,py,pz,qx,qy,qz,qw,buttons\n0,0,0,0,0,0,0,1,0\n1,0,0\n";
  }
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), path("bad.csv"), "--out", path("out")}),
            1);
  EXPECT_NE(err().find("bad.csv"), std::string::npos) << err();
  EXPECT_NE(err().find("3"), std::string::npos) << err();
  EXPECT_FALSE(fs::exists(path("out")));
  // missing files and bad option values: 2
  EXPECT_EQ(run(HAPTICCTL, {"study", path("none.glb")}), 2);
  EXPECT_NE(err().find("cannot open"), std::string::npos) << err();
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), path("none.csv")}), 2);
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), "--rate", "0"}), 2);
  EXPECT_NE(err().find("--rate"), std::string::npos) << err();
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), "--budget-us", "-1"}), 2);
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), "--budget-us", "abc"}), 2);
}

TEST_F(StudyCommand, ARunLongerThanItsTimeLimitSaysSoBeforeItStarts) {
  const std::string out_dir = path("out");
  EXPECT_EQ(run(HAPTICCTL, {"study", scene("peg_in_hole"), "--quick", "--out", out_dir,
                            "--time-limit", "1e-6"}),
            1);
  EXPECT_NE(err().find("would take about"), std::string::npos) << err();
  EXPECT_NE(err().find("nothing was run"), std::string::npos) << err();
  EXPECT_EQ(err().find("[1/"), std::string::npos) << err();
  EXPECT_FALSE(fs::exists(fs::path(out_dir) / "results.csv"));
  EXPECT_TRUE(out().empty());
}

// a mesh as an OBJ of its v and f lines, at full precision
void writeObj(const hapticd::decomp::TriangleMesh& mesh, const std::string& file) {
  std::ofstream f(file);
  f.precision(17);
  for (const auto& v : mesh.positions)
    f << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
  for (const auto& t : mesh.triangles)
    f << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

// A real model made by others (the Stanford dragon of ../shared/meshes, skipped where absent),
// imported as a user would, under the study's generated approach: the config's probe sphere comes
// down onto the dragon's back, presses and slides where two pieces meet. There the proxy once
// fell into a cycle of two sub-steps (one toward the device into a piece, the next pushed out of
// it, each counted as progress), so every tick of the slide ran all max_substeps (64), the proxy
// where it started: ticks of 0.4 to 10 ms. Every tick must end before max_substeps, with the
// proxy still pressing the dragon.
TEST_F(StudyCommand, OnAnImportedDragonTheProxyNeverRunsOutOfSubSteps) {
  const auto mesh = hapticd::decomp::models::sharedMesh("dragon_lowres.obj");
  if (!mesh)
    GTEST_SKIP() << "shared/meshes/dragon_lowres.obj is not here (set HAPTICD_MESHES_DIR)";
  writeObj(*mesh, path("dragon.obj"));
  ASSERT_EQ(run(HAPTICCTL, {"import", path("dragon.obj"), "-o", path("dragon.glb")}), 0) << err();
  auto report = hapticd::scene::loadSceneFile(path("dragon.glb"));
  ASSERT_TRUE(report.ok()) << report.message();
  const auto model = std::make_shared<const hapticd::scene::SceneModel>(std::move(*report.scene));
  const auto stream = hapticd::study::approachStream(*model, 0.5);
  ASSERT_GE(stream.size(), 2u);
  const hapticd::sim::SimOptions options;
  auto sim = hapticd::sim::Simulation::create(model, options);
  ASSERT_TRUE(sim.ok()) << sim.error().message;
  const double dt = options.response.tick_s;
  const double end = stream.back().t_s;
  std::size_t cursor = 0, ticks = 0, touching = 0, most = 0, worst_tick = 0;
  for (std::size_t k = 0;; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (t > end)
      break;
    hapticd::sim::TickInput in;
    in.t_s = t;
    in.X_W_device = hapticd::proto::samplePoseStream(stream, t, cursor).X_WD;
    const auto out = sim.value()->step(in);
    ++ticks;
    if (out.contacts > 0)
      ++touching;
    if (out.proxy_substeps > most) {
      most = out.proxy_substeps;
      worst_tick = k;
    }
  }
  EXPECT_GT(ticks, 3000u);
  EXPECT_GT(touching, 1000u) << "the probe presses the dragon for over a second";
  EXPECT_LT(most, options.response.max_substeps)
      << "tick " << worst_tick << " ran all " << most << " sub-steps";
}

// A real part made by others (the machined part of ../shared/meshes, skipped where absent),
// imported as a user would, decomposed into 64 pieces, dynamic, and placed where a static floor
// 0.1 m thick already is: its lower 0.45 m reaches through the floor, so some of its pieces are
// pushed up and some down at once. It may stay caught, but nothing throws it: it once jittered
// for 1.5 s and then left at 1.5 km/s (a warm-start impulse counted twice, balanced by the
// floor's other side, grew tick by tick to 1e8 times the part's weight until one point left).
TEST_F(StudyCommand, OnAnImportedPartPlacedThroughAFloorNothingIsThrown) {
  const auto mesh = hapticd::decomp::models::sharedMesh("featuretype.STL");
  if (!mesh)
    GTEST_SKIP() << "shared/meshes/featuretype.STL is not here (set HAPTICD_MESHES_DIR)";
  writeObj(*mesh, path("part.obj"));
  writeObj(hapticd::decomp::models::box({-20, -0.1, -20}, {20, 0, 20}), path("floor.obj"));
  ASSERT_EQ(run(HAPTICCTL, {"import", path("floor.obj"), "--units", "m", "-o", path("s.glb")}), 0)
      << err();
  ASSERT_EQ(
      run(HAPTICCTL, {"import", path("part.obj"), "--units", "m", "--role", "dynamic", "--density",
                      "500", "--add", path("s.glb"), "--at", "0", "0.8", "0", "-o", path("s.glb")}),
      0)
      << err();
  auto report = hapticd::scene::loadSceneFile(path("s.glb"));
  ASSERT_TRUE(report.ok()) << report.message();
  const auto model = std::make_shared<const hapticd::scene::SceneModel>(std::move(*report.scene));
  hapticd::sim::SimOptions options;
  options.dynamics_sleep_time_s = 0.0;  // solved on every tick
  auto sim = hapticd::sim::Simulation::create(model, options);
  ASSERT_TRUE(sim.ok()) << sim.error().message;
  const auto partPose = [&] {
    for (const auto& b : sim.value()->bodyPoses()) {
      if (model->bodies[b.body].motion == hapticd::scene::Motion::kDynamic)
        return b.X_WB;
    }
    return hapticd::geom::Pose{};
  };
  const hapticd::geom::Vec3 start = partPose().translation;
  hapticd::sim::TickInput in;
  in.X_W_device.translation = {30, 30, 30};  // the probe far from everything
  double jump = 0.0, farthest = 0.0;
  hapticd::geom::Vec3 last = start;
  const double dt = options.response.tick_s;
  for (int k = 0; k < 3000; ++k) {
    in.t_s = k * dt;
    sim.value()->step(in);
    const hapticd::geom::Vec3 x = partPose().translation;
    ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z)) << "tick " << k;
    // after its first push out of the floor (0.07 m a tick for ten ticks)
    if (k >= 100)
      jump = std::max(jump, glm::length(x - last));
    farthest = std::max(farthest, glm::length(x - start));
    last = x;
  }
  std::printf("part through the floor: largest move in a tick %.4g m, farthest %.4g m\n", jump,
              farthest);
  // the part is 2.5 m tall; thrown, it moved 0.5 m a tick and went 7 km up
  EXPECT_LT(jump, 0.1);
  EXPECT_LT(farthest, 1.0);
}

}  // namespace
