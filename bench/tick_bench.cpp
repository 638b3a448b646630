// hapticbench, the whole servo tick (core/sim/simulation.h): Tick/<scene> for every demo scene
// (scenes/<name>.glb through the loader) driven by its pose stream (tests/streams/<name>.csv,
// interpolated at 1 kHz, played forwards then backwards so that the motion never jumps) over
// 100 000 ticks (Tick/<scene>/4kHz: the same 100 s of the stream at 4 kHz, tick_s 0.25 ms, the
// stream sampled every 0.25 ms: 400 000 ticks), and Tick/code_peg_in_hole, a peg in a hole with
// 0.1 mm clearance built in code, and Tick/stack100: 100 boxes in 25 stacks of four under
// gravity, the dynamics' sleep off (every tick solved), Tick/stack100_sleeping the same with the
// default sleep (their /own variants: each tick's least time over five runs, as the demos').
// dynamics_ticks counts the ticks the dynamics did work (0 for a scene without
// dynamic bodies).
// Each tick is timed on its own; the counters are the percentiles of compute time per tick in
// microseconds (the paper's Table 1: average 179 us, worst 343 us on 2000 hardware).
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/dynamics/dynamics.h"
#include "core/scene/loader.h"
#include "core/sim/output_shaping.h"
#include "core/sim/simulation.h"
#include "protocol/pose_stream.h"

