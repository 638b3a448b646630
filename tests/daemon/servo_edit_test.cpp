// The servo loop's scene edits, state lists and shared memory, on virtual clocks: an edit batch
// is applied whole at one tick boundary (every entry visible together in the next lists), a batch
// for an old generation is dropped and counted, one for a scene offered but not yet taken waits
// for it, refused entries are counted and reported, a full ring refuses; the lists carry body
// poses and contacts (truncated at their capacity, counted); a shm client's commands go through
// the command gate (sequence echoed in the segment's state, the device follows, the stream stop
// ramps the force to zero by 200 ms and latches a fault until re-armed).
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "daemon/servo_loop.h"
#include "protocol/server.h"
#include "protocol/shm.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

using testing::EditableSimulation;
using testing::FakeDevice;

// Virtual time that the test lets run tick by tick: sleepUntilNs waits (yielding) until the test
// allows the deadline. A test-only clock: the servo thread blocks in it by design.
class LockstepClock final : public Clock {
 public:
  std::int64_t nowNs() noexcept override { return now_.load(); }
  void sleepUntilNs(std::int64_t deadline_ns) noexcept override {
    while (deadline_ns > allowed_.load())
      std::this_thread::yield();
    if (deadline_ns > now_.load())
      now_.store(deadline_ns);
  }
  bool isVirtual() const noexcept override { return true; }
  void allowUntil(std::int64_t ns) { allowed_.store(ns); }

 private:
  std::atomic<std::int64_t> now_{0};
  std::atomic<std::int64_t> allowed_{0};
};

constexpr std::int64_t kPeriodNs = 1'000'000;

// A loop on a LockstepClock run by its own thread; step(n) runs n more ticks and waits for them.
class Stepped {
 public:
  Stepped(ServoOptions options, std::unique_ptr<ServoScene> scene, FakeDevice& device) {
    options.max_ticks = 1'000'000;
    loop = std::make_unique<ServoLoop>(options, clock, device, std::move(scene));
    clock.allowUntil(-1);
    thread = std::thread([this] {
      loop->prepareServoThread();
      loop->run();
    });
  }
  ~Stepped() {
    loop->requestStop();
    clock.allowUntil(INT64_MAX);
    thread.join();
  }
  // runs ticks until state().tick == target (each tick k runs at deadline k * period)
  void runUntilTick(std::uint64_t target) {
    clock.allowUntil(static_cast<std::int64_t>(target - 1) * kPeriodNs);
    while (loop->state().tick < target)
      std::this_thread::yield();
  }
  void step(std::uint64_t n = 1) { runUntilTick(loop->state().tick + n); }

  LockstepClock clock;
  std::unique_ptr<ServoLoop> loop;
  std::thread thread;
};

std::unique_ptr<ServoScene> editScene(EditableSimulation** out, std::uint64_t gen = 1) {
  return testing::servoSceneOf<EditableSimulation>(gen, out);
}

geom::Pose at(double x, double y, double z) {
  geom::Pose X;
  X.translation = geom::Vec3(x, y, z);
  return X;
}

const sim::BodyPose* findBody(const ServoLists& l, std::uint32_t body) {
  for (std::uint32_t i = 0; i < l.body_count; ++i)
    if (l.bodies[i].body == body)
      return &l.bodies[i];
  return nullptr;
}

std::vector<ServoEvent> events(ServoLoop& loop) {
  return testing::drainEvents(loop);
}

