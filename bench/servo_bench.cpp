// Servo loop on the real clock (CLOCK_MONOTONIC, clock_nanosleep TIMER_ABSTIME): wake-up lateness
// and compute time histograms at 1 kHz (and 4 kHz), with and without SCHED_FIFO.
//   ServoLoop/RealClock/<rate>Hz/<SCHED_OTHER|SCHED_FIFO>
// Each run lasts HAPTICD_SERVO_BENCH_S seconds (default 10). Counters, in microseconds:
// late_p50, late_p99, late_p999, late_max, compute_p50, compute_p99, compute_max; overruns and
// skipped periods. The full histograms go to stderr. The tick computes a penalty wall (a fixed,
// cheap workload: this measures the loop and the machine, not the collision code; Tick/<scene>
// measures that). Figures for this VM are in bench/README.md and docs/daemon.md.
//
// Round trip pose command -> state through the real ServoLoop at 1 kHz on the real clock:
//   Daemon/RoundTrip/Shm  a proto::ShmClient pushes a pose command into the segment; the servo
//                         thread drains it into the command gate and publishes a ShmState after
//                         its tick; the client spins on the segment until the state echoes the
//                         command's sequence.
//   Daemon/RoundTrip/Udp  a proto::Client sends a PoseCommand to a proto::Server on loopback (its
//                         own thread, wired as the daemon wires it: on_command -> the loop's
//                         command ring, fill_state <- the loop's seqlock), subscribed at 1 kHz,
//                         until a State echoes the sequence.
// Commands are sent at pseudo-random phases of the tick (a 0..1 ms pause between samples), so the
// figures include the wait for the next tick as a client sees it. HAPTICD_ROUNDTRIP_N samples
// (default 3000). Counters in microseconds: rtt_p50_us, rtt_p99_us, rtt_max_us.
//
// The per-tick cost of the state lists and the shm publish (virtual clock, back-to-back ticks,
// wall time per tick over 200 000 ticks):
//   Daemon/Tick/Virtual/Bare          no bodies, no contacts, no segment
//   Daemon/Tick/Virtual/Lists64x32    64 body poses and 32 contacts published per tick
//   Daemon/Tick/Virtual/Lists64x32Shm the same and a ShmState (16 bodies) published per tick
//   Daemon/Tick/Virtual/Lists4x2[Shm] 4 bodies and 2 contacts (a small scene), without / with shm
// (the fake simulation writes the poses and contacts it reports each step: a few ns per entry of
// the difference is its own work, not the publishing)
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "daemon/clock.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "protocol/client.h"
#include "protocol/server.h"
#include "protocol/shm.h"

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

constexpr std::size_t kListBodiesForBench = daemon::kListBodies;
constexpr std::size_t kListContactsForBench = daemon::kListContacts;

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

// The penalty wall with `bodies` non-static body poses and `contacts` contact points to publish.
class ListSimulation final : public sim::Simulation {
 public:
  ListSimulation(std::size_t bodies, std::size_t contacts) : poses_(bodies), points_(contacts) {
    for (std::size_t i = 0; i < bodies; ++i)
      poses_[i].body = static_cast<std::uint32_t>(i);
  }
  sim::TickOutput step(const sim::TickInput& in) override {
    sim::TickOutput out;
    out.X_W_proxy = in.X_W_device;
    for (auto& p : poses_)
      p.X_WB.translation = in.X_W_device.translation;
    for (auto& c : points_)
      c.p_W = in.X_W_device.translation;
    out.contacts = static_cast<std::uint32_t>(points_.size());
    return out;
  }
  std::span<const sim::BodyPose> bodyPoses() const override { return poses_; }
  std::span<const sim::ContactPoint> contactPoints() const override { return points_; }
  void restartRamp() override {}
  const scene::SceneModel& scene() const override { return scene_; }
  void prepareThread() override {}

 private:
  std::vector<sim::BodyPose> poses_;
  std::vector<sim::ContactPoint> points_;
  scene::SceneModel scene_;
};

std::size_t roundTripSamples() {
  if (const char* s = std::getenv("HAPTICD_ROUNDTRIP_N"))
    return std::atoi(s) > 0 ? static_cast<std::size_t>(std::atoi(s)) : 3000;
  return 3000;
}

std::unique_ptr<daemon::ServoScene> listScene(std::size_t bodies, std::size_t contacts) {
  auto scene = std::make_unique<daemon::ServoScene>();
  scene->sim = std::make_unique<ListSimulation>(bodies, contacts);
  scene->generation = 1;
  return scene;
}