namespace hapticd::bench {
namespace {

using geom::Pose;
using geom::Quat;
using geom::Vec3;

constexpr std::size_t kTicks = 100000;

// a pose-stream row (protocol/pose_stream.h); the code-built scenes below write theirs by hand
using Key = proto::PoseStreamRow;

std::vector<Key> readStream(const std::string& file) {
  auto text = proto::readPoseStreamFile(file);
  if (!text)
    return {};
  auto rows = proto::parsePoseStream(text.value(), file, 1e-3, proto::PoseStreamDialect::kStrict);
  return rows ? std::move(rows).value() : std::vector<Key>{};
}

// The pose at time t of a stream played forwards then backwards, again and again (the stream's
// own interpolation, proto::samplePoseStream).
sim::TickInput inputAt(const std::vector<Key>& keys, double t) {
  const double T = keys.back().t_s;
  double u = std::fmod(t, 2.0 * T);
  if (u > T)
    u = 2.0 * T - u;
  std::size_t cursor = 0;
  const Key k = proto::samplePoseStream(keys, u, cursor);
  sim::TickInput in;
  in.t_s = t;
  in.X_W_device = k.X_WD;
  in.buttons = k.buttons;
  return in;
}

// Per-tick times (us) as counters <prefix>mean_us, p50_us, p99_us, p999_us, max_us.
void reportTimes(benchmark::State& state, const std::vector<double>& v, const std::string& prefix) {
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  auto pct = [&](double p) {
    return sorted[std::min(sorted.size() - 1,
                           static_cast<std::size_t>(p * static_cast<double>(sorted.size())))];
  };
  double mean = 0.0;
  for (double x : v)
    mean += x;
  mean /= static_cast<double>(v.size());
  state.counters[prefix + "mean_us"] = mean;
  state.counters[prefix + "p50_us"] = pct(0.50);
  state.counters[prefix + "p99_us"] = pct(0.99);
  state.counters[prefix + "p999_us"] = pct(0.999);
  state.counters[prefix + "max_us"] = sorted.back();
}

void runTicks(benchmark::State& state,
              std::shared_ptr<const scene::SceneModel> model,
              const std::vector<Key>& keys,
              double dynamics_sleep_time_s = sim::SimOptions{}.dynamics_sleep_time_s,
              std::size_t ticks = kTicks,
              double rate_hz = 1000.0,
              std::size_t repeats = 1) {
  sim::SimOptions options;
  options.dynamics_sleep_time_s = dynamics_sleep_time_s;
  options.response.tick_s = 1.0 / rate_hz;  // as hapticd --rate sets it ([response] tick_s 0)
  // the tick as the daemon runs it: the simulation, then the one output stage
  auto makeSim = [&]() -> std::unique_ptr<sim::Simulation> {
    auto created = sim::Simulation::create(model, options);
    if (!created.ok()) {
      state.SkipWithError(created.error().message.c_str());
      return nullptr;
    }
    auto made = sim::withOutputStage(std::move(created).value(), options.response);
    made->prepareThread();  // as the daemon does on its servo thread before the first tick
    return made;
  };
  auto sim = makeSim();
  if (sim == nullptr)
    return;
  std::vector<sim::TickInput> inputs(ticks);
  for (std::size_t k = 0; k < ticks; ++k)
    inputs[k] = inputAt(keys, static_cast<double>(k) * options.response.tick_s);
  std::vector<double> us(ticks), cpu_us(ticks);
  auto threadCpuNs = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
  };
  double checksum = 0.0;
  std::uint64_t contacts = 0, pairs = 0, dynamics_ticks = 0;
  std::uint64_t depth_certified = 0, depth_fallbacks = 0, depth_cold = 0, depth_untracked = 0;
  std::vector<double> asleep_cpu_us;
  asleep_cpu_us.reserve(ticks);
  std::vector<std::size_t> asleep_ticks;  // the first run's ticks once asleep (for the own work)
  asleep_ticks.reserve(ticks);
  for (auto _ : state) {
    for (std::size_t k = 0; k < ticks; ++k) {
      const double c0 = threadCpuNs();
      const auto t0 = std::chrono::steady_clock::now();
      const sim::TickOutput out = sim->step(inputs[k]);
      const auto t1 = std::chrono::steady_clock::now();
      const double c1 = threadCpuNs();
      us[k] = std::chrono::duration<double, std::micro>(t1 - t0).count();
      cpu_us[k] = (c1 - c0) * 1e-3;
      checksum += out.force_W_n.y;
      contacts += out.contacts;
      pairs += out.pairs_tested;
      depth_certified += out.depth_certified;
      depth_fallbacks += out.depth_fallbacks;
      depth_cold += out.depth_cold;
      depth_untracked += out.depth_untracked;
      dynamics_ticks += (out.flags & sim::kTickDynamics) != 0 ? 1u : 0u;
      // once the dynamics have run and then stopped (the scene asleep): those ticks apart
      if ((out.flags & sim::kTickDynamics) == 0 && dynamics_ticks > 0) {
        asleep_cpu_us.push_back(cpu_us[k]);
        asleep_ticks.push_back(k);
      }
    }
  }
  // the first run's forces, kept apart: read after DoNotOptimize, the sum came back as a
  // denormal here (g++ 12.2 -O3), so nothing is compared with it after that
  const double first_check = checksum;
  benchmark::DoNotOptimize(checksum);
  // wall time per tick (steady_clock) and this thread's CPU time per tick (leaves out the time
  // the shared VM took the core away; includes the clock's own cost, about 0.3 us)
  auto report = [&](const std::vector<double>& v, const std::string& prefix) {
    reportTimes(state, v, prefix);
  };
  report(us, "");
  report(cpu_us, "cpu_");
  if (repeats > 1) {
    // the ticks' own work: the same stream again on a fresh simulation, `repeats` runs in all;
    // every run does the same work tick for tick (the simulation is deterministic: checked by
    // the forces and the pairs tested), so a tick's least time over the runs is its own work
    // and what a run's time exceeds it by is the machine's (bench/README.md "Tick/gears'
    // slowest ticks")
    std::vector<double> own = cpu_us;
    double differ = 0.0;
    for (std::size_t r = 1; r < repeats; ++r) {
      auto again = makeSim();
      if (again == nullptr)
        return;
      double check = 0.0;
      std::uint64_t again_pairs = 0;
      for (std::size_t k = 0; k < ticks; ++k) {
        const double c0 = threadCpuNs();
        const sim::TickOutput out = again->step(inputs[k]);
        const double c1 = threadCpuNs();
        own[k] = std::min(own[k], (c1 - c0) * 1e-3);
        check += out.force_W_n.y;
        again_pairs += out.pairs_tested;
      }
      if (check != first_check || again_pairs != pairs)
        differ += 1.0;
    }
    reportTimes(state, own, "own_cpu_");
    // the tick of the most own work (its index in the stream's ticks)
    state.counters["own_cpu_max_tick"] =
        static_cast<double>(std::max_element(own.begin(), own.end()) - own.begin());
    state.counters["own_runs"] = static_cast<double>(repeats);
    state.counters["own_runs_differ"] = differ;  // not 0: the own-work figures mean nothing
    if (!asleep_ticks.empty()) {
      // the own work of the ticks once asleep (the same ticks in every run: checked above)
      std::vector<double> asleep_own;
      asleep_own.reserve(asleep_ticks.size());
      for (const std::size_t k : asleep_ticks)
        asleep_own.push_back(own[k]);
      reportTimes(state, asleep_own, "asleep_own_cpu_");
    }
  }
  if (!asleep_cpu_us.empty())
    report(asleep_cpu_us, "asleep_cpu_");  // thread CPU time of the ticks once asleep
  state.counters["contacts_per_tick"] = static_cast<double>(contacts) / static_cast<double>(ticks);
  state.counters["pairs_per_tick"] = static_cast<double>(pairs) / static_cast<double>(ticks);
  state.counters["dynamics_ticks"] = static_cast<double>(dynamics_ticks);
  // the penetration depths of the run (docs/narrow-phase.md "In the collision world"): per
  // tick, and the share of the tracked ones whose certificate failed
  const double runs = static_cast<double>(ticks) * static_cast<double>(state.iterations());
  state.counters["depth_certified_per_tick"] = static_cast<double>(depth_certified) / runs;
  state.counters["depth_fallbacks_per_tick"] = static_cast<double>(depth_fallbacks) / runs;
  state.counters["depth_cold_per_tick"] = static_cast<double>(depth_cold) / runs;
  state.counters["depth_untracked_per_tick"] = static_cast<double>(depth_untracked) / runs;
  state.counters["depth_fallback_rate"] =
      depth_certified + depth_fallbacks > 0
          ? static_cast<double>(depth_fallbacks) /
                static_cast<double>(depth_certified + depth_fallbacks)
          : 0.0;
}

void tickScene(benchmark::State& state, const char* name, double rate_hz, std::size_t repeats) {
  const std::string dir = HAPTICD_SOURCE_DIR;
  auto report = scene::loadSceneFile(dir + "/scenes/" + name + ".glb");
  if (!report.ok()) {
    state.SkipWithError(("scene: " + report.message()).c_str());
    return;
  }
  const auto keys = readStream(dir + "/tests/streams/" + name + ".csv");
  if (keys.size() < 2) {
    state.SkipWithError("pose stream missing or malformed");
    return;
  }
  // the same 100 s of the stream at every rate: 100 000 ticks at 1 kHz, 400 000 at 4 kHz
  const auto ticks =
      static_cast<std::size_t>(std::llround(static_cast<double>(kTicks) * rate_hz / 1000.0));
  runTicks(state, std::make_shared<const scene::SceneModel>(std::move(*report.scene)), keys,
           sim::SimOptions{}.dynamics_sleep_time_s, ticks, rate_hz, repeats);
}

std::shared_ptr<const geom::Polytope> box(const Vec3& h) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
  return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(p).value());
}

