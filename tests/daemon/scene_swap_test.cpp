// Scene swaps without a hiccup (issue 18 point 5): a scene of 10, 200 or 2 000 bodies (dynamic
// 20 mm boxes resting on a floor, scenes::makeBoxField) is built and prewarmed off the servo
// thread, as the daemon's builder does (sim::Simulation::prewarm at the device's pose), then
// swapped into a running ServoLoop; the swap tick and the ticks after it must do no cold work,
// judged by counters, never by time:
//  - no pair query started cold, no broad-phase sort, no rebuild of its position tables
//    (sim::ColdWork, the collision world's counters);
//  - no dynamics solve: the scene, found at rest by the prewarm, sleeps from its first tick
//    (DynamicsStatus::ticks does not move, ticks_asleep does);
//  - no allocation on the servo thread (tests/daemon/alloc_counter.cpp).
// The same swap without the prewarm shows the counters moving on the servo thread, so that the
// zeros above are not a counter that never counts.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "scenes/demo_scenes.h"
#include "tests/daemon/alloc_counter.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

constexpr std::uint64_t kSwapAtTick = 20;  // ticks of the old scene before the swap
constexpr std::uint64_t kTicksAfter = 60;  // ticks of the new scene, the swap tick included

// A device held still in free space above the boxes (scene frame = device frame).
class StillDevice final : public device::Device {
 public:
  StillDevice() { info_.name = "still"; }
  const device::DeviceInfo& info() const override { return info_; }
  device::DeviceStatus read(double, device::DeviceSample& out) noexcept override {
    out.X_WD = X_WD;
    return device::DeviceStatus::kOk;
  }
  device::DeviceStatus write(const geom::Vec3&, const geom::Vec3&) noexcept override {
    return device::DeviceStatus::kOk;
  }
  geom::Pose X_WD{geom::Vec3(0.0, 0.15, 0.0), geom::Quat(1.0, 0.0, 0.0, 0.0)};

 private:
  device::DeviceInfo info_;
};

// Virtual time that stops at one deadline until the test lets it go on: the test offers the new
// scene while the loop waits there, so the swap happens at a known tick of a running loop.
class HoldClock final : public Clock {
 public:
  explicit HoldClock(std::int64_t hold_at_ns) : hold_at_ns_(hold_at_ns) {}
  std::int64_t nowNs() noexcept override { return now_ns_; }
  void sleepUntilNs(std::int64_t deadline_ns) noexcept override {
    if (deadline_ns >= hold_at_ns_ && !released_.load()) {
      held_ = true;
      while (!released_.load())
        std::this_thread::yield();
    }
    if (deadline_ns > now_ns_)
      now_ns_ = deadline_ns;
  }
  bool isVirtual() const noexcept override { return true; }
  bool held() const { return held_.load(); }
  void release() { released_ = true; }

 private:
  std::int64_t now_ns_ = 0;
  std::int64_t hold_at_ns_;
  std::atomic<bool> held_{false}, released_{false};
};

struct SwapFigures {
  sim::ColdWork before, after;  // the new scene's counters at the offer, at the end
  sim::DynamicsStatus dyn_before, dyn_after;
  sim::PrewarmReport prewarm;
  std::uint64_t servo_allocations = ~0ull;
  std::uint64_t generation = 0;
  std::uint64_t ticks = 0;
};

std::shared_ptr<const scene::SceneModel> boxField(int boxes) {
  const auto bytes = scenes::makeBoxField(boxes);
  auto report = scene::loadScene(bytes, "box_field_" + std::to_string(boxes));
  EXPECT_TRUE(report.ok()) << report.message();
  if (!report.ok())
    return nullptr;
  return std::make_shared<const scene::SceneModel>(std::move(*report.scene));
}