TEST(ServoEdits, ABatchIsAppliedWholeAtOneTickBoundaryAndSeenTogetherInTheNextLists) {
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  Stepped s(ServoOptions{}, editScene(&sim), device);
  s.runUntilTick(5);
  ServoLists before = s.loop->lists();
  EXPECT_EQ(before.tick, 5u);
  ASSERT_EQ(findBody(before, 4), nullptr);  // the door starts inactive
  ASSERT_NE(findBody(before, 3), nullptr);
  ASSERT_NE(findBody(before, 5), nullptr);

  // one update: take the crate out, add the door at a pose, move the slider and the door
  EditBatch b;
  b.generation = 1;
  b.id = 1;
  b.remove_count = 1;
  b.removed[0] = 5;
  b.add_count = 1;
  b.added[0] = {4, at(4.0, 1.0, 0.0)};
  b.pose_count = 2;
  b.poses[0] = {3, at(3.0, 0.5, 0.25)};
  b.poses[1] = {4, at(4.0, 2.0, 0.0)};  // after its add in the same batch: allowed
  ASSERT_TRUE(s.loop->sendEdits(b));
  s.step();

  const ServoLists l = s.loop->lists();
  EXPECT_EQ(l.tick, 6u);
  ASSERT_NE(findBody(l, 3), nullptr);
  EXPECT_EQ(findBody(l, 3)->X_WB.translation, geom::Vec3(3.0, 0.5, 0.25));
  ASSERT_NE(findBody(l, 4), nullptr);
  EXPECT_EQ(findBody(l, 4)->X_WB.translation, geom::Vec3(4.0, 2.0, 0.0));
  EXPECT_EQ(findBody(l, 5), nullptr);
  // every entry reached the simulation between the same two steps, in the order removes, adds,
  // poses
  ASSERT_EQ(sim->editCount(), 4u);
  const std::uint32_t order[] = {5, 4, 3, 4};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sim->edit(i).body, order[i]);
    EXPECT_EQ(sim->edit(i).status, sim::EditStatus::kOk);
    EXPECT_EQ(sim->edit(i).steps_before, 5u);
  }
  const ServoState st = s.loop->state();
  EXPECT_EQ(st.edit_batches_applied, 1u);
  EXPECT_EQ(st.edits_applied, 4u);
  EXPECT_EQ(st.edits_refused, 0u);
  EXPECT_EQ(st.edit_batches_dropped, 0u);
}

TEST(ServoEdits, BatchesPushedWhileTheLoopRunsNeverSplitAcrossTicks) {
  // the loop free-running on the virtual clock while this thread pushes 300 batches of three
  // poses each (retrying while the ring is full): each batch's three entries reach the
  // simulation between the same two steps
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  VirtualClock clock;
  ServoOptions options;
  options.edit_capacity = 4;
  ServoLoop loop(options, clock, device, editScene(&sim));
  std::thread servo([&] {
    loop.prepareServoThread();
    loop.run();
  });
  constexpr int kBatches = 300;
  for (int i = 0; i < kBatches; ++i) {
    EditBatch b;
    b.generation = 1;
    b.id = static_cast<std::uint64_t>(i + 1);
    b.pose_count = 3;
    for (std::uint32_t k = 0; k < 3; ++k)
      b.poses[k] = {3, at(static_cast<double>(i), static_cast<double>(k), 0.0)};
    while (!loop.sendEdits(b))
      std::this_thread::yield();
  }
  while (loop.state().edit_batches_applied < kBatches)
    std::this_thread::yield();
  loop.requestStop();
  servo.join();
  ASSERT_EQ(sim->editCount(), 3u * kBatches);
  std::size_t distinct_ticks = 0;
  for (int i = 0; i < kBatches; ++i) {
    const auto& first = sim->edit(3 * static_cast<std::size_t>(i));
    EXPECT_EQ(first.X_WB.translation.x, static_cast<double>(i));
    for (std::size_t k = 1; k < 3; ++k)
      EXPECT_EQ(sim->edit(3 * static_cast<std::size_t>(i) + k).steps_before, first.steps_before)
          << "batch " << i << " split across ticks";
    if (i == 0 || sim->edit(3 * static_cast<std::size_t>(i) - 1).steps_before != first.steps_before)
      ++distinct_ticks;
  }
  EXPECT_GT(distinct_ticks, 1u);  // the batches did arrive over several ticks
  EXPECT_EQ(loop.state().edits_applied, 3u * kBatches);
}

