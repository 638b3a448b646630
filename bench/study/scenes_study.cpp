// The scene part of the accuracy study: each demo scene replayed from its pose stream through the
// whole tick (core/sim), with the settings that trade accuracy for time, against the same tick at
// its most accurate settings.
//
// - Closed loop (bench/study/scene_study.h, shared with `hapticctl study`): the scheduler budget
//   (pairs tested per tick: unlimited, 8, 4, 2, 1), the predictive distance δ of §5.2 on and off,
//   and the tessellation tolerance of curved shapes. Each run is the real tick, so its error is
//   what the hand would feel: the force and torque sent to the device, against the truth run's,
//   tick by tick on the same pose stream.
// - Knob sweeps with a truth of their own (runSweep): the dynamics solver's iterations on the
//   dynamic demo and on a stack of boxes (parts dynamics/...: the truth at 100 velocity and 50
//   split-impulse iterations; drift and energy beside the force), and the output stage's step
//   limit F_max and force shading's crease angle on peg_in_hole, gears and stress (parts
//   shaping/...: the truth without a step limit, shading at its default).
// - Methods inside the closed loop (loop_methods.h): the paper's depth along the motion and three
//   peer libraries answer every pair query of the tick in place of its own, at the default
//   settings, each a row "closed loop" of the scene's part.
// - Open loop: voxel sampling (McNeely et al. 1999) at the truth run's proxy poses: the static
//   bodies as a voxel map, the held body as a point shell, its force against the truth's contact
//   wrench at the same pose (the force the coupling balances), its stiffness fitted by least
//   squares on every fifth tick and scored on the others. Moving bodies are not in the voxel map
//   (McNeely's method voxelises a static scene): contacts with them are misses, and counted.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#include "bench/study/loop_methods.h"
#include "bench/study/scene_study.h"
#include "bench/study/study.h"
#include "core/dynamics/dynamics.h"
#include "core/scene/loader.h"
#include "core/voxel/voxel_sampling.h"

#ifndef HAPTICD_SOURCE_DIR
#define HAPTICD_SOURCE_DIR "."
#endif