scene::Body staticBox(const Vec3& c, const Vec3& h) {
  scene::Body b;
  b.name = "wall";
  b.X_WB.translation = c;
  scene::Primitive p;
  p.shape = box(h);
  b.primitives.push_back(p);
  return b;
}

// A 20 mm square peg, 60 mm long, and a hole 20.1 mm square, 40 mm deep (0.1 mm clearance).
void tickCodePegInHole(benchmark::State& state) {
  scene::SceneModel s;
  s.name = "code_peg_in_hole";
  const double hh = 0.01005, w = 0.01, d = 0.04, c = hh + w / 2;
  s.bodies.push_back(staticBox(Vec3{0, -0.01, 0}, Vec3{0.1, 0.01, 0.1}));
  s.bodies.push_back(staticBox(Vec3{c, d / 2, 0}, Vec3{w / 2, d / 2, hh + w}));
  s.bodies.push_back(staticBox(Vec3{-c, d / 2, 0}, Vec3{w / 2, d / 2, hh + w}));
  s.bodies.push_back(staticBox(Vec3{0, d / 2, c}, Vec3{hh, d / 2, w / 2}));
  s.bodies.push_back(staticBox(Vec3{0, d / 2, -c}, Vec3{hh, d / 2, w / 2}));
  scene::Body peg = staticBox(Vec3{0, 0.08, 0}, Vec3{0.01, 0.03, 0.01});
  peg.name = "peg";
  peg.motion = scene::Motion::kKinematic;
  peg.probe = true;
  s.bodies.push_back(peg);
  s.probe_body = 5;
  s.plan.static_primitives = 5;
  s.plan.moving_primitives = 1;
  const double wob = 0.5 * std::numbers::pi / 180.0;
  auto at = [](double y, Quat q) { return Pose{Vec3{0, y, 0}, q}; };
  const Quat id{1, 0, 0, 0};
  std::vector<Key> keys{{0.0, at(0.08, id), 0},
                        {1.0, at(0.071, id), 0},
                        {1.5, at(0.064, id), 0},
                        {2.0, at(0.055, glm::angleAxis(wob, Vec3{1, 0, 0})), 0},
                        {2.5, at(0.045, glm::angleAxis(-wob, Vec3{0, 0, 1})), 0},
                        {3.0, at(0.035, id), 0},
                        {3.5, at(0.035, glm::angleAxis(0.035, Vec3{0, 0, 1})), 0},
                        {4.0, at(0.035, id), 0},
                        {5.0, at(0.027, id), 0},
                        {5.5, at(0.027, id), 0},
                        {8.0, at(0.08, id), 0}};
  runTicks(state, std::make_shared<const scene::SceneModel>(std::move(s)), keys);
}