TEST(ServoEdits, ABatchForAnOldGenerationIsDroppedCountedAndReported) {
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  Stepped s(ServoOptions{}, editScene(&sim), device);
  s.runUntilTick(3);
  EditBatch b;
  b.generation = 7;  // not the running scene's (1)
  b.id = 42;
  b.pose_count = 1;
  b.poses[0] = {3, at(9.0, 9.0, 9.0)};
  ASSERT_TRUE(s.loop->sendEdits(b));
  s.step(2);
  EXPECT_EQ(sim->editCount(), 0u);  // nothing reached the simulation
  const ServoState st = s.loop->state();
  EXPECT_EQ(st.edit_batches_dropped, 1u);
  EXPECT_EQ(st.edit_batches_applied, 0u);
  EXPECT_EQ(findBody(s.loop->lists(), 3)->X_WB.translation, geom::Vec3(3.0, 0.0, 0.0));
  bool reported = false;
  for (const auto& e : events(*s.loop)) {
    if (e.kind != ServoEventKind::kEditBatchDropped)
      continue;
    reported = true;
    EXPECT_EQ(e.a, 7);
    EXPECT_EQ(e.b, 1);
    EXPECT_EQ(e.c, 42);
    const std::string text = describe(e);
    EXPECT_NE(text.find("scene update 42 dropped"), std::string::npos) << text;
    EXPECT_NE(text.find("generation 7"), std::string::npos) << text;
  }
  EXPECT_TRUE(reported);
  EXPECT_EQ(s.loop->editsPending(), 0u);
}

TEST(ServoEdits, ABatchForASceneOfferedButNotYetTakenWaitsForItsSwap) {
  FakeDevice device;
  EditableSimulation* first = nullptr;
  EditableSimulation* second = nullptr;
  EditableSimulation* third = nullptr;
  Stepped s(ServoOptions{}, editScene(&first, 1), device);
  s.runUntilTick(2);
  s.loop->offerScene(editScene(&second, 2));
  s.step(2);
  ASSERT_EQ(s.loop->state().scene_generation, 2u);
  // generation 1 waits to be reclaimed, so generation 3 cannot be taken yet
  s.loop->offerScene(editScene(&third, 3));
  EditBatch b;
  b.generation = 3;
  b.pose_count = 1;
  b.poses[0] = {3, at(0.0, 3.0, 0.0)};
  ASSERT_TRUE(s.loop->sendEdits(b));
  s.step(3);
  EXPECT_EQ(s.loop->state().scene_generation, 2u);
  EXPECT_EQ(s.loop->state().edit_batches_dropped, 0u);
  EXPECT_EQ(s.loop->editsPending(), 1u);  // waiting, not dropped
  s.loop->reclaimScenes();
  s.step(2);
  EXPECT_EQ(s.loop->state().scene_generation, 3u);
  EXPECT_EQ(s.loop->state().edit_batches_applied, 1u);
  EXPECT_EQ(third->editCount(), 1u);
  EXPECT_EQ(second->editCount(), 0u);
  s.loop->reclaimScenes();
}

TEST(ServoEdits, RefusedEntriesAreCountedAndReportedAndTheRestOfTheBatchApplies) {
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  Stepped s(ServoOptions{}, editScene(&sim), device);
  s.runUntilTick(2);
  EditBatch b;
  b.generation = 1;
  b.pose_count = 2;
  b.poses[0] = {4, at(1.0, 1.0, 1.0)};  // the door is inactive: the simulation refuses
  b.poses[1] = {3, at(2.0, 2.0, 2.0)};
  ASSERT_TRUE(s.loop->sendEdits(b));
  s.step();
  const ServoState st = s.loop->state();
  EXPECT_EQ(st.edits_refused, 1u);
  EXPECT_EQ(st.edits_applied, 1u);
  EXPECT_EQ(st.edit_batches_applied, 1u);
  EXPECT_EQ(findBody(s.loop->lists(), 3)->X_WB.translation, geom::Vec3(2.0, 2.0, 2.0));
  bool reported = false;
  for (const auto& e : events(*s.loop)) {
    if (e.kind != ServoEventKind::kEditRefused)
      continue;
    reported = true;
    EXPECT_EQ(e.a, 4);
    EXPECT_EQ(e.b, static_cast<std::int64_t>(sim::EditStatus::kInactive));
    EXPECT_EQ(e.c, 0);
    const std::string text = describe(e);
    EXPECT_NE(text.find("poses entry for body 4"), std::string::npos) << text;
    EXPECT_NE(text.find("not active"), std::string::npos) << text;
  }
  EXPECT_TRUE(reported);
}