void reportRoundTrip(benchmark::State& state, std::vector<double>& us, std::size_t wanted) {
  if (us.empty()) {
    state.SkipWithError("no round trip completed");
    return;
  }
  std::sort(us.begin(), us.end());
  auto q = [&](double f) {
    return us[static_cast<std::size_t>(f * static_cast<double>(us.size() - 1))];
  };
  state.counters["rtt_p50_us"] = q(0.5);
  state.counters["rtt_p99_us"] = q(0.99);
  state.counters["rtt_max_us"] = us.back();
  state.counters["samples"] = static_cast<double>(us.size());
  state.counters["lost"] = static_cast<double>(wanted - us.size());
}

// a pause of 0..1 ms (a pseudo-random phase of the 1 kHz tick)
void randomPhase(std::uint64_t& rng) {
  rng = rng * 6364136223846793005ull + 1442695040888963407ull;
  std::this_thread::sleep_for(std::chrono::microseconds((rng >> 33) % 1000));
}

void roundTripShm(benchmark::State& state) {
  for (auto _ : state) {
    const std::string name = "/hapticd-bench-" + std::to_string(getpid());
    auto server = proto::ShmServer::create(name);
    if (!server) {
      state.SkipWithError(server.error().message.c_str());
      return;
    }
    daemon::MonotonicClock clock;
    CircleDevice device;
    daemon::ServoOptions options;
    options.miss_fault_count = 1u << 30;
    daemon::ServoLoop loop(options, clock, device, listScene(4, 4));
    loop.attachShm(&server.value());
    daemon::Thread servo;
    (void)servo.start("servo-bench", 1 << 20, [&] {
      loop.prepareServoThread();
      loop.run();
    });
    auto client = proto::ShmClient::attach(name);
    if (!client) {
      loop.requestStop();
      servo.join();
      state.SkipWithError(client.error().message.c_str());
      return;
    }
    proto::ShmClient& c = client.value();
    c.beat(proto::monotonicNs());
    (void)c.pushArm(proto::monotonicNs());
    const std::size_t n = roundTripSamples();
    std::vector<double> us;
    us.reserve(n);
    std::uint64_t rng = 1;
    proto::PoseCommand cmd;
    proto::ShmState st{};
    for (std::size_t i = 0; i < n; ++i) {
      randomPhase(rng);
      const std::uint64_t t0 = proto::monotonicNs();
      c.beat(t0);
      std::uint64_t seq = 0;
      cmd.X_WT.p[1] = 0.001 * static_cast<double>(i % 10);
      if (!c.pushPose(cmd, t0, &seq))
        continue;
      while (proto::monotonicNs() - t0 < 100'000'000) {  // 100 ms: lost
        if (c.readState(st) && st.last_command_sequence >= seq) {
          us.push_back(static_cast<double>(proto::monotonicNs() - t0) / 1e3);
          break;
        }
      }
    }
    loop.requestStop();
    servo.join();
    reportRoundTrip(state, us, n);
  }
}

