// hapticbench, dynamics: the cost of one dynamics step per servo tick.
//  Dynamics/stack100: 100 boxes (a 5 x 5 grid of stacks four high) resting on a floor under
//    gravity, after one settling second, sleep off; p50, p99 and p99.9 of Dynamics::step per
//    tick (wall clock and thread CPU time), and the CollisionWorld step before it.
//  Dynamics/small_parts/own:{1,0}: two 5 mm parts of 64 pieces resting on a 40 m floor, with
//    margins of their own (1) or the world's (0); the collision and dynamics steps per tick.
//  Dynamics/empty: a scene without dynamic bodies (a floor and a kinematic body): the stage is
//    inactive and step() returns at once.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <memory>
#include <vector>

#include "core/dynamics/dynamics.h"

namespace hapticd::bench {
namespace {

using dynamics::Dynamics;
using geom::Pose;
using geom::Quat;
using geom::Vec3;

std::shared_ptr<const geom::Polytope> box(const Vec3& h) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
  return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(p).value());
}

scene::Body body(std::shared_ptr<const geom::Polytope> s, const Vec3& at, scene::Motion motion) {
  scene::Body b;
  b.name = "b";
  b.motion = motion;
  b.X_WB = Pose{at, Quat{1, 0, 0, 0}};
  b.primitives.push_back(scene::Primitive{std::move(s), Pose{}, scene::ShapeSource::kCode, -1, 0});
  if (motion == scene::Motion::kDynamic) {
    const auto mp = dynamics::computeMassProperties(b.primitives, 500.0);
    b.mass = mp.mass;
    b.com_B = mp.com_B;
    b.inertia_B = mp.inertia_B;
  }
  return b;
}

// this thread's CPU time (ns): the VM is shared, so the wall clock also counts other programs
double cpuNs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

double quantile(std::vector<double>& v, double q) {
  if (v.empty())
    return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// p50, p99 and p99.9 of the times per tick (ns) as counters: wall clock and this thread's CPU
void putPercentiles(benchmark::State& state, std::vector<double>& wall, std::vector<double>& cpu) {
  state.counters["p50_ns"] = quantile(wall, 0.5);
  state.counters["p99_ns"] = quantile(wall, 0.99);
  state.counters["p99.9_ns"] = quantile(wall, 0.999);
  state.counters["cpu_p50_ns"] = quantile(cpu, 0.5);
  state.counters["cpu_p99_ns"] = quantile(cpu, 0.99);
  state.counters["cpu_p99.9_ns"] = quantile(cpu, 0.999);
}

// a scene under gravity, friction 0.6 everywhere, with a static floor box of these half extents
// whose top is at y = 0
scene::SceneModel floorScene(const Vec3& half) {
  scene::SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  scene::Material m;
  m.static_friction = m.dynamic_friction = 0.6;
  s.materials.push_back(m);
  s.bodies.push_back(body(box(half), Vec3{0, -half.y, 0}, scene::Motion::kStatic));
  return s;
}

void BM_Stack100(benchmark::State& state) {
  scene::SceneModel s = floorScene(Vec3{1, 0.1, 1});
  const double h = 0.05;
  const auto cube = box(Vec3{h});
  for (int i = 0; i < 25; ++i) {
    for (int level = 0; level < 4; ++level) {
      s.bodies.push_back(body(cube,
                              Vec3{-0.5 + 0.25 * (i % 5), h + 2 * h * level, -0.5 + 0.25 * (i / 5)},
                              scene::Motion::kDynamic));
    }
  }
  s.length_scale = std::sqrt(2.0 * 2.0 * 2 + 0.6 * 0.6);
  auto world = dynamics::buildCollisionWorld(s, {}).value();
  dynamics::DynamicsOptions o;
  o.sleep_time_s = 0.0;  // the resting pile is solved on every tick (asleep it costs nothing)
  auto dyn = Dynamics::create(s, *world, o).value();
  for (int k = 0; k < 1000; ++k) {  // settle
    world->step();
    dyn->step(*world, 0.001);
  }
  std::vector<double> dyn_ns, dyn_cpu_ns, world_ns;
  dyn_ns.reserve(1 << 20);
  dyn_cpu_ns.reserve(1 << 20);
  world_ns.reserve(1 << 20);
  std::uint64_t points = 0, iterations = 0, tois = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    world->step();
    const auto t1 = std::chrono::steady_clock::now();
    const double c1 = cpuNs();
    const auto r = dyn->step(*world, 0.001);
    const double c2 = cpuNs();
    const auto t2 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(r);
    points += r.contact_points;
    iterations += r.velocity_iterations;
    tois += r.toi_substeps;
    if (dyn_ns.size() < dyn_ns.capacity()) {
      world_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
      dyn_ns.push_back(std::chrono::duration<double, std::nano>(t2 - t1).count());
      dyn_cpu_ns.push_back(c2 - c1);
    }
  }
  // Dynamics::step per tick: wall clock and this thread's CPU time
  putPercentiles(state, dyn_ns, dyn_cpu_ns);
  // the collision step before it (not the dynamics' work, for scale)
  state.counters["world_p50_ns"] = quantile(world_ns, 0.5);
  const auto per_tick = [&](std::uint64_t n) {
    return static_cast<double>(n) / static_cast<double>(state.iterations());
  };
  state.counters["points"] = per_tick(points);
  // the solver's work per tick: velocity iterations (all solves) and times of impact
  state.counters["iterations"] = per_tick(iterations);
  state.counters["toi_substeps"] = per_tick(tois);
  // the stack must still stand, or the figures mean nothing
  double top = 0.0;
  for (std::uint32_t b = 4; b < dyn->bodyCount(); b += 4)
    top = std::max(top, std::abs(dyn->pose(b).translation.y - 7 * h));
  state.counters["top_drift_mm"] = top * 1e3;
}
BENCHMARK(BM_Stack100)->Name("Dynamics/stack100")->Unit(benchmark::kMicrosecond)->MinTime(3.0);