TEST(ServoEdits, AFullRingRefusesTheBatchAndKeepsTheOnesQueued) {
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  VirtualClock clock;
  ServoOptions options;
  options.edit_capacity = 2;
  options.max_ticks = 3;
  ServoLoop loop(options, clock, device, editScene(&sim));
  EditBatch b;
  b.generation = 1;
  b.pose_count = 1;
  b.poses[0] = {3, at(1.0, 0.0, 0.0)};
  EXPECT_TRUE(loop.sendEdits(b));
  b.poses[0] = {3, at(2.0, 0.0, 0.0)};
  EXPECT_TRUE(loop.sendEdits(b));
  b.poses[0] = {3, at(3.0, 0.0, 0.0)};
  EXPECT_FALSE(loop.sendEdits(b));  // full: not queued
  EXPECT_EQ(loop.editsPending(), 2u);
  loop.prepareServoThread();
  loop.run();
  EXPECT_EQ(loop.state().edit_batches_applied, 2u);
  ASSERT_EQ(sim->editCount(), 2u);
  EXPECT_EQ(sim->edit(1).X_WB.translation.x, 2.0);
  EXPECT_EQ(findBody(loop.lists(), 3)->X_WB.translation.x, 2.0);
}

TEST(ServoLists, BodyPosesAndContactsArePublishedEachTickAndTruncatedAtTheirCapacity) {
  FakeDevice device;
  device.depth_offset = 0.02;  // below the wall all the time: in contact
  EditableSimulation* sim = nullptr;
  Stepped s(ServoOptions{}, editScene(&sim), device);
  sim->contacts_per_touch = 3;
  s.runUntilTick(4);
  ServoLists l = s.loop->lists();
  ServoState st = s.loop->state();
  EXPECT_EQ(l.tick, st.tick);
  EXPECT_EQ(l.scene_generation, 1u);
  EXPECT_EQ(l.body_count, 4u);  // the non-static active bodies: Probe, lid, slider, crate
  EXPECT_EQ(l.bodies_total, 4u);
  ASSERT_EQ(l.contact_count, 3u);
  EXPECT_EQ(l.contacts_total, 3u);
  EXPECT_EQ(l.contacts[0].n_W, geom::Vec3(0.0, 1.0, 0.0));
  EXPECT_GT(l.contacts[2].depth_m, 0.0);
  EXPECT_GT(st.pairs_tested, 0u);
  EXPECT_GT(st.last_tick_ns, 0);

  sim->contacts_per_touch = 40;  // more than the lists hold
  s.step();
  l = s.loop->lists();
  EXPECT_EQ(l.contact_count, kListContacts);
  EXPECT_EQ(l.contacts_total, 40u);
  sim->contacts_per_touch = 1;  // fewer again: the count says how many are current
  s.step();
  l = s.loop->lists();
  EXPECT_EQ(l.contact_count, 1u);
  EXPECT_EQ(l.contacts_total, 1u);
}

// ---- shared memory -------------------------------------------------------------------------

std::string uniqueShmName(const char* what) {
  return "/hapticd-test-" + std::to_string(getpid()) + "-" + what;
}

proto::PoseCommand poseCommand(double x, double y, double z) {
  proto::PoseCommand c;
  c.X_WT.p = {x, y, z};
  return c;
}

// The segment's state as of the loop's last tick. The loop writes its own state before the
// segment's, and a seqlock read gives up while the writer is inside (a servo thread preempted
// mid-write, as under ASan on a loaded machine), so this reads again until the segment shows the
// tick the loop reports; false only if it never does (the 30 s only guards against a hang).
bool readShmOfLastTick(const Stepped& s, const proto::ShmClient& c, proto::ShmState& out) {
  const std::uint64_t tick = s.loop->state().tick;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  do {
    if (c.readState(out) && out.tick == tick)
      return true;
    std::this_thread::yield();
  } while (std::chrono::steady_clock::now() < give_up);
  return false;
}