// 100 boxes of 10 cm (density 500) in a 5 x 5 grid of stacks four high on a floor, friction 0.6,
// under gravity; the probe sphere circles 20 cm above the stacks, touching none. state.range(0):
// 1 = the dynamics' sleep off (every tick solved: the cost of a pile that is never at rest),
// 0 = the default sleep (the stacks settle and the scene sleeps: the collision step only).
// repeats: runs of the stream (more than 1: the ticks' own work, runTicks)
void tickStack100(benchmark::State& state, std::size_t repeats) {
  scene::SceneModel s;
  s.name = "stack100";
  s.gravity_W = Vec3{0, -9.81, 0};
  scene::Material m;
  m.static_friction = m.dynamic_friction = 0.6;
  s.materials.push_back(m);
  scene::Body floor = staticBox(Vec3{0, -0.1, 0}, Vec3{1, 0.1, 1});
  floor.primitives[0].material = 0;
  s.bodies.push_back(floor);
  const double h = 0.05;
  const auto cube = box(Vec3{h});
  for (int i = 0; i < 25; ++i) {
    for (int level = 0; level < 4; ++level) {
      scene::Body b;
      b.name = "box";
      b.motion = scene::Motion::kDynamic;
      b.X_WB.translation = Vec3{-0.5 + 0.25 * (i % 5), h + 2 * h * level, -0.5 + 0.25 * (i / 5)};
      b.primitives.push_back(scene::Primitive{cube, Pose{}, scene::ShapeSource::kCode, -1, 0});
      const auto mp = dynamics::computeMassProperties(b.primitives, 500.0);
      b.mass = mp.mass;
      b.inverse_mass = 1.0 / mp.mass;
      b.com_B = mp.com_B;
      b.inertia_B = mp.inertia_B;
      s.bodies.push_back(b);
    }
  }
  s.length_scale = std::sqrt(2.0 * 2.0 * 2 + 0.6 * 0.6);
  s.plan.contact_forces = true;
  s.plan.dynamics = true;
  s.plan.gravity = true;
  s.plan.friction = true;
  s.plan.static_primitives = 1;
  s.plan.moving_primitives = 100;
  std::vector<Key> keys;
  for (int k = 0; k <= 40; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 40.0;
    keys.push_back(
        {0.25 * k, Pose{Vec3{0.3 * std::cos(a), 0.6, 0.3 * std::sin(a)}, Quat{1, 0, 0, 0}}, 0});
  }
  runTicks(state, std::make_shared<const scene::SceneModel>(std::move(s)), keys,
           state.range(0) != 0 ? 0.0 : sim::SimOptions{}.dynamics_sleep_time_s, kTicks, 1000.0,
           repeats);
}