// Dynamics/small_parts/<own>: two parts of 8 x 8 cube pieces (64 pieces, 5 mm across, 0.6 mm
// thick) resting 1 mm apart on a static floor 40 m wide, sleep off: the collision step and the
// dynamics step per tick. own 1: each part's boxes grow by its own margin (the default); own 0:
// by the world's, 0.5% of the scene's size (0.28 m), as before 2026-12-06, within which every
// piece of one part is near every piece of the other.
void BM_SmallParts(benchmark::State& state) {
  scene::SceneModel s = floorScene(Vec3{20, 0.05, 20});
  const double h = 0.0003125;
  const auto cube = box(Vec3{h, 0.0003, h});
  for (int part = 0; part < 2; ++part) {
    scene::Body b = body(cube, Vec3{0.006 * part, 0.0003, 0}, scene::Motion::kDynamic);
    b.primitives.clear();
    for (int i = 0; i < 8; ++i) {
      for (int k = 0; k < 8; ++k) {
        b.primitives.push_back(
            scene::Primitive{cube, Pose{Vec3{2 * h * i, 0, 2 * h * k}, Quat{1, 0, 0, 0}},
                             scene::ShapeSource::kCode, -1, 0});
      }
    }
    const auto mp = dynamics::computeMassProperties(b.primitives, 500.0);
    b.mass = mp.mass;
    b.com_B = mp.com_B;
    b.inertia_B = mp.inertia_B;
    s.bodies.push_back(std::move(b));
  }
  s.length_scale = std::sqrt(40.0 * 40.0 * 2 + 0.1 * 0.1);
  auto world = dynamics::buildCollisionWorld(s, {}).value();
  dynamics::DynamicsOptions o;
  o.sleep_time_s = 0.0;
  o.body_margins = state.range(0) != 0;
  auto dyn = Dynamics::create(s, *world, o).value();
  for (int k = 0; k < 500; ++k) {  // settle
    world->step();
    dyn->step(*world, 0.001);
  }
  std::vector<double> tick_ns, tick_cpu_ns;
  tick_ns.reserve(1 << 20);
  tick_cpu_ns.reserve(1 << 20);
  std::uint64_t pairs = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpuNs();
    world->step();
    const auto r = dyn->step(*world, 0.001);
    const double c1 = cpuNs();
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(r);
    pairs += world->contacts().size();
    if (tick_ns.size() < tick_ns.capacity()) {
      tick_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
      tick_cpu_ns.push_back(c1 - c0);
    }
  }
  // the collision step and Dynamics::step per tick: wall clock and this thread's CPU time
  putPercentiles(state, tick_ns, tick_cpu_ns);
  state.counters["pairs"] = static_cast<double>(pairs) / static_cast<double>(state.iterations());
  // both parts must rest where they were put, or the figures mean nothing
  double drift = 0.0;
  for (std::uint32_t b = 1; b <= 2; ++b) {
    const Vec3 d = dyn->pose(b).translation - Vec3{0.006 * (b - 1), 0.0003, 0};
    drift = std::max(drift, glm::length(d));
  }
  state.counters["drift_um"] = drift * 1e6;
}
BENCHMARK(BM_SmallParts)
    ->Name("Dynamics/small_parts")
    ->ArgName("own")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(2.0);

void BM_Empty(benchmark::State& state) {
  scene::SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.bodies.push_back(body(box(Vec3{1, 0.1, 1}), Vec3{0, -0.1, 0}, scene::Motion::kStatic));
  s.bodies.push_back(body(box(Vec3{0.05}), Vec3{0, 0.5, 0}, scene::Motion::kKinematic));
  auto world = dynamics::buildCollisionWorld(s, {}).value();
  auto dyn = Dynamics::create(s, *world).value();
  for (auto _ : state) {
    auto r = dyn->step(*world, 0.001);
    benchmark::DoNotOptimize(r);
  }
  state.counters["ticks_with_work"] = static_cast<double>(dyn->counters().ticks);
}
BENCHMARK(BM_Empty)->Name("Dynamics/empty")->Unit(benchmark::kNanosecond);

}  // namespace
}  // namespace hapticd::bench