TEST(ServoShm, ShmCommandsDriveTheDeviceThroughTheGateAndTheStreamStopRampsThenFaults) {
  auto server = proto::ShmServer::create(uniqueShmName("gate"));
  ASSERT_TRUE(server) << server.error().message;
  FakeDevice device;
  device.depth_offset = 0.02;  // in contact: a force for the gate to scale
  EditableSimulation* sim = nullptr;
  ServoOptions options;
  Stepped s(options, editScene(&sim), device);
  s.loop->attachShm(&server.value());  // before the first tick (the clock holds tick 0)
  auto client = proto::ShmClient::attach(uniqueShmName("gate"));
  ASSERT_TRUE(client) << client.error().message;
  client.value().beat(proto::monotonicNs());
  s.runUntilTick(3);
  proto::ShmState shm{};
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_EQ(shm.tick, 3u);
  EXPECT_EQ(shm.body_count, 4u);
  EXPECT_TRUE(s.loop->state().shm_client_alive);

  ASSERT_TRUE(client.value().pushArm(proto::monotonicNs()));
  std::uint64_t seq = 0;
  for (int i = 0; i < 50; ++i) {  // 50 ms of a 1 kHz stream
    ASSERT_TRUE(client.value().pushPose(poseCommand(0.01, 0.02, 0.03), proto::monotonicNs(), &seq));
    s.step();
  }
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_EQ(shm.last_command_sequence, seq);
  EXPECT_NE(shm.state_flags & proto::kStateStreaming, 0u);
  EXPECT_EQ(shm.force_scale, 1.0);
  EXPECT_EQ(device.last_command.X_W_target.translation, geom::Vec3(0.01, 0.02, 0.03));
  EXPECT_EQ(s.loop->state().shm_commands, 51u);
  // layout minor 1: this tick's pair tests (the fake's 3 in contact), depth and compute time
  EXPECT_EQ(shm.pairs_tested, 3u);
  EXPECT_GT(shm.max_penetration_m, 0.0);
  EXPECT_GT(shm.tick_ns, 0u);
  EXPECT_GT(device.commands, 40u);

  // the stream stops at tick t0: full force for 20 ms, then a ramp, zero and a fault by 200 ms
  const std::uint64_t t0 = s.loop->state().tick;
  s.runUntilTick(t0 + 15);
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_EQ(shm.force_scale, 1.0);
  s.runUntilTick(t0 + 110);
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_GT(shm.force_scale, 0.0);
  EXPECT_LT(shm.force_scale, 1.0);
  EXPECT_NE(shm.state_flags & proto::kStateRamping, 0u);
  EXPECT_EQ(shm.fault_bits & proto::kFaultStreamLost, 0u);
  s.runUntilTick(t0 + 202);
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_EQ(shm.force_scale, 0.0);
  EXPECT_NE(shm.fault_bits & proto::kFaultStreamLost, 0u);
  EXPECT_EQ(glm::length(s.loop->state().force_W_n), 0.0);
  // latched: later commands are dropped, the fault stays until an arm
  const std::uint64_t dropped = s.loop->state().commands_dropped;
  ASSERT_TRUE(client.value().pushPose(poseCommand(0.0, 0.0, 0.0), proto::monotonicNs()));
  s.step(50);
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_NE(shm.fault_bits & proto::kFaultStreamLost, 0u);
  EXPECT_GT(s.loop->state().commands_dropped, dropped);
  ASSERT_TRUE(client.value().pushArm(proto::monotonicNs()));
  s.step(2);
  ASSERT_TRUE(readShmOfLastTick(s, client.value(), shm));
  EXPECT_EQ(shm.fault_bits, 0u);
}

TEST(ServoShm, BadSlotsInTheSegmentAreRefusedAndCountedNotApplied) {
  auto server = proto::ShmServer::create(uniqueShmName("bad"));
  ASSERT_TRUE(server) << server.error().message;
  FakeDevice device;
  EditableSimulation* sim = nullptr;
  Stepped s(ServoOptions{}, editScene(&sim), device);
  s.loop->attachShm(&server.value());
  auto client = proto::ShmClient::attach(uniqueShmName("bad"));
  ASSERT_TRUE(client) << client.error().message;
  ASSERT_TRUE(client.value().pushArm(proto::monotonicNs()));
  proto::PoseCommand bad = poseCommand(std::nan(""), 0.0, 0.0);
  ASSERT_TRUE(client.value().pushPose(bad, proto::monotonicNs()));
  s.runUntilTick(3);
  EXPECT_EQ(server.value().commandsRefused(), 1u);
  EXPECT_EQ(s.loop->state().shm_commands, 1u);  // the arm only
  EXPECT_EQ(device.commands, 0u);
}

}  // namespace
}  // namespace hapticd::daemon
