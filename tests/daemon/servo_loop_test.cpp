// The servo loop against a fake simulation and a fake device: overruns and the miss fault on a
// scripted clock, device lost and back, the stop ramp, end of stream, the force guard, scene
// swaps at tick boundaries, pose commands through the workspace mapping, determinism on the
// virtual clock.
#include "daemon/servo_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "daemon/device/replay_device.h"
#include "protocol/pose_stream.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

using testing::FakeDevice;
using testing::FakeSimulation;

using testing::drainEvents;

std::unique_ptr<ServoScene> fakeScene(FakeSimulation** out = nullptr, std::uint64_t gen = 1) {
  return testing::servoSceneOf<FakeSimulation>(gen, out);
}

bool hasEvent(const std::vector<ServoEvent>& events, ServoEventKind kind) {
  for (const auto& e : events)
    if (e.kind == kind)
      return true;
  return false;
}

TEST(ServoLoop, MissFaultLatchesAfterTheConfiguredRunAndFadesTheForce) {
  // ticks 0..199 take 100 us; then 12 ticks of 1.5 ms (each overruns a 1 ms period); then 100 us
  std::vector<std::int64_t> script(200, 100'000);
  script.insert(script.end(), 12, 1'500'000);
  ScriptedClock clock(script, 100'000);
  FakeDevice device;
  device.depth_offset = 0.005;  // always in contact: a force to fade
  ServoOptions options;
  options.miss_fault_count = 10;
  options.max_ticks = 400;
  options.fault_fade_s = 0.02;
  ServoLoop loop(options, clock, device, fakeScene());
  EXPECT_EQ(loop.run(), ServoExit::kMaxTicks);
  const ServoState st = loop.state();
  EXPECT_EQ(st.faults & kFaultMisses, kFaultMisses);
  EXPECT_EQ(st.overruns, 12u);
  // each 1.5 ms tick ran into exactly one following period, which was skipped, not queued
  EXPECT_EQ(st.skipped_periods, 12u);
  EXPECT_EQ(st.period_index, 400u + 12u - 1u);
  EXPECT_EQ(st.consecutive_misses, 0u);  // the run ended; the fault stays latched
  EXPECT_EQ(st.output_gain, 0.0);
  EXPECT_EQ(device.last_force, geom::Vec3(0.0));
  const auto events = drainEvents(loop);
  ASSERT_TRUE(hasEvent(events, ServoEventKind::kMissFault));
  for (const auto& e : events)
    if (e.kind == ServoEventKind::kMissFault) {
      EXPECT_EQ(e.a, 10);
      EXPECT_EQ(e.tick, 210u);  // the 10th overrunning tick (ticks 200..209) latched it
    }
  // the fade never steps the force by more than F_max
  EXPECT_LE(device.max_step_n, options.max_force_step_n + 1e-12);
  EXPECT_GT(device.max_written_n, 1.0);
  // the lateness histogram saw every tick on time (scripted clock wakes exactly on deadline)
  EXPECT_EQ(loop.lateness().count(), 400u);
  EXPECT_EQ(loop.lateness().maxNs(), 0);
}

TEST(ServoLoop, NineMissesInARowDoNotLatchAndAGoodTickResetsTheRun) {
  std::vector<std::int64_t> script;
  for (int round = 0; round < 5; ++round) {
    script.insert(script.end(), 9, 2'500'000);  // 9 overruns of two periods each
    script.push_back(100'000);
  }
  ScriptedClock clock(script, 100'000);
  FakeDevice device;
  ServoOptions options;
  options.miss_fault_count = 10;
  options.max_ticks = 100;
  ServoLoop loop(options, clock, device, fakeScene());
  loop.run();
  const ServoState st = loop.state();
  EXPECT_EQ(st.faults, 0u);
  EXPECT_EQ(st.overruns, 45u);
  EXPECT_EQ(st.skipped_periods, 90u);
}

TEST(ServoLoop, ArmClearsALatchedFaultAndRestartsTheRamp) {
  std::vector<std::int64_t> script(20, 100'000);
  script.insert(script.end(), 3, 1'200'000);
  ScriptedClock clock(script, 100'000);
  FakeDevice device;
  device.depth_offset = 0.005;
  FakeSimulation* sim = nullptr;
  ServoOptions options;
  options.miss_fault_count = 3;
  options.max_ticks = 200;
  ServoLoop loop(options, clock, device, fakeScene(&sim));
  loop.run();
  ASSERT_NE(loop.state().faults & kFaultMisses, 0u);
  EXPECT_EQ(loop.state().ramp_restarts, 0u);
  ServoCommand arm;
  arm.kind = CommandKind::kArm;
  arm.sequence = 7;
  ASSERT_TRUE(loop.sendCommand(arm));
  loop.setMaxTicks(400);
  loop.run();
  const ServoState st = loop.state();
  EXPECT_EQ(st.faults, 0u);
  EXPECT_EQ(st.output_gain, 1.0);
  EXPECT_EQ(st.last_command_sequence, 7u);
  EXPECT_EQ(st.ramp_restarts, 1u);
  EXPECT_TRUE(hasEvent(drainEvents(loop), ServoEventKind::kArmed));
}

TEST(ServoLoop, DeviceLostZeroesTheForceAtOnceAndComesBack) {
  VirtualClock clock;
  FakeDevice device;
  device.depth_offset = 0.005;
  device.lost_from = 100;
  device.lost_until = 200;
  FakeSimulation* sim = nullptr;
  ServoOptions options;
  options.max_ticks = 100;
  ServoLoop loop(options, clock, device, fakeScene(&sim));
  loop.run();
  EXPECT_GT(glm::length(device.last_force), 0.5);
  EXPECT_TRUE(loop.state().device_connected);
  const std::uint64_t writes_before = device.writes;

  loop.setMaxTicks(101);  // the first lost tick
  loop.run();
  ServoState st = loop.state();
  EXPECT_FALSE(st.device_connected);
  EXPECT_EQ(st.device_lost_count, 1u);
  EXPECT_EQ(st.force_W_n, geom::Vec3(0.0));  // at once, no ramp
  EXPECT_FALSE(sim->last_input.device_ok);
  EXPECT_EQ(device.writes, writes_before);  // nothing written to a lost device
  EXPECT_TRUE(hasEvent(drainEvents(loop), ServoEventKind::kDeviceLost));

  loop.setMaxTicks(200);
  loop.run();
  EXPECT_EQ(loop.state().device_lost_count, 1u);  // one loss, however long
  EXPECT_EQ(device.writes, writes_before);

  loop.setMaxTicks(400);
  loop.run();
  st = loop.state();
  EXPECT_TRUE(st.device_connected);
  EXPECT_TRUE(sim->last_input.device_ok);
  EXPECT_EQ(st.ramp_restarts, 1u);  // the force ramps in again after reconnection
  EXPECT_GT(glm::length(st.force_W_n), 0.5);
  EXPECT_TRUE(hasEvent(drainEvents(loop), ServoEventKind::kDeviceBack));
}

TEST(ServoLoop, StopRampsTheForceToZeroWithinTheStepLimitThenReturns) {
  VirtualClock clock;
  FakeDevice device;
  device.depth_offset = 0.02;  // 12 N before the clamp: the clamp holds it at 10 N
  ServoOptions options;
  options.max_ticks = 300;
  options.ramp_in_s =
      0.0;  // full force from the start (the output stage's ramp-in is tested apart)
  ServoLoop loop(options, clock, device, fakeScene());
  loop.run();
  EXPECT_NEAR(glm::length(device.last_force), 10.0, 1e-9);
  loop.setMaxTicks(0);
  loop.requestStop();
  EXPECT_EQ(loop.run(), ServoExit::kStopped);
  const ServoState st = loop.state();
  EXPECT_TRUE(st.stopping);
  EXPECT_FALSE(st.running);
  EXPECT_EQ(device.last_force, geom::Vec3(0.0));
  EXPECT_EQ(device.last_torque, geom::Vec3(0.0));
  EXPECT_LE(device.max_step_n, options.max_force_step_n + 1e-12);
  EXPECT_LE(device.max_written_n, options.limits.max_force_n + 1e-12);
  // the ramp took at least stop_ramp_s (0.2 s = 200 ticks) and ended soon after
  EXPECT_GE(st.tick, 300u + 200u);
  EXPECT_LE(st.tick, 300u + 210u);
  EXPECT_TRUE(hasEvent(drainEvents(loop), ServoEventKind::kStopRampDone));
}

TEST(ServoLoop, EndOfStreamEndsTheLoop) {
  VirtualClock clock;
  FakeDevice device;
  device.end_after = 1234;
  ServoOptions options;
  ServoLoop loop(options, clock, device, fakeScene());
  EXPECT_EQ(loop.run(), ServoExit::kEndOfStream);
  EXPECT_EQ(loop.state().tick, 1234u);  // the end-of-stream reading is not a tick
  EXPECT_EQ(device.last_force, geom::Vec3(0.0));
}

// A replay plays every row of its stream: rows at decimal times (t = i ms, written "%.3f") end
// on the tick at the last row, at 1 and 4 kHz. The loop's time k * T once rounded up past such a
// row (9 * 0.001 > 0.009) and the replay ended one tick before its last row.
TEST(ServoLoop, AReplayPlaysTheLastRowOfItsStream) {
  for (const int rows : {10, 2001}) {
    std::string text = "t,px,py,pz,qx,qy,qz,qw,buttons\n";
    for (int i = 0; i < rows; ++i) {
      char line[96];
      std::snprintf(line, sizeof line, "%.3f,0,0,%.6f,0,0,0,1,0\n", i * 1e-3, 0.05 - i * 1e-6);
      text += line;
    }
    for (const double rate_hz : {1000.0, 4000.0}) {
      auto parsed =
          proto::parsePoseStream(text, "rows.csv", 1e-3, proto::PoseStreamDialect::kStrict);
      ASSERT_TRUE(parsed.ok());
      device::ReplayDevice device("replay:rows.csv", std::move(parsed).value(),
                                  device::DeviceOptions{});
      VirtualClock clock;
      ServoOptions options;
      options.rate_hz = rate_hz;
      ServoLoop loop(options, clock, device, fakeScene());
      EXPECT_EQ(loop.run(), ServoExit::kEndOfStream);
      const auto per_row = static_cast<std::uint64_t>(rate_hz / 1000.0);
      EXPECT_EQ(loop.state().tick, static_cast<std::uint64_t>(rows - 1) * per_row + 1)
          << rows << " rows at " << rate_hz << " Hz";
      EXPECT_EQ(loop.state().t_s, device.rows().back().t_s);
    }
  }
}

TEST(ServoLoop, NonFiniteForceIsZeroedAndLatched) {
  VirtualClock clock;
  FakeDevice device;
  device.depth_offset = 0.005;
  FakeSimulation* sim = nullptr;
  ServoOptions options;
  options.max_ticks = 100;
  ServoLoop loop(options, clock, device, fakeScene(&sim));
  sim->nan_at_step = 50;
  loop.run();
  const ServoState st = loop.state();
  EXPECT_NE(st.faults & kFaultNonFinite, 0u);
  EXPECT_TRUE(std::isfinite(device.max_written_n));
  EXPECT_EQ(device.last_force, geom::Vec3(0.0));
  EXPECT_TRUE(hasEvent(drainEvents(loop), ServoEventKind::kNonFiniteForce));
}

TEST(ServoLoop, SceneSwapsAtATickBoundaryAndTheOldOneIsFreedByTheOwner) {
  VirtualClock clock;
  FakeDevice device;
  ServoOptions options;
  options.max_ticks = 0;
  ServoLoop loop(options, clock, device, fakeScene(nullptr, 1));
  std::thread servo([&] { loop.run(); });
  for (std::uint64_t gen = 2; gen <= 50; ++gen) {
    loop.offerScene(fakeScene(nullptr, gen));
    while (loop.state().scene_generation != gen) {
      loop.reclaimScenes();
      std::this_thread::yield();
    }
  }
  loop.requestStop();
  servo.join();
  loop.reclaimScenes();
  EXPECT_EQ(loop.currentScene()->generation, 50u);
}

TEST(ServoLoop, ScenesArePreparedOnTheServoThreadBeforeTheirFirstStep) {
  VirtualClock clock;
  FakeDevice device;
  ServoOptions options;
  options.max_ticks = 10;
  ServoLoop loop(options, clock, device, nullptr);
  FakeSimulation* first = nullptr;
  loop.offerScene(fakeScene(&first, 1));
  loop.prepareServoThread();  // takes the offer and prepares it
  ASSERT_NE(loop.currentScene(), nullptr);
  EXPECT_EQ(first->prepared, 1u);
  EXPECT_EQ(first->steps, 0u);
  loop.run();
  EXPECT_EQ(first->steps, 10u);
  FakeSimulation* second = nullptr;
  loop.offerScene(fakeScene(&second, 2));
  loop.setMaxTicks(11);
  loop.run();  // swapped in at the tick boundary, prepared, then stepped
  EXPECT_EQ(second->prepared, 1u);
  EXPECT_EQ(second->steps, 1u);
  EXPECT_EQ(loop.state().scene_generation, 2u);
  loop.reclaimScenes();
}

TEST(ServoLoop, StateReadFromAnotherThreadIsAlwaysOneWholeTick) {
  // on the virtual clock no period is skipped: every snapshot must have tick == period_index + 1
  // and t == period_index * period (whole nanoseconds, in seconds), whatever moment the reader
  // catches
  VirtualClock clock;
  FakeDevice device;
  ServoOptions options;
  options.max_ticks = 200'000;
  ServoLoop loop(options, clock, device, fakeScene());
  std::thread servo([&] { loop.run(); });
  std::uint64_t reads = 0, last_tick = 0;
  for (;;) {
    const ServoState st = loop.state();
    if (st.tick > 0) {
      ASSERT_EQ(st.tick, st.period_index + 1);
      ASSERT_EQ(st.t_s, static_cast<double>(st.period_index * 1'000'000) / 1e9);
      ASSERT_EQ(st.X_W_device.translation.x, 0.001 * st.t_s);  // the fake device's path
      ASSERT_GE(st.tick, last_tick);
      last_tick = st.tick;
      ++reads;
    }
    if (!st.running && st.tick == options.max_ticks)
      break;
  }
  servo.join();
  EXPECT_GT(reads, 0u);
}

// 10 ticks; the device frame at x = 1 in the scene, scene metres per device metre 2
ServoOptions mappedOptions() {
  ServoOptions options;
  options.max_ticks = 10;
  options.workspace.scale = 2.0;
  options.workspace.X_SD.translation = geom::Vec3(1.0, 0.0, 0.0);
  return options;
}

TEST(ServoLoop, PoseCommandsGoToTheDeviceInItsOwnFrame) {
  VirtualClock clock;
  FakeDevice device;
  ServoLoop loop(mappedOptions(), clock, device, fakeScene());
  ServoCommand cmd;
  cmd.sequence = 42;
  cmd.pose.X_W_target.translation = geom::Vec3(3.0, 2.0, 0.0);
  ASSERT_TRUE(loop.sendCommand(cmd));
  loop.run();
  EXPECT_EQ(device.commands, 1u);
  EXPECT_EQ(device.last_command.X_W_target.translation, geom::Vec3(1.0, 1.0, 0.0));
  EXPECT_EQ(loop.state().last_command_sequence, 42u);
  // and the device pose comes back mapped: x_S = 1 + 2 x_D
  const ServoState st = loop.state();
  EXPECT_DOUBLE_EQ(st.X_W_device.translation.x, 1.0 + 2.0 * 0.001 * st.t_s);
}

// a client's command goes through the gate as the daemon's own type: the device gets the pose
// as sent (through the workspace), velocities and buttons too; when the stream stops the gate
// latches stream_lost, which the loop reports with the protocol's number and a named event
TEST(ServoLoop, GatedCommandsReachTheDeviceAsSentAndAStoppedStreamLatchesStreamLost) {
  VirtualClock clock;
  FakeDevice device;
  ServoLoop loop(mappedOptions(), clock, device, fakeScene());
  proto::PoseCommand wire;
  wire.X_WT.p = {3.0, 2.0, 0.0};
  wire.X_WT.q = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};
  wire.v_W = {0.5, 0.0, 0.0};
  wire.w_W = {0.0, 0.0, 1.0};
  wire.buttons = 3;
  ASSERT_TRUE(loop.sendCommand(gatedCommand(CommandKind::kArm, 7, 1, {})));
  ASSERT_TRUE(loop.sendCommand(gatedCommand(CommandKind::kPose, 7, 2, wire)));
  loop.run();
  ASSERT_GT(device.commands, 0u);
  const device::PoseCommand& c = device.last_command;
  EXPECT_EQ(c.X_W_target.translation, geom::Vec3(1.0, 1.0, 0.0));
  const geom::Quat q = glm::normalize(geom::Quat(std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)));
  EXPECT_EQ(c.X_W_target.rotation, q);  // normalised once, as it entered
  EXPECT_EQ(c.linear_velocity, geom::Vec3(0.25, 0.0, 0.0));
  EXPECT_EQ(c.angular_velocity, geom::Vec3(0.0, 0.0, 1.0));
  EXPECT_EQ(c.buttons, 3u);
  EXPECT_EQ(loop.state().last_command_sequence, 2u);
  EXPECT_EQ(loop.state().faults, 0u);
  drainEvents(loop);
  loop.setMaxTicks(400);  // 390 ms more without a command: the gate ramps, then faults
  loop.run();
  const ServoState st = loop.state();
  EXPECT_EQ(st.faults, proto::kFaultStreamLost);
  EXPECT_EQ(st.fault_latches, 1u);
  const auto events = drainEvents(loop);
  ASSERT_TRUE(hasEvent(events, ServoEventKind::kStreamLost));
  for (const auto& e : events) {
    if (e.kind == ServoEventKind::kStreamLost) {
      EXPECT_EQ(describe(e).rfind("fault latched at tick ", 0), 0u) << describe(e);
      EXPECT_NE(describe(e).find(": stream_lost: "), std::string::npos) << describe(e);
    }
  }
}

TEST(ServoLoop, VirtualClockRunsAreIdenticalButForTickNs) {
  auto runOnce = [] {
    VirtualClock clock;
    FakeDevice device;
    device.end_after = 3000;
    ServoOptions options;
    options.record = true;
    options.wait_for_record_space = true;
    options.record_capacity = 64;  // small: the writer below must keep up
    ServoLoop loop(options, clock, device, fakeScene());
    std::vector<RecordRow> rows;
    std::atomic<bool> done{false};
    std::thread writer([&] {
      RecordRow r;
      for (;;) {
        if (loop.popRecord(r)) {
          rows.push_back(r);
        } else if (done.load()) {
          while (loop.popRecord(r))
            rows.push_back(r);
          break;
        }
      }
    });
    loop.run();
    done = true;
    writer.join();
    return rows;
  };
  const auto a = runOnce();
  const auto b = runOnce();
  ASSERT_EQ(a.size(), 3000u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    RecordRow x = a[i], y = b[i];
    x.tick_ns = y.tick_ns = 0;
    ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << "row " << i;
    EXPECT_EQ(a[i].tick, i);
  }
}

}  // namespace
}  // namespace hapticd::daemon