namespace hapticd::study {
namespace {

using geom::Pose;
using geom::Quat;
using geom::Vec3;

std::string fmt(double x, const char* f = "%g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

// The dynamics solver's iterations: the truth at 100 velocity and 50 split-impulse iterations,
// then the velocity iterations swept at the default split-impulse count and the split-impulse
// iterations at the default velocity count, each a fixed count (no settling iterations beyond
// it: what the count alone costs and buys), and the defaults with and without their settling
// iterations (the default run lies on both lines, run once). Quick: the extremes and the default
// only.
std::vector<PlannedRun> iterationRuns(bool quick) {
  const Knobs defaults;
  std::vector<PlannedRun> runs;
  Knobs truth;
  truth.velocity_iterations = 100;
  truth.position_iterations = 50;
  truth.velocity_iterations_max = 0;
  truth.position_iterations_max = 0;
  runs.push_back({"iterations 100/50 (the truth)", truth});
  Knobs fixed;
  fixed.velocity_iterations_max = 0;
  fixed.position_iterations_max = 0;
  runs.push_back({"no settling iterations (12/6 fixed)", fixed});
  const std::vector<std::uint32_t> velocity =
      quick ? std::vector<std::uint32_t>{1u, defaults.velocity_iterations}
            : std::vector<std::uint32_t>{1u, 4u, defaults.velocity_iterations, 32u};
  const std::vector<std::uint32_t> position =
      quick ? std::vector<std::uint32_t>{0u, defaults.position_iterations}
            : std::vector<std::uint32_t>{0u, 2u, defaults.position_iterations, 18u};
  for (const std::uint32_t v : velocity) {
    Knobs k;
    k.velocity_iterations = v;
    if (v != defaults.velocity_iterations)
      k.velocity_iterations_max = k.position_iterations_max = 0;
    runs.push_back({"velocity iterations=" + std::to_string(v) +
                        (v == defaults.velocity_iterations ? " (default)" : " (no settling)"),
                    k});
  }
  for (const std::uint32_t p : position) {
    Knobs k;
    k.position_iterations = p;
    if (p != defaults.position_iterations)
      k.velocity_iterations_max = k.position_iterations_max = 0;
    runs.push_back({"split-impulse iterations=" + std::to_string(p) +
                        (p == defaults.position_iterations ? " (default)" : " (no settling)"),
                    k});
  }
  return runs;
}

// The output stage's step limit and force shading: the truth without a step limit (1e6 N per
// tick) and shading at its default angle; F_max swept (the torque twin scaled with it), then the
// crease angle without a step limit. Quick: two of each.
std::vector<PlannedRun> shapingRuns(bool quick) {
  const Knobs defaults;
  constexpr double kOff = 1e6;
  std::vector<PlannedRun> runs;
  Knobs truth;
  truth.max_force_step_n = kOff;
  runs.push_back(
      {"no step limit, shading " + fmt(defaults.crease_angle_deg) + "° (the truth)", truth});
  const std::vector<double> steps =
      quick ? std::vector<double>{0.1, defaults.max_force_step_n}
            : std::vector<double>{0.1, 0.25, defaults.max_force_step_n, 2.0};
  const std::vector<double> angles =
      quick ? std::vector<double>{0.0, 60.0} : std::vector<double>{0.0, 20.0, 60.0, 85.0};
  for (const double f : steps) {
    Knobs k;
    k.max_force_step_n = f;
    runs.push_back(
        {"F_max=" + fmt(f) + " N/tick" + (f == defaults.max_force_step_n ? " (default)" : ""), k});
  }
  for (const double a : angles) {
    Knobs k;
    k.max_force_step_n = kOff;
    k.crease_angle_deg = a;
    runs.push_back({"crease angle=" + fmt(a) + "°" + (a == 0.0 ? " (shading off)" : ""), k});
  }
  return runs;
}

// A stack of five 40 mm boxes (50 g) on a static floor under gravity, no probe body (the probe
// sphere of 10 mm is the hand); the default material's friction.
std::shared_ptr<const scene::SceneModel> stackScene() {
  scene::SceneModel s;
  s.name = "stack";
  s.gravity_W = Vec3{0.0, -9.81, 0.0};
  const auto box = [](const Vec3& h) {
    std::vector<Vec3> p;
    p.reserve(8);
    for (int i = 0; i < 8; ++i)
      p.push_back(
          Vec3{(i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y, (i & 4) != 0 ? h.z : -h.z});
    return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(p).value());
  };
  scene::Body floor;
  floor.name = "floor";
  floor.X_WB.translation = Vec3{0.0, -0.01, 0.0};
  floor.primitives.push_back(
      scene::Primitive{box(Vec3{0.2, 0.01, 0.2}), Pose{}, scene::ShapeSource::kCode, -1, -1});
  s.bodies.push_back(floor);
  constexpr double kHalf = 0.02;
  const auto cube = box(Vec3{kHalf});
  for (int level = 0; level < 5; ++level) {
    scene::Body b;
    b.name = "box" + std::to_string(level);
    b.motion = scene::Motion::kDynamic;
    b.X_WB.translation = Vec3{0.0, kHalf + 2.0 * kHalf * level, 0.0};
    b.primitives.push_back(scene::Primitive{cube, Pose{}, scene::ShapeSource::kCode, -1, -1});
    const auto mp = dynamics::computeMassProperties(b.primitives, 0.05 / std::pow(2.0 * kHalf, 3));
    b.mass = mp.mass;
    b.inverse_mass = 1.0 / mp.mass;
    b.com_B = mp.com_B;
    b.inertia_B = mp.inertia_B;
    s.bodies.push_back(b);
  }
  s.length_scale = 0.4;
  s.plan.contact_forces = true;
  s.plan.dynamics = true;
  s.plan.gravity = true;
  s.plan.friction = true;
  s.plan.static_primitives = 1;
  s.plan.moving_primitives = 5;
  return std::make_shared<const scene::SceneModel>(std::move(s));
}

// The stack's stream (4 s): the probe sphere rests beside the top box, comes in and pushes it 4
// mm sideways, holds, backs out, and the stack settles.
std::vector<proto::PoseStreamRow> stackStream() {
  const auto at = [](double x) { return Pose{Vec3{x, 0.18, 0.0}, Quat{1.0, 0.0, 0.0, 0.0}}; };
  struct Key {
    double t, x;
  };
  // the top box's face at x = -0.02, the sphere's radius 0.01: touching at x = -0.03
  const Key keys[] = {{0.0, -0.06},  {0.5, -0.06}, {1.5, -0.03}, {2.0, -0.026},
                      {2.5, -0.026}, {3.0, -0.06}, {4.0, -0.06}};
  std::vector<proto::PoseStreamRow> rows;
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.01 * i;
    std::size_t k = 1;
    while (k + 1 < std::size(keys) && keys[k].t < t)
      ++k;
    const double u = std::clamp((t - keys[k - 1].t) / (keys[k].t - keys[k - 1].t), 0.0, 1.0);
    const double w = 0.5 - 0.5 * std::cos(std::numbers::pi * u);
    rows.push_back({t, at(keys[k - 1].x + w * (keys[k].x - keys[k - 1].x)), 0});
  }
  return rows;
}

void sweep(const std::string& part,
           const std::shared_ptr<const scene::SceneModel>& model,
           const std::vector<proto::PoseStreamRow>& stream,
           const SceneStudyOptions& base,
           const std::vector<PlannedRun>& runs,
           std::vector<Row>& rows) {
  SceneStudyOptions so = base;
  so.rate_multiples.clear();
  so.progress = [&](const std::string& line) {
    std::fprintf(stderr, "study: %s %s\n", part.c_str(), line.c_str());
  };
  auto ran = runSweep(part, model, stream, so, runs, rows);
  if (!ran.ok())
    std::fprintf(stderr, "study: %s: %s\n", part.c_str(), ran.error().message.c_str());
}

}  // namespace

void runScenes(const Options& options, std::vector<Row>& rows) {
  for (const char* name : {"peg_in_hole", "gears", "dynamic", "stress"}) {
    const std::string part = std::string("scene/") + name;
    const std::string glb = std::string(HAPTICD_SOURCE_DIR) + "/scenes/" + name + ".glb";
    const std::string csv = std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv";
    scene::LoadReport report = scene::loadSceneFile(glb);
    if (!report.ok()) {
      std::fprintf(stderr, "study: %s: %s\n", glb.c_str(), report.message().c_str());
      continue;
    }
    auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
    auto text = proto::readPoseStreamFile(csv);
    if (!text.ok()) {
      std::fprintf(stderr, "study: cannot read %s: %s\n", csv.c_str(),
                   text.error().message.c_str());
      continue;
    }
    auto parsed =
        proto::parsePoseStream(text.value(), csv, 1e-3, proto::PoseStreamDialect::kStrict);
    if (!parsed.ok()) {
      std::fprintf(stderr, "study: %s\n", parsed.error().message.c_str());
      continue;
    }
    const auto& stream = parsed.value();
    SceneStudyOptions so;
    so.max_seconds = options.quick ? 3.0 : 0.0;  // quick: the first 3 s of each stream
    so.rate_multiples = {2, 4};                  // 2 and 4 kHz beside the truth's 1 kHz
    so.loop_methods = loopMethods();             // the depth along the motion, the peers
    so.progress = [&](const std::string& line) {
      std::fprintf(stderr, "study: %s %s\n", part.c_str(), line.c_str());
    };
    std::vector<TruthTick> truth;
    auto ran = runSceneStudy(part, glb, model, stream, so, rows, &truth);
    if (!ran.ok()) {
      std::fprintf(stderr, "study: %s: %s\n", part.c_str(), ran.error().message.c_str());
      continue;
    }
    if (std::string(name) == "dynamic")
      sweep("dynamics/dynamic", model, stream, so, iterationRuns(options.quick), rows);
    // stress: force shading over its tessellated spheres, capsules and cylinders
    if (std::string(name) == "peg_in_hole" || std::string(name) == "gears" ||
        std::string(name) == "stress")
      sweep(std::string("shaping/") + name, model, stream, so, shapingRuns(options.quick), rows);

    // voxel sampling at the truth's proxy poses
    const std::int32_t held = model->probe_body;
    if (held < 0) {
      std::fprintf(stderr, "study: %s: no probe body: voxel sampling left out\n", part.c_str());
      continue;
    }
    std::vector<voxel::PlacedShape> statics, shell_shapes;
    for (const auto& body : model->bodies) {
      if (body.motion != scene::Motion::kStatic)
        continue;
      for (const auto& p : body.primitives) {
        statics.push_back({p.shape.get(), (body.X_WB.toTransform() * p.X_BP.toTransform())});
      }
    }
    const scene::Body& hb = model->bodies[static_cast<std::size_t>(held)];
    for (const auto& p : hb.primitives)
      shell_shapes.push_back({p.shape.get(), p.X_BP.toTransform()});
    if (statics.empty() || shell_shapes.empty())
      continue;
    double size = 0.0;
    for (const auto& s : shell_shapes)
      size = std::max(size, s.shape->radius());
    for (const double fraction : {0.1, 0.05, 0.025}) {
      const double h = fraction * size;
      auto map = voxel::VoxelMap::build(statics, h);
      auto shell = voxel::makePointShell(shell_shapes, h);
      if (!map.ok() || !shell.ok()) {
        std::fprintf(stderr, "study: %s: voxel h=%g: %s\n", part.c_str(), h,
                     (!map.ok() ? map.error() : shell.error()).message.c_str());
        continue;
      }
      const auto com = [&](const Pose& X) { return X.toTransform().apply(hb.com_B); };
      double num = 0.0, den = 0.0;
      for (std::size_t k = 0; k < truth.size(); k += 5) {  // fitted on every fifth tick
        const auto u = voxel::force(map.value(), shell.value(), truth[k].proxy.toTransform(),
                                    com(truth[k].proxy), 1.0);
        num += glm::dot(u.force_W, truth[k].contact_force);
        den += glm::dot(u.force_W, u.force_W);
      }
      const double kp = den > 0.0 ? num / den : 0.0;
      char setting[96];
      std::snprintf(setting, sizeof setting, "h=%.3gmm (open loop)", h * 1e3);
      Row row{part, "voxel-McNeely", setting, {}, {}, {}, 0, 0, 0, 0, {}, {}};
      const double overhead = threadClockOverheadNs();
      for (std::size_t k = 0; k < truth.size(); ++k) {
        if (k % 5 == 0)
          continue;  // scored on the other ticks
        const TruthTick& t = truth[k];
        const double t0 = threadNowNs();
        const auto f =
            voxel::force(map.value(), shell.value(), t.proxy.toTransform(), com(t.proxy), kp);
        const double ns = threadNowNs() - t0 - overhead;
        row.add(glm::length(f.force_W - t.contact_force),
                glm::length(f.torque_W - t.contact_torque), ns,
                glm::dot(t.contact_force, t.contact_force) > 0.0, f.points_in_contact > 0);
      }
      rows.push_back(std::move(row));
    }
  }
  // a stack of boxes pushed at the top: the iterations where they hold a pile up
  SceneStudyOptions so;
  so.max_seconds = options.quick ? 3.0 : 0.0;
  sweep("dynamics/stack", stackScene(), stackStream(), so, iterationRuns(options.quick), rows);
}

}  // namespace hapticd::study
