// The servo thread allocates nothing after start: ServoLoop::run() over 100 000 ticks (after
// ServoLoop::prepareServoThread(), as in the daemon), counted by a per-thread allocator hook
// (tests/daemon/alloc_counter.cpp), with the record rings on, commands and scene swaps (of the
// same scene, freshly built, and with the real simulation prewarmed as the daemon's builder does)
// arriving, scene edit batches arriving, a shared-memory segment
// served (a client pushing commands, the state published every tick), and state and lists read
// from another thread. With the real libraries
// in the tree it runs every demo scene through the real simulation and the replay device fed by the
// scene's pose stream.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "protocol/client.h"
#include "protocol/server.h"
#include "protocol/shm.h"
#include "tests/daemon/alloc_counter.h"
#include "tests/daemon/fakes.h"

#ifdef HAPTICD_FAKE_DHD
#include "daemon/device/dhd_api.h"
#include "daemon/device/forcedimension_device.h"
#include "tests/daemon/device/fake_dhd.h"
#endif
#ifdef HAPTICD_FAKE_HD
#include "daemon/device/hd_api.h"
#include "daemon/device/openhaptics_device.h"
#include "tests/daemon/device/fake_hd.h"
#endif
#ifdef HAPTICD_FAKE_HAPLY
#include "daemon/device/haply_device.h"
#include "tests/daemon/device/fake_haply.h"
#endif
#ifdef HAPTICD_HAVE_REAL_BACKENDS
#include "core/scene/loader.h"
#include "scenes/demo_scenes.h"
#endif