// 2 000 boxes of 2 cm (density 500) on a floor in a 50 x 40 grid 5 cm apart (no two within the box
// margin of each other), friction 0.6, under gravity, the default sleep; the probe sphere circles
// 20 cm above them, touching none. Once the boxes sleep, what they cost a tick is what a resting
// scene costs the servo thread (issue 18, point 5: a scene of 2 000 resting boxes). 20 000 ticks.
void tickBoxes2000(benchmark::State& state) {
  scene::SceneModel s;
  s.name = "boxes2000";
  s.gravity_W = Vec3{0, -9.81, 0};
  scene::Material m;
  m.static_friction = m.dynamic_friction = 0.6;
  s.materials.push_back(m);
  scene::Body floor = staticBox(Vec3{0, -0.1, 0}, Vec3{1.3, 0.1, 1.05});
  floor.primitives[0].material = 0;
  s.bodies.push_back(floor);
  const double h = 0.01;
  const auto cube = box(Vec3{h});
  for (int i = 0; i < 2000; ++i) {
    scene::Body b;
    b.name = "box";
    b.motion = scene::Motion::kDynamic;
    b.X_WB.translation =
        Vec3{-1.225 + 0.05 * (i % 50), h, -0.975 + 0.05 * static_cast<double>(i / 50)};
    b.primitives.push_back(scene::Primitive{cube, Pose{}, scene::ShapeSource::kCode, -1, 0});
    const auto mp = dynamics::computeMassProperties(b.primitives, 500.0);
    b.mass = mp.mass;
    b.inverse_mass = 1.0 / mp.mass;
    b.com_B = mp.com_B;
    b.inertia_B = mp.inertia_B;
    s.bodies.push_back(b);
  }
  s.length_scale = std::sqrt(2.6 * 2.6 + 2.1 * 2.1 + 0.4 * 0.4);
  s.plan.contact_forces = true;
  s.plan.dynamics = true;
  s.plan.gravity = true;
  s.plan.friction = true;
  s.plan.static_primitives = 1;
  s.plan.moving_primitives = 2000;
  std::vector<Key> keys;
  for (int k = 0; k <= 40; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 40.0;
    keys.push_back(
        {0.25 * k, Pose{Vec3{0.3 * std::cos(a), 0.2, 0.3 * std::sin(a)}, Quat{1, 0, 0, 0}}, 0});
  }
  runTicks(state, std::make_shared<const scene::SceneModel>(std::move(s)), keys,
           sim::SimOptions{}.dynamics_sleep_time_s, 20000);
}

// The noise floor of this machine: a probe sphere moving in an empty scene (no pair, no contact):
// whatever its tail shows is the VM, not the work.
void tickEmpty(benchmark::State& state) {
  scene::SceneModel s;
  s.name = "empty";
  std::vector<Key> keys{{0.0, Pose{Vec3{0.0}, Quat{1, 0, 0, 0}}, 0},
                        {5.0, Pose{Vec3{0.1, 0.05, 0.0}, Quat{1, 0, 0, 0}}, 0}};
  runTicks(state, std::make_shared<const scene::SceneModel>(std::move(s)), keys);
}