void roundTripUdp(benchmark::State& state) {
  for (auto _ : state) {
    daemon::MonotonicClock clock;
    CircleDevice device;
    daemon::ServoOptions options;
    options.miss_fault_count = 1u << 30;
    daemon::ServoLoop loop(options, clock, device, listScene(4, 4));
    proto::ServerConfig cfg;
    cfg.bind_address = "127.0.0.1:0";
    proto::ServerHandlers h;
    h.on_command = [&](const proto::CommandEvent& e) {
      daemon::ServoCommand c;
      c.gated = true;
      c.session_id = e.session_id;
      c.sequence = e.sequence;
      c.kind = e.kind == proto::CommandEvent::Kind::kArm      ? daemon::CommandKind::kArm
               : e.kind == proto::CommandEvent::Kind::kDisarm ? daemon::CommandKind::kDisarm
                                                              : daemon::CommandKind::kPose;
      c.pose.X_W_target = geom::Pose::fromXyzw(
          geom::Vec3(e.pose.X_WT.p[0], e.pose.X_WT.p[1], e.pose.X_WT.p[2]), e.pose.X_WT.q[0],
          e.pose.X_WT.q[1], e.pose.X_WT.q[2], e.pose.X_WT.q[3]);
      return loop.sendCommand(c);
    };
    h.fill_state = [&](proto::State& out) {
      const daemon::ServoState s = loop.state();
      out.tick = s.tick;
      out.last_command_sequence = s.last_command_sequence;
      out.X_WD.p = {s.X_W_device.translation.x, s.X_W_device.translation.y,
                    s.X_W_device.translation.z};
      out.contact_count = s.contacts;
      return s.tick > 0;
    };
    auto server = proto::Server::create(cfg, h);
    if (!server) {
      state.SkipWithError(server.error().message.c_str());
      return;
    }
    std::atomic<bool> stop{false};
    std::thread net([&] { server.value()->run(stop); });
    daemon::Thread servo;
    (void)servo.start("servo-bench", 1 << 20, [&] {
      loop.prepareServoThread();
      loop.run();
    });
    proto::ClientConfig cc;
    cc.server = server.value()->localAddress().toString();
    auto client = proto::Client::connect(cc);
    std::vector<double> us;
    const std::size_t n = roundTripSamples();
    if (client && client.value()->arm() && client.value()->subscribe(1000)) {
      proto::Client& c = *client.value();
      us.reserve(n);
      std::uint64_t rng = 1;
      proto::PoseCommand cmd;
      for (std::size_t i = 0; i < n; ++i) {
        randomPhase(rng);
        while (c.receiveState(0)) {
        }
        const std::uint64_t t0 = proto::monotonicNs();
        cmd.X_WT.p[1] = 0.001 * static_cast<double>(i % 10);
        auto seq = c.sendPose(cmd);
        if (!seq)
          continue;
        while (proto::monotonicNs() - t0 < 100'000'000) {
          auto s = c.receiveState(1);
          if (s && s->last_command_sequence >= seq.value()) {
            us.push_back(static_cast<double>(proto::monotonicNs() - t0) / 1e3);
            break;
          }
        }
      }
    }
    loop.requestStop();
    servo.join();
    stop = true;
    net.join();
    if (!client) {
      state.SkipWithError(client.error().message.c_str());
      return;
    }
    reportRoundTrip(state, us, n);
  }
}

void tickVirtual(benchmark::State& state, std::size_t bodies, std::size_t contacts, bool shm) {
  constexpr std::uint64_t kTicks = 200'000;
  for (auto _ : state) {
    std::optional<proto::ShmServer> server;
    if (shm) {
      auto created = proto::ShmServer::create("/hapticd-bench-tick-" + std::to_string(getpid()));
      if (!created) {
        state.SkipWithError(created.error().message.c_str());
        return;
      }
      server.emplace(std::move(created.value()));
    }
    daemon::VirtualClock clock;
    CircleDevice device;
    daemon::ServoOptions options;
    options.max_ticks = kTicks;
    daemon::ServoLoop loop(options, clock, device, listScene(bodies, contacts));
    if (server)
      loop.attachShm(&*server);
    loop.prepareServoThread();
    const auto t0 = std::chrono::steady_clock::now();
    loop.run();
    const double ns =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    state.counters["ns_per_tick"] = ns / static_cast<double>(kTicks);
    state.counters["compute_p50_us"] = static_cast<double>(loop.compute().quantileNs(0.5)) / 1e3;
    state.counters["compute_p99_us"] = static_cast<double>(loop.compute().quantileNs(0.99)) / 1e3;
  }
}

void registerAll() {
  benchmark::RegisterBenchmark("Daemon/RoundTrip/Shm", roundTripShm)
      ->Iterations(1)
      ->Unit(benchmark::kSecond);
  benchmark::RegisterBenchmark("Daemon/RoundTrip/Udp", roundTripUdp)
      ->Iterations(1)
      ->Unit(benchmark::kSecond);
  struct Lists {
    const char* name;
    std::size_t bodies, contacts;
    bool shm;
  };
  for (const Lists& l :
       {Lists{"Bare", 0, 0, false},
        Lists{"Lists64x32", kListBodiesForBench, kListContactsForBench, false},
        Lists{"Lists4x2", 4, 2, false}, Lists{"Lists4x2Shm", 4, 2, true},
        Lists{"Lists64x32Shm", kListBodiesForBench, kListContactsForBench, true}}) {
    benchmark::RegisterBenchmark(("Daemon/Tick/Virtual/" + std::string(l.name)).c_str(),
                                 tickVirtual, l.bodies, l.contacts, l.shm)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  }
  for (const int rate_hz : {1000, 4000}) {
    for (const bool fifo : {false, true}) {
      const std::string name = "ServoLoop/RealClock/" + std::to_string(rate_hz) + "Hz/" +
                               (fifo ? "SCHED_FIFO" : "SCHED_OTHER");
      benchmark::RegisterBenchmark(name.c_str(), servoLoopRealClock, static_cast<double>(rate_hz),
                                   fifo)
          ->Iterations(1)
          ->Unit(benchmark::kSecond);
    }
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