namespace hapticd::daemon {
namespace {

constexpr std::uint64_t kTicks = 100'000;

struct Counts {
  std::uint64_t servo_allocations = ~0ull;
  ServoExit exit = ServoExit::kStopped;
  std::uint64_t rows = 0, body_rows = 0, state_reads = 0, edits_sent = 0, shm_sent = 0;
};

// What runCounted adds when given: edit batches (a pose for `edit_body` now and then, an add and
// a remove of `toggle_body`) and a shm client's commands.
struct Extras {
  std::uint32_t edit_body = 3;
  std::uint32_t toggle_body = 4;
  proto::ShmClient* shm = nullptr;
};

// Runs the loop on its own thread (allocations counted inside run() only) while this thread
// drains the record rings, reads the seqlock state and sends pose commands.
Counts runCounted(ServoLoop& loop,
                  bool offer_scenes,
                  const std::function<std::unique_ptr<ServoScene>(std::uint64_t)>& make_scene,
                  const Extras* extras = nullptr) {
  Counts c;
  std::atomic<bool> done{false};
  if (extras != nullptr) {
    // queued before the start, so that a loop that outruns this thread (virtual clock, loaded
    // machine) still meets an edit batch and a shm command inside its counted run
    EditBatch e;
    e.generation = loop.state().scene_generation;
    e.pose_count = 1;
    e.poses[0] = {extras->edit_body, geom::Pose{}};
    c.edits_sent += loop.sendEdits(e) ? 1u : 0u;
    if (extras->shm != nullptr) {
      c.shm_sent += extras->shm->pushArm(proto::monotonicNs()) ? 1u : 0u;
      c.shm_sent += extras->shm->pushPose(proto::PoseCommand{}, proto::monotonicNs()) ? 1u : 0u;
    }
  }
  Thread servo;
  auto started = servo.start("servo-test", 1 << 20, [&] {
    loop.prepareServoThread();  // as the daemon's servo thread does before its loop
    const std::uint64_t before = testing::threadAllocations();
    c.exit = loop.run();
    c.servo_allocations = testing::threadAllocations() - before;
    done = true;
  });
  EXPECT_TRUE(started.ok());
  std::uint64_t gen = 1, seq = 0;
  RecordRow r;
  BodyRow b;
  while (!done.load()) {
    while (loop.popRecord(r))
      ++c.rows;
    while (loop.popBody(b))
      ++c.body_rows;
    const ServoState st = loop.state();
    ++c.state_reads;
    ServoCommand cmd;
    cmd.sequence = ++seq;
    cmd.pose.X_W_target.translation = geom::Vec3(0.0, 0.01 * std::sin(st.t_s), 0.0);
    // every other command goes through the CommandGate, as a network client's do; an arm now
    // and then (the gate's stream-stop fault latches between them on the virtual clock)
    cmd.gated = seq % 2 == 0;
    cmd.session_id = 7;
    if (seq % 1000 == 0)
      cmd.kind = CommandKind::kArm;
    (void)loop.sendCommand(cmd);
    if (extras != nullptr) {
      const ServoLists l = loop.lists();
      c.state_reads += l.tick > 0 ? 1u : 0u;
      if (seq % 5 == 0) {
        EditBatch e;
        e.generation = st.scene_generation;
        e.id = seq;
        e.pose_count = 1;
        e.poses[0] = {extras->edit_body, cmd.pose.X_W_target};
        if (seq % 10 == 0) {
          e.add_count = 1;
          e.added[0] = {extras->toggle_body, cmd.pose.X_W_target};
        } else {
          e.remove_count = 1;
          e.removed[0] = extras->toggle_body;
        }
        c.edits_sent += loop.sendEdits(e) ? 1u : 0u;
      }
      if (extras->shm != nullptr) {
        const std::uint64_t now = proto::monotonicNs();
        extras->shm->beat(now);
        proto::PoseCommand p;
        p.X_WT.p[1] = cmd.pose.X_W_target.translation.y;
        const bool ok = seq % 997 == 0 ? extras->shm->pushArm(now) : extras->shm->pushPose(p, now);
        c.shm_sent += ok ? 1u : 0u;
        proto::ShmState shm_state;
        (void)extras->shm->readState(shm_state);
      }
    }
    if (offer_scenes && st.tick > gen * 20'000 && !loop.sceneOfferPending()) {
      loop.offerScene(make_scene(++gen));
    }
    loop.reclaimScenes();
    std::this_thread::yield();
  }
  servo.join();
  while (loop.popRecord(r))
    ++c.rows;
  while (loop.popBody(b))
    ++c.body_rows;
  loop.reclaimScenes();
  return c;
}

std::unique_ptr<ServoScene> fakeScene(std::uint64_t gen) {
  return testing::servoSceneOf<testing::FakeSimulation>(gen);
}

// kTicks ticks, every one recorded (the loop waits for record space: no row dropped)
ServoOptions recordingOptions() {
  ServoOptions options;
  options.max_ticks = kTicks;
  options.record = true;
  options.wait_for_record_space = true;
  return options;
}

// The daemon's wiring: a network thread running proto::Server is the command ring's only
// producer; a protocol client arms, streams pose commands (gated) and subscribes to state at
// 1 kHz while the loop runs on the real clock.
TEST(ServoAllocation, NoneOnTheServoThreadWithTheNetworkThreadFeedingTheGate) {
  MonotonicClock clock;
  testing::FakeDevice device;
  ServoOptions options;
  options.max_ticks = 3000;
  ServoLoop loop(options, clock, device, fakeScene(1));
  proto::ServerConfig cfg;
  cfg.bind_address = "127.0.0.1:0";
  proto::ServerHandlers h;
  h.on_command = [&](const proto::CommandEvent& e) {
    ServoCommand c;
    c.gated = true;
    c.session_id = e.session_id;
    c.sequence = e.sequence;
    c.kind = e.kind == proto::CommandEvent::Kind::kArm      ? CommandKind::kArm
             : e.kind == proto::CommandEvent::Kind::kDisarm ? CommandKind::kDisarm
                                                            : CommandKind::kPose;
    c.pose.X_W_target.translation =
        geom::Vec3(e.pose.X_WT.p[0], e.pose.X_WT.p[1], e.pose.X_WT.p[2]);
    return loop.sendCommand(c);
  };
  h.fill_state = [&](proto::State& st) {
    const ServoState s = loop.state();
    st.tick = s.tick;
    st.last_command_sequence = s.last_command_sequence;
    return s.tick > 0;
  };
  auto server = proto::Server::create(cfg, h);
  ASSERT_TRUE(server) << server.error().message;
  std::atomic<bool> stop{false};
  std::thread net([&] { server.value()->run(stop); });

  proto::ClientConfig cc;
  cc.server = server.value()->localAddress().toString();
  auto client = proto::Client::connect(cc);
  ASSERT_TRUE(client) << client.error().message;
  ASSERT_TRUE(client.value()->arm());
  ASSERT_TRUE(client.value()->subscribe(1000));

  std::atomic<bool> done{false};
  std::uint64_t allocations = ~0ull;
  Thread servo;
  ASSERT_TRUE(servo
                  .start("servo-test", 1 << 20,
                         [&] {
                           loop.prepareServoThread();
                           const std::uint64_t before = testing::threadAllocations();
                           (void)loop.run();
                           allocations = testing::threadAllocations() - before;
                           done = true;
                         })
                  .ok());
  std::uint64_t states = 0;
  proto::PoseCommand cmd;
  while (!done.load()) {
    cmd.X_WT.p[1] = 0.001 * static_cast<double>(states % 10);
    (void)client.value()->sendPose(cmd);
    while (client.value()->receiveState(1))
      ++states;
  }
  servo.join();
  stop = true;
  net.join();
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(states, 0u);
  EXPECT_GT(loop.state().commands_accepted, 0u);  // the gate took the network's commands
}

TEST(ServoAllocation, NoneOnTheServoThreadOver100000TicksWithFakes) {
  VirtualClock clock;
  testing::FakeDevice device;
  device.depth_offset = 0.002;
  ServoOptions options = recordingOptions();
  options.record_bodies = true;
  ServoLoop loop(options, clock, device, fakeScene(1));
  const Counts c = runCounted(loop, true, &fakeScene);
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(c.servo_allocations, 0u);
  EXPECT_EQ(c.rows, kTicks);
  EXPECT_EQ(c.body_rows, 2 * kTicks);
  EXPECT_GE(loop.state().scene_generation, 2u);  // scenes were swapped during the run
  EXPECT_GT(device.commands, 0u);
}

std::unique_ptr<ServoScene> editableScene(std::uint64_t gen) {
  return testing::servoSceneOf<testing::EditableSimulation>(gen);
}

TEST(ServoAllocation, NoneOnTheServoThreadWithEditsListsAndSharedMemory) {
  const std::string name = "/hapticd-alloc-test-" + std::to_string(getpid());
  auto server = proto::ShmServer::create(name);
  ASSERT_TRUE(server) << server.error().message;
  auto client = proto::ShmClient::attach(name);
  ASSERT_TRUE(client) << client.error().message;
  VirtualClock clock;
  testing::FakeDevice device;
  device.depth_offset = 0.002;  // in contact: contact lists every tick
  const ServoOptions options = recordingOptions();
  ServoLoop loop(options, clock, device, editableScene(1));
  loop.attachShm(&server.value());
  Extras extras;
  extras.shm = &client.value();
  const Counts c = runCounted(loop, true, &editableScene, &extras);
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(c.servo_allocations, 0u);
  const ServoState st = loop.state();
  EXPECT_GT(c.edits_sent, 0u);
  EXPECT_GT(st.edit_batches_applied, 0u);  // the edits were applied (and refusals reported)
  EXPECT_GT(st.edits_applied, 0u);
  EXPECT_GT(c.shm_sent, 0u);
  EXPECT_GT(st.shm_commands, 0u);
  EXPECT_GE(st.scene_generation, 2u);
  proto::ShmState shm{};
  ASSERT_TRUE(client.value().readState(shm));
  EXPECT_EQ(shm.tick, kTicks);
}

#ifdef HAPTICD_FAKE_DHD
// The forcedimension backend over the fake DHD library (tests/daemon/device/fake_dhd.cpp): reads,
// writes, device faults (latched, faded, braked) and re-arms (forces on again) on the servo
// thread, every 1000th command an arm.
TEST(ServoAllocation, NoneOnTheServoThreadWithTheForceDimensionDevice) {
  const FakeDhdControl& fake = fakeDhd();
  fake.reset(1, 104);
  const double p[3] = {0.0, 0.0, -0.002};  // in contact with the fake wall
  const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  fake.set_pose(0, p, R);
  auto api = device::dhd::loadApi(HAPTICD_FAKE_DHD);
  ASSERT_TRUE(api.ok()) << api.error().message;
  auto device = device::ForceDimensionDevice::open(api.value(), 0, device::DeviceOptions{});
  ASSERT_TRUE(device.ok()) << device.error().message;
  fake.fail(0, device::dhd::kError, 1);  // a device fault at the first read
  VirtualClock clock;
  const ServoOptions options = recordingOptions();
  ServoLoop loop(options, clock, *device.value(), fakeScene(1));
  const Counts c = runCounted(loop, true, &fakeScene);
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(c.servo_allocations, 0u);
  EXPECT_GE(loop.state().fault_latches, 1u);
  EXPECT_GT(fake.state(0).force_calls, 0u);  // live again after an arm
}
#endif

#ifdef HAPTICD_FAKE_HD
// The openhaptics backend in device-clocked mode: the ticks run on the fake HD scheduler's thread
// (the servo thread of this mode); its allocations are read by the fake's end-of-frame hook, on
// that thread, from the second frame to the last, with HD errors (faults), arms and the gate.
TEST(ServoAllocation, NoneOnTheHdSchedulerThreadWithTheOpenHapticsDevice) {
  const FakeHdControl& fake = fakeHd();
  fake.reset("PHANTOM Premium 1.5 6DOF", 6, 8.5, 515.0);
  const double p[3] = {0.0, -2.0, 0.0};  // in contact with the fake wall (mm)
  const double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  fake.set_pose(p, R);
  for (std::uint64_t f = 1000; f < kTicks; f += 10'000)
    fake.at(f, 3, 0x0201);  // kFakeHdError, HD_EXCEEDED_MAX_FORCE
  struct Seen {
    std::uint64_t frames = 0, first = 0, last = 0;
  } seen;
  fake.set_frame_hook(
      [](void* data) {
        auto* s = static_cast<Seen*>(data);
        const std::uint64_t n = testing::threadAllocations();
        if (++s->frames == 2)
          s->first = n;
        s->last = n;
      },
      &seen);
  auto api = device::hd::loadApi(HAPTICD_FAKE_HD);
  ASSERT_TRUE(api.ok()) << api.error().message;
  auto device = device::OpenHapticsDevice::open(api.value(), "", device::DeviceOptions{});
  ASSERT_TRUE(device.ok()) << device.error().message;
  VirtualClock clock;
  const ServoOptions options = recordingOptions();
  ServoLoop loop(options, clock, *device.value(), fakeScene(1));
  const Counts c = runCounted(loop, true, &fakeScene);
  fake.set_frame_hook(nullptr, nullptr);
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(seen.frames, kTicks);
  EXPECT_EQ(seen.last - seen.first, 0u);
  EXPECT_GE(loop.state().fault_latches, 1u);
  EXPECT_GT(fake.frame_count(), 0u);
}
#endif

#ifdef HAPTICD_FAKE_HAPLY
// The haply backend over the fake Haply Inverse Service: reads and writes are seqlock copies, the
// WebSocket exchange runs on the device's I/O thread; the service reports an error at the start
// (a device fault, latched and faded) and clears it after a few exchanges; arms re-arm.
TEST(ServoAllocation, NoneOnTheServoThreadWithTheHaplyDevice) {
  testing::FakeHaply fake;
  fake.move({0.0, 0.0, -0.002});  // in contact with the fake wall (Haply's z is up)
  fake.reportError(true);
  auto device = device::HaplyDevice::open(fake.url(), device::DeviceOptions{});
  ASSERT_TRUE(device.ok()) << device.error().message;
  std::thread clear([&] {
    for (int i = 0; i < 5000 && fake.forceCount() < 20; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    fake.reportError(false);
  });
  VirtualClock clock;
  const ServoOptions options = recordingOptions();
  ServoLoop loop(options, clock, *device.value(), fakeScene(1));
  const Counts c = runCounted(loop, true, &fakeScene);
  clear.join();
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(c.servo_allocations, 0u);
  EXPECT_GE(loop.state().fault_latches, 1u);
  EXPECT_GE(device.value()->faultTicks(), 1u);
  EXPECT_GT(fake.forceCount(), 0u);
}
#endif

TEST(ServoAllocation, TheHookCountsThisThreadsAllocations) {
  // the hook must see an allocation, or the zeros above prove nothing
  const std::uint64_t before = testing::threadAllocations();
  auto p = std::make_unique<std::vector<int>>(100);
  EXPECT_GE(testing::threadAllocations() - before, 2u);
  std::uint64_t other = 0;
  std::thread t([&] { other = testing::threadAllocations(); });
  t.join();
  EXPECT_LT(other, before + 2);  // another thread's count is its own
}

#ifdef HAPTICD_HAVE_REAL_BACKENDS
// A pose stream repeated until it covers `seconds` (the demo streams are shorter than 100 s).
std::string repeatedStream(const std::string& path, double seconds, const std::string& out_path) {
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  std::vector<std::string> rows;
  double last_t = 0.0;
  while (std::getline(in, line)) {
    if (line.empty())
      continue;
    rows.push_back(line);
    last_t = std::stod(line.substr(0, line.find(',')));
  }
  std::ofstream out(out_path);
  out << header << "\n";
  const double span = last_t + 0.004;
  char buf[64];
  for (int rep = 0; rep * span < seconds; ++rep) {
    for (const auto& row : rows) {
      const auto comma = row.find(',');
      const double t = std::stod(row.substr(0, comma)) + rep * span;
      std::snprintf(buf, sizeof buf, "%.6f", t);
      out << buf << row.substr(comma) << "\n";
    }
  }
  return out_path;
}

class ServoAllocationDemo : public ::testing::TestWithParam<std::string> {};

TEST_P(ServoAllocationDemo, NoneOnTheServoThreadOver100000Ticks) {
  const std::string name = GetParam();
  const auto bytes = scenes::makeDemoScene(name);
  ASSERT_FALSE(bytes.empty());
  auto report = scene::loadScene(bytes, name);
  ASSERT_TRUE(report.ok()) << report.message();
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
  sim::SimOptions sim_options;
  const ServoLoop* running = nullptr;
  auto make = [&](std::uint64_t gen) {
    auto sim = sim::Simulation::create(model, sim_options);
    EXPECT_TRUE(sim.ok());
    auto s = std::make_unique<ServoScene>();
    s->sim = std::move(sim.value());
    // a swapped-in scene is prewarmed at the device's pose, as the daemon's builder does
    if (running != nullptr)
      (void)s->sim->prewarm(running->state().X_W_device);
    s->generation = gen;
    return s;
  };
  const std::string stream = std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv";
  const std::string long_stream =
      repeatedStream(stream, 101.0,
                     ::testing::TempDir() + "/alloc_" + name + "_" + std::to_string(::getpid()) +
                         ".csv");  // per process: two checkouts may run this test at once
  auto device = device::makeDevice("replay:" + long_stream, device::DeviceOptions{});
  ASSERT_TRUE(device.ok()) << device.error().message;
  VirtualClock clock;
  ServoOptions options = recordingOptions();
  options.record_bodies = true;
  ServoLoop loop(options, clock, *device.value(), make(1));
  running = &loop;
  // edits of the first non-static, non-probe bodies (whatever the simulation answers: refusals
  // are events, never allocations) and a shm segment served
  Extras extras;
  for (std::size_t i = 0, found = 0; i < model->bodies.size() && found < 2; ++i) {
    if (model->bodies[i].motion == scene::Motion::kStatic || model->bodies[i].probe)
      continue;
    (found++ == 0 ? extras.edit_body : extras.toggle_body) = static_cast<std::uint32_t>(i);
  }
  const std::string shm_name = "/hapticd-alloc-test-" + std::to_string(getpid()) + "-" + name;
  auto server = proto::ShmServer::create(shm_name);
  ASSERT_TRUE(server) << server.error().message;
  auto client = proto::ShmClient::attach(shm_name);
  ASSERT_TRUE(client) << client.error().message;
  loop.attachShm(&server.value());
  extras.shm = &client.value();
  const Counts c = runCounted(loop, true, make, &extras);
  EXPECT_EQ(c.exit, ServoExit::kMaxTicks);
  EXPECT_EQ(c.servo_allocations, 0u) << name;
  EXPECT_EQ(c.rows, kTicks);
  EXPECT_GT(loop.state().contact_ticks, 0u) << name << ": the stream never touched anything";
}

INSTANTIATE_TEST_SUITE_P(
    DemoScenes,
    ServoAllocationDemo,
    ::testing::Values("gears", "peg_in_hole", "dynamic", "stress", "decomposed"));
#endif

}  // namespace
}  // namespace hapticd::daemon