// The shared VM's own tail for a tick of fixed work: 100 000 "ticks" of the same arithmetic (a
// chain of state.range(0) dependent multiply-adds, no memory traffic, no branch that varies),
// each timed like a scene's tick. Every tick does exactly the same work, so whatever its p99 and
// p99.9 exceed its p50 by is the machine's (interrupts, the hypervisor taking the core), not the
// code's. Arg 11000 is about 20 us a tick on the 2.1 GHz EPYC VM (Tick/gears' p50 there).
void tickFixedWork(benchmark::State& state) {
  const auto n = static_cast<std::int64_t>(state.range(0));
  std::vector<double> cpu_us(kTicks);
  auto threadCpuNs = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
  };
  double x = 1.0;
  for (auto _ : state) {
    for (std::size_t k = 0; k < kTicks; ++k) {
      benchmark::DoNotOptimize(x);
      const double c0 = threadCpuNs();
      for (std::int64_t i = 0; i < n; ++i)
        x = x * 0.999999999 + 1e-9;
      benchmark::DoNotOptimize(x);
      cpu_us[k] = (threadCpuNs() - c0) * 1e-3;
    }
  }
  reportTimes(state, cpu_us, "cpu_");
}

// one iteration each: an iteration runs the whole pose stream and times every tick
void registerAll() {
  const auto once = [](benchmark::internal::Benchmark* b) {
    b->Iterations(1)->Unit(benchmark::kMillisecond);
  };
  once(benchmark::RegisterBenchmark("Tick/empty", tickEmpty));
  once(benchmark::RegisterBenchmark("Tick/fixed_work", tickFixedWork)->Arg(11000));
  for (const char* scene : {"peg_in_hole", "gears", "dynamic", "stress", "decomposed"})
    once(benchmark::RegisterBenchmark(("Tick/" + std::string(scene)).c_str(), tickScene, scene,
                                      1000.0, std::size_t{1}));
  // the ticks' own work (own_cpu_*): each stream run 5 times, each tick's least time over the
  // runs, which leaves out the shared VM's stalls (Tick/fixed_work shows them alone)
  for (const char* scene : {"peg_in_hole", "gears", "dynamic", "stress", "decomposed"})
    once(benchmark::RegisterBenchmark(("Tick/" + std::string(scene) + "/own").c_str(), tickScene,
                                      scene, 1000.0, std::size_t{5}));
  // the same at 4 kHz (hapticd --rate 4000): the stream sampled every 0.25 ms, the response's
  // tick_s 0.25 ms (delta, the coupling's damping, the dynamics' step), 400 000 ticks (the same
  // 100 s of the stream played forwards and backwards); budget 250 us a tick, target p99.9 < 125 us
  for (const char* scene : {"peg_in_hole", "gears", "dynamic", "stress", "decomposed"})
    once(benchmark::RegisterBenchmark(("Tick/" + std::string(scene) + "/4kHz").c_str(), tickScene,
                                      scene, 4000.0, std::size_t{1}));
  once(benchmark::RegisterBenchmark("Tick/stack100", tickStack100, std::size_t{1})->Arg(1));
  once(
      benchmark::RegisterBenchmark("Tick/stack100_sleeping", tickStack100, std::size_t{1})->Arg(0));
  // their own work, as the demos' (asleep_own_cpu_*: the ticks once asleep)
  once(benchmark::RegisterBenchmark("Tick/stack100/own", tickStack100, std::size_t{5})->Arg(1));
  once(benchmark::RegisterBenchmark("Tick/stack100_sleeping/own", tickStack100, std::size_t{5})
           ->Arg(0));
  once(benchmark::RegisterBenchmark("Tick/boxes2000_sleeping", tickBoxes2000));
  once(benchmark::RegisterBenchmark("Tick/code_peg_in_hole", tickCodePegInHole));
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace hapticd::bench
