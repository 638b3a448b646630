// A scene swap's first tick beside an ordinary tick (issue 18 point 5): a field of dynamic 20 mm
// boxes resting on a floor (scenes::makeBoxField; the probe sphere held still 15 cm above them)
// is built and, as the daemon's builder does, prewarmed on another thread
// (sim::Simulation::prewarm); then this thread steps it as the servo thread would after the
// swap. Per iteration: the swap tick (the first step()) and the 50 ticks after it.
//   SceneSwap/Prewarmed/<boxes>  as the daemon swaps now
//   SceneSwap/Cold/<boxes>       without the prewarm (as before issue 18: the dynamics solve every
//                                tick until their 0.5 s sleep time has passed)
// The time reported is the swap tick's. Counters (microseconds): swap_tick_us (mean),
// ordinary_tick_us (the median of the 50 ticks after it, over all iterations), prewarm_ms (the
// builder's extra work), cold_queries / position_rebuilds / dynamics_solves on this thread after
// the swap (per iteration).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "scenes/demo_scenes.h"

namespace {

using namespace hapticd;
using Clock = std::chrono::steady_clock;

constexpr int kTicksAfter = 50;

double microseconds(Clock::duration d) {
  return std::chrono::duration<double, std::micro>(d).count();
}

void sceneSwap(benchmark::State& state, bool prewarm) {
  const int boxes = static_cast<int>(state.range(0));
  const auto bytes = scenes::makeBoxField(boxes);
  auto report = scene::loadScene(bytes, "box_field");
  if (!report.ok()) {
    state.SkipWithError(report.message().c_str());
    return;
  }
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
  sim::TickInput in;
  in.X_W_device.translation = geom::Vec3(0.0, 0.15, 0.0);
  double swap_sum = 0.0, prewarm_sum = 0.0;
  std::vector<double> ordinary;
  std::uint64_t cold = 0, rebuilds = 0, solves = 0, k = 0;
  for (auto _ : state) {
    // the builder's part, on another thread
    std::unique_ptr<sim::Simulation> sim;
    double prewarm_ms = 0.0;
    std::thread builder([&] {
      auto created = sim::Simulation::create(model, sim::SimOptions{});
      if (!created.ok())
        return;
      sim = std::move(created.value());
      const auto t0 = Clock::now();
      if (prewarm)
        (void)sim->prewarm(in.X_W_device);
      prewarm_ms = microseconds(Clock::now() - t0) / 1000.0;
    });
    builder.join();
    if (!sim) {
      state.SkipWithError("the simulation was refused");
      return;
    }
    const sim::ColdWork before = sim->coldWork();
    const std::uint64_t solves_before = sim->dynamicsStatus().ticks;
    // the servo thread's part: the swap tick, then ordinary ticks
    const auto t0 = Clock::now();
    in.t_s = 0.0;
    benchmark::DoNotOptimize(sim->step(in));
    const double swap_us = microseconds(Clock::now() - t0);
    state.SetIterationTime(swap_us * 1e-6);
    for (int i = 1; i <= kTicksAfter; ++i) {
      in.t_s = 0.001 * i;
      const auto a = Clock::now();
      benchmark::DoNotOptimize(sim->step(in));
      ordinary.push_back(microseconds(Clock::now() - a));
    }
    const sim::ColdWork after = sim->coldWork();
    cold += after.cold_queries - before.cold_queries;
    rebuilds += after.position_rebuilds - before.position_rebuilds;
    solves += sim->dynamicsStatus().ticks - solves_before;
    swap_sum += swap_us;
    prewarm_sum += prewarm_ms;
    ++k;
    sim.reset();  // not timed (manual time)
  }
  if (k == 0)
    return;
  std::nth_element(ordinary.begin(), ordinary.begin() + static_cast<long>(ordinary.size() / 2),
                   ordinary.end());
  const auto n = static_cast<double>(k);
  state.counters["swap_tick_us"] = swap_sum / n;
  state.counters["ordinary_tick_us"] = ordinary[ordinary.size() / 2];
  state.counters["prewarm_ms"] = prewarm_sum / n;
  state.counters["cold_queries"] = static_cast<double>(cold) / n;
  state.counters["position_rebuilds"] = static_cast<double>(rebuilds) / n;
  state.counters["dynamics_solves"] = static_cast<double>(solves) / n;
}

void prewarmed(benchmark::State& state) {
  sceneSwap(state, true);
}
void cold(benchmark::State& state) {
  sceneSwap(state, false);
}

// 1 999 boxes and the floor: the loader's default max_bodies (2 000)
BENCHMARK(prewarmed)
    ->Name("SceneSwap/Prewarmed")
    ->Arg(10)
    ->Arg(200)
    ->Arg(1999)
    ->UseManualTime()
    ->Iterations(8)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(cold)
    ->Name("SceneSwap/Cold")
    ->Arg(10)
    ->Arg(200)
    ->Arg(1999)
    ->UseManualTime()
    ->Iterations(8)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
