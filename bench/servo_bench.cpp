// Servo loop on the real clock (CLOCK_MONOTONIC, clock_nanosleep TIMER_ABSTIME): wake-up lateness
// and compute time histograms at 1 kHz (and 4 kHz), with and without SCHED_FIFO.
//   ServoLoop/RealClock/<rate>Hz/<SCHED_OTHER|SCHED_FIFO>
// Each run lasts HAPTICD_SERVO_BENCH_S seconds (default 10). Counters, in microseconds:
// late_p50, late_p99, late_p999, late_max, compute_p50, compute_p99, compute_max; overruns and
// skipped periods. The full histograms go to stderr. The tick computes a penalty wall (a fixed,
// cheap workload: this measures the loop and the machine, not the collision code; Tick/<scene>
// measures that). Figures for this VM are in bench/README.md and docs/daemon.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "daemon/clock.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"

namespace {

using namespace hapticd;

class WallSimulation final : public sim::Simulation {
 public:
  sim::TickOutput step(const sim::TickInput& in) override {
    sim::TickOutput out;
    out.X_W_proxy = in.X_W_device;
    const double depth = -in.X_W_device.translation.y;
    if (depth > 0.0)
      out.force_W_n = geom::Vec3(0.0, 600.0 * depth, 0.0);
    return out;
  }
  std::span<const sim::BodyPose> bodyPoses() const override { return {}; }
  void restartRamp() override {}
  const scene::SceneModel& scene() const override { return scene_; }
  void prepareThread() override {}

 private:
  scene::SceneModel scene_;
};

class CircleDevice final : public device::Device {
 public:
  CircleDevice() { info_.name = "bench"; }
  const device::DeviceInfo& info() const override { return info_; }
  device::DeviceStatus read(double t, device::DeviceSample& out) noexcept override {
    out.X_WD.translation = geom::Vec3(0.01 * std::cos(t), 0.005 * std::sin(3.0 * t), 0.0);
    return device::DeviceStatus::kOk;
  }
  device::DeviceStatus write(const geom::Vec3&, const geom::Vec3&) noexcept override {
    return device::DeviceStatus::kOk;
  }

 private:
  device::DeviceInfo info_;
};

double benchSeconds() {
  if (const char* s = std::getenv("HAPTICD_SERVO_BENCH_S"))
    return std::atof(s) > 0 ? std::atof(s) : 10.0;
  return 10.0;
}

void servoLoopRealClock(benchmark::State& state, double rate_hz, bool fifo) {
  for (auto _ : state) {
    daemon::MonotonicClock clock;
    CircleDevice device;
    daemon::ServoOptions options;
    options.rate_hz = rate_hz;
    options.max_ticks = static_cast<std::uint64_t>(benchSeconds() * rate_hz);
    options.miss_fault_count = 1u << 30;  // measure, never fault
    auto scene = std::make_unique<daemon::ServoScene>();
    scene->sim = std::make_unique<WallSimulation>();
    daemon::ServoLoop loop(options, clock, device, std::move(scene));
    std::string sched;
    bool granted = false;
    daemon::Thread servo;
    (void)servo.start("servo-bench", 1 << 20, [&] {
      daemon::RealtimeOptions rt;
      rt.policy = fifo ? daemon::RealtimePolicy::kPrefer : daemon::RealtimePolicy::kOff;
      auto r = daemon::setupServoThreadRealtime(rt);
      granted = r && r.value().fifo;
      sched = daemon::describeThreadScheduling();
      loop.run();
    });
    servo.join();
    if (fifo && !granted) {
      state.SkipWithError("SCHED_FIFO refused on this machine");
      return;
    }
    const auto& late = loop.lateness();
    const auto& cpu = loop.compute();
    auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1e3; };
    state.counters["late_p50_us"] = us(late.quantileNs(0.5));
    state.counters["late_p99_us"] = us(late.quantileNs(0.99));
    state.counters["late_p999_us"] = us(late.quantileNs(0.999));
    state.counters["late_max_us"] = us(late.maxNs());
    state.counters["compute_p50_us"] = us(cpu.quantileNs(0.5));
    state.counters["compute_p99_us"] = us(cpu.quantileNs(0.99));
    state.counters["compute_max_us"] = us(cpu.maxNs());
    const auto st = loop.state();
    state.counters["ticks"] = static_cast<double>(st.tick);
    state.counters["overruns"] = static_cast<double>(st.overruns);
    state.counters["skipped"] = static_cast<double>(st.skipped_periods);
    std::fprintf(stderr, "\n== %g Hz, %s: wake-up lateness (bucket upper edge us, count)\n%s",
                 rate_hz, sched.c_str(), late.table().c_str());
    std::fprintf(stderr, "== %g Hz, %s: compute time (bucket upper edge us, count)\n%s", rate_hz,
                 sched.c_str(), cpu.table().c_str());
    std::fprintf(stderr, "== lateness %s\n== compute  %s\n", late.summary().c_str(),
                 cpu.summary().c_str());
  }
}

}  // namespace

BENCHMARK_CAPTURE(servoLoopRealClock, 1000Hz / SCHED_OTHER, 1000.0, false)
    ->Name("ServoLoop/RealClock/1000Hz/SCHED_OTHER")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(servoLoopRealClock, 1000Hz / SCHED_FIFO, 1000.0, true)
    ->Name("ServoLoop/RealClock/1000Hz/SCHED_FIFO")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(servoLoopRealClock, 4000Hz / SCHED_OTHER, 4000.0, false)
    ->Name("ServoLoop/RealClock/4000Hz/SCHED_OTHER")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(servoLoopRealClock, 4000Hz / SCHED_FIFO, 4000.0, true)
    ->Name("ServoLoop/RealClock/4000Hz/SCHED_FIFO")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