// Runs the loop (a fake scene first), swaps in the box field at kSwapAtTick, runs kTicksAfter
// more ticks; the new simulation's counters are read before the offer and after the run.
SwapFigures runSwap(int boxes, bool prewarm) {
  SwapFigures f;
  auto model = boxField(boxes);
  if (!model)
    return f;
  StillDevice device;
  auto created = sim::Simulation::create(model, sim::SimOptions{});
  EXPECT_TRUE(created.ok()) << (created.ok() ? "" : created.error().message);
  if (!created.ok())
    return f;
  sim::Simulation* sim = created.value().get();
  if (prewarm)
    f.prewarm = sim->prewarm(device.X_WD);  // what the daemon's builder does (scene_builder.cpp)
  f.before = sim->coldWork();
  f.dyn_before = sim->dynamicsStatus();
  auto next = std::make_unique<ServoScene>();
  next->sim = std::move(created.value());
  next->generation = 2;

  ServoOptions options;
  options.max_ticks = kSwapAtTick + kTicksAfter;
  HoldClock clock(static_cast<std::int64_t>(kSwapAtTick) * 1'000'000);  // 1 kHz
  ServoLoop loop(options, clock, device, testing::servoSceneOf<testing::FakeSimulation>(1));
  Thread servo;
  std::atomic<bool> done{false};
  auto started = servo.start("servo-swap-test", 1 << 20, [&] {
    loop.prepareServoThread();
    const std::uint64_t a = testing::threadAllocations();
    (void)loop.run();
    f.servo_allocations = testing::threadAllocations() - a;
    done = true;
  });
  EXPECT_TRUE(started.ok());
  while (!clock.held() && !done.load())
    std::this_thread::yield();
  loop.offerScene(std::move(next));
  clock.release();
  servo.join();
  loop.reclaimScenes();  // the fake scene, freed here (never on the servo thread)
  f.generation = loop.state().scene_generation;
  f.ticks = loop.state().tick;
  f.after = sim->coldWork();
  f.dyn_after = sim->dynamicsStatus();
  return f;
}

class SceneSwap : public ::testing::TestWithParam<int> {};

TEST_P(SceneSwap, TheSwapTickAndTheTicksAfterItDoNoColdWork) {
  const int boxes = GetParam();
  const SwapFigures f = runSwap(boxes, true);
  ASSERT_EQ(f.generation, 2u) << "the scene was not swapped in";
  ASSERT_EQ(f.ticks, kSwapAtTick + kTicksAfter);
  // the prewarm found the boxes at rest and did the cold work
  EXPECT_TRUE(f.prewarm.at_rest) << boxes;
  EXPECT_GT(f.prewarm.dynamics_steps, 0u);
  EXPECT_GE(f.before.cold_queries, static_cast<std::uint64_t>(boxes));  // every box on the floor
  EXPECT_GT(f.before.full_sorts, 0u);
  // none of it on the servo thread
  EXPECT_EQ(f.after.cold_queries, f.before.cold_queries) << boxes;
  EXPECT_EQ(f.after.full_sorts, f.before.full_sorts) << boxes;
  EXPECT_EQ(f.after.position_rebuilds, f.before.position_rebuilds) << boxes;
  EXPECT_EQ(f.dyn_after.ticks, f.dyn_before.ticks)
      << boxes << ": the dynamics solved after the swap";
  EXPECT_EQ(f.dyn_after.ticks_asleep - f.dyn_before.ticks_asleep, kTicksAfter);
  EXPECT_EQ(f.servo_allocations, 0u) << boxes;
}

// 2 000 bodies: 1 999 boxes and the floor (the loader's default max_bodies)
INSTANTIATE_TEST_SUITE_P(Boxes, SceneSwap, ::testing::Values(10, 200, 1999));

TEST(SceneSwapCounters, WithoutThePrewarmTheServoThreadDoesTheColdWork) {
  const SwapFigures f = runSwap(200, false);
  ASSERT_EQ(f.generation, 2u);
  // the probe sphere's first placement and the dynamics' first steps run on the servo thread:
  // the broad phase's positions are rebuilt there and the dynamics solve every tick (the scene
  // would sleep only after sleep_time_s)
  EXPECT_GT(f.after.position_rebuilds, f.before.position_rebuilds);
  EXPECT_EQ(f.dyn_after.ticks - f.dyn_before.ticks, kTicksAfter);
  EXPECT_EQ(f.dyn_after.ticks_asleep, f.dyn_before.ticks_asleep);
}

}  // namespace
}  // namespace hapticd::daemon
