// The real hapticd binary on a free loopback port (real clock, sim device), driven by the real
// hapticctl binary and by the protocol Client: status, load (accepted, refused with the loader's
// first error while the old scene stays), pose commands moving the sim device, arm/disarm, the
// stream-stop ramp and latched fault through the daemon, record, watch, ten clients at once, a
// pre-shared key (only keyed clients served) and "no daemon" answers. Waits are bounded by
// generous limits (a hang fails); no wall-clock duration is asserted. The round trip and tick
// figures are printed (NetFigures), not asserted.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/auth.h"
#include "protocol/client.h"
#include "protocol/server.h"
#include "protocol/shm.h"
#include "tests/daemon/daemon_fixture.h"
#ifdef HAPTICD_FAKE_HAPLY
#include "tests/daemon/device/fake_haply.h"
#endif

#ifdef HAPTICD_HAVE_SCENEGEN
#include "core/scene/loader.h"
#include "scenes/glb_builder.h"
#endif

namespace {

namespace fs = std::filesystem;
namespace proto = hapticd::proto;
const std::string kSource = HAPTICD_SOURCE_DIR;
using SteadyClock = std::chrono::steady_clock;

using hapticd::testing::receiveUntil;
using hapticd::testing::slurp;
using hapticd::testing::spawn;
using hapticd::testing::waitExit;

struct CtlRun {
  int code = -1;
  std::string out, err;
};

class NetTest : public ::testing::Test {
 protected:
  void TearDown() override {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      if (waitExit(pid_, 60.0) != 0)
        ADD_FAILURE() << "hapticd did not stop cleanly on SIGTERM\n" << slurp(dir_ / "d.err");
    }
  }

  // Starts hapticd (real clock, realtime off, sim device) on a free loopback port and waits for
  // its status file to name the port.
  void startDaemon(const std::string& scene = kSource + "/scenes/peg_in_hole.glb",
                   const std::string& network = "",
                   const std::string& device = "") {
    // a shm segment of its own per test (runs in parallel do not collide)
    shm_ = "/hapticd-net-test-" + std::to_string(getpid()) + "-" + hapticd::testing::testName();
    std::ofstream(dir_ / "hapticd.toml")
        << "[servo]\nrealtime = \"off\"\n[scene]\npath = \"" << scene << "\"\n[network]\n"
        << network << (network.find("shm =") == std::string::npos ? "shm = \"" + shm_ + "\"\n" : "")
        << device;
    pid_ = spawn({HAPTICD_BINARY, "--config", (dir_ / "hapticd.toml").string(), "--udp",
                  "127.0.0.1:0", "--status-file", (dir_ / "status.json").string()},
                 dir_ / "d.out", dir_ / "d.err");
    ASSERT_GT(pid_, 0);
    for (int i = 0; i < 6000 && port_ == 0; ++i) {
      const auto j = hapticd::testing::parseJsonOrEmpty(slurp(dir_ / "status.json"));
      if (j.contains("network") && j.value("tick", 0) > 0) {
        const std::string a = j["network"]["udp"];
        port_ = std::stoi(a.substr(a.rfind(':') + 1));
      }
      int st = 0;
      ASSERT_NE(waitpid(pid_, &st, WNOHANG), pid_) << "hapticd ended\n" << slurp(dir_ / "d.err");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_GT(port_, 0) << slurp(dir_ / "d.err");
  }

  CtlRun ctl(std::vector<std::string> args, double limit_s = 120.0) {
    std::vector<std::string> all{HAPTICCTL_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    all.push_back("--port");
    all.push_back(std::to_string(port_));
    const pid_t p = spawn(all, dir_ / "c.out", dir_ / "c.err");
    CtlRun r;
    r.code = waitExit(p, limit_s);
    r.out = slurp(dir_ / "c.out");
    r.err = slurp(dir_ / "c.err");
    return r;
  }

  std::unique_ptr<proto::Client> client(const std::string& name = "net_test") {
    proto::ClientConfig c;
    c.server = "127.0.0.1:" + std::to_string(port_);
    c.name = name;
    c.timeout_ms = 10000;
    auto r = proto::Client::connect(c);
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    return r ? std::move(r.value()) : nullptr;
  }

  nlohmann::json statusJson() {
    CtlRun r = ctl({"status", "--json"});
    EXPECT_EQ(r.code, 0) << r.err;
    return hapticd::testing::parseJsonOrEmpty(r.out);
  }

  hapticd::testing::ScratchDir dir_{"hapticd_net_test"};
  pid_t pid_ = -1;
  int port_ = 0;
  std::string shm_;
};

proto::PoseCommand poseAt(const proto::WireVec3& p) {
  proto::PoseCommand c;
  c.X_WT.p = p;
  return c;
}

double dist(const proto::WireVec3& a, const proto::WireVec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

TEST_F(NetTest, StatusShowsTheSceneAndPlanAndLoadAcceptsGoodAndRefusesBadScenes) {
  startDaemon();
  auto j = statusJson();
  EXPECT_EQ(j["scene"], "peg_in_hole.glb");
  EXPECT_FALSE(j["plan"].get<std::string>().empty());
  EXPECT_GT(j["ticks"].get<std::uint64_t>(), 0u);
  EXPECT_NE(j["device"].get<std::string>().find("sim"), std::string::npos) << j.dump();
  EXPECT_TRUE(j["refused"].is_object());

  CtlRun text = ctl({"status"});
  EXPECT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("scene peg_in_hole.glb"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("plan:"), std::string::npos);

  CtlRun good = ctl({"load", kSource + "/scenes/gears.glb"});
  EXPECT_EQ(good.code, 0) << good.err;
  j = statusJson();
  EXPECT_EQ(j["scene"], "gears.glb");
  EXPECT_FALSE(j["plan"].get<std::string>().empty());

  std::ofstream(dir_ / "broken.glb") << "glTF this is not a binary glTF";
  CtlRun bad = ctl({"load", (dir_ / "broken.glb").string()});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("refused"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("broken.glb"), std::string::npos) << bad.err;       // the loader's text
  EXPECT_EQ(bad.err.find("hapticd-upload-"), std::string::npos) << bad.err;  // not the temp file
  EXPECT_EQ(statusJson()["scene"], "gears.glb");                             // the old scene stays
}

#if defined(HAPTICD_FAKE_DHD) || defined(HAPTICD_FAKE_HAPLY)
// a vendor device: status names its model and serial, the DOF it senses and renders, and its
// limits, as text and as JSON
#define EXPECT_STATUS_DEVICE(want)                                               \
  do {                                                                           \
    CtlRun text = ctl({"status"});                                               \
    EXPECT_EQ(text.code, 0) << text.err;                                         \
    EXPECT_NE(text.out.find("device " + (want)), std::string::npos) << text.out; \
    EXPECT_EQ(statusJson()["device"], (want));                                   \
  } while (false)
#endif

#ifdef HAPTICD_FAKE_DHD
// forcedimension over the fake DHD library
TEST_F(NetTest, StatusShowsAVendorDevicesModelSerialDofAndLimits) {
  startDaemon(kSource + "/scenes/peg_in_hole.glb", "",
              "[device]\nspec = \"forcedimension\"\nforcedimension_library = \"" HAPTICD_FAKE_DHD
              "\"\n");
  EXPECT_STATUS_DEVICE(std::string(
      "forcedimension:0 sigma.7: serial 1200, sensing 7 DOF, force 7 DOF, limits 10 N 0.4 N m"));
}
#endif

#ifdef HAPTICD_FAKE_HAPLY
// haply over the fake Haply Inverse Service (a WebSocket server in this process)
TEST_F(NetTest, StatusShowsTheHaplyDevicesModelSerialDofAndLimits) {
  hapticd::testing::FakeHaply fake;
  startDaemon(kSource + "/scenes/peg_in_hole.glb", "",
              "[device]\nspec = \"haply:" + fake.url() + "\"\n");
  EXPECT_STATUS_DEVICE("haply:" + fake.url() +
                       " Inverse3 (right-handed) + VerseGrip: serial 049D, sensing 6 DOF, force 3 "
                       "DOF, limits 10 N 0 N m");
  EXPECT_GT(fake.forceCount(), 0u);  // the daemon's servo loop drives it
}
#endif

TEST_F(NetTest, PoseCommandsMoveTheSimDeviceThenTheStreamStopRampsAndLatchesAFault) {
  startDaemon();
  auto c = client();
  ASSERT_TRUE(c);
  ASSERT_TRUE(c->subscribe(1000));
  auto first = c->receiveState(10000);
  ASSERT_TRUE(first);
  ASSERT_TRUE(c->arm());
  const proto::WireVec3 start = first->X_WD.p;
  // +y: away from the peg-in-hole contact the idle hand rests in (its force pushes +y)
  const proto::WireVec3 target{start[0] + 0.01, start[1] + 0.05, start[2] + 0.005};
  const double d0 = dist(start, target);
  // stream the target at ~500 Hz until the device is within 10% of the first distance
  bool reached = false;
  std::uint64_t last_seq = 0;
  proto::State st;
  const auto end = SteadyClock::now() + std::chrono::seconds(30);
  while (!reached && SteadyClock::now() < end) {
    auto seq = c->sendPose(poseAt(target));
    ASSERT_TRUE(seq);
    last_seq = seq.value();
    auto s = c->receiveState(2);
    while (s) {
      st = *s;
      if (dist(s->X_WD.p, target) < 0.1 * d0 && s->last_command_sequence > 0)
        reached = true;
      s = c->receiveState(0);
    }
  }
  ASSERT_TRUE(reached) << "start " << start[0] << " " << start[1] << " " << start[2] << " contacts "
                       << st.contact_count << " force " << st.force_n[1] << " device at "
                       << st.X_WD.p[0] << " " << st.X_WD.p[1] << " " << st.X_WD.p[2];
  EXPECT_NE(st.state_flags & proto::kStateStreaming, 0u);
  EXPECT_EQ(st.fault_bits, 0u);
  EXPECT_LE(st.last_command_sequence, last_seq);

  // the stream stops: held, ramping (scale strictly between 0 and 1 seen), then the fault
  bool saw_ramp = false;
  ASSERT_TRUE(receiveUntil(
      *c,
      [&](const proto::State& s) {
        if ((s.state_flags & proto::kStateRamping) != 0 && s.force_scale > 0.0 &&
            s.force_scale < 1.0)
          saw_ramp = true;
        return (s.fault_bits & proto::kFaultStreamLost) != 0;
      },
      30.0, &st));
  EXPECT_TRUE(saw_ramp);
  EXPECT_TRUE(receiveUntil(*c, [](const proto::State& s) { return s.force_scale == 0.0; }));
  EXPECT_NE(statusJson()["faults"].get<std::string>().find("stream_lost"), std::string::npos);
  // a command while faulted is dropped; re-arm clears the fault
  const auto dropped_before = statusJson()["commands_dropped"].get<std::uint64_t>();
  ASSERT_TRUE(c->sendPose(poseAt(start)));
  EXPECT_TRUE(receiveUntil(*c, [](const proto::State&) { return true; }));
  ASSERT_TRUE(c->arm());
  EXPECT_TRUE(receiveUntil(*c, [](const proto::State& s) { return s.fault_bits == 0; }));
  EXPECT_GT(statusJson()["commands_dropped"].get<std::uint64_t>(), dropped_before);

  // disarm and arm through hapticctl
  CtlRun d = ctl({"disarm"});
  EXPECT_EQ(d.code, 0) << d.err;
  EXPECT_TRUE(receiveUntil(*c, [](const proto::State& s) {
    return (s.state_flags & proto::kStateArmed) == 0 && s.force_scale == 0.0;
  }));
  CtlRun a = ctl({"arm"});
  EXPECT_EQ(a.code, 0) << a.err;
  EXPECT_TRUE(receiveUntil(
      *c, [](const proto::State& s) { return (s.state_flags & proto::kStateArmed) != 0; }));
}

TEST_F(NetTest, AShmClientMovesTheSimDeviceThenTheStreamStopRampsAndLatchesAFault) {
  startDaemon();
  auto attached = proto::ShmClient::attach(shm_);
  ASSERT_TRUE(attached) << attached.error().message << "\n" << slurp(dir_ / "d.err");
  proto::ShmClient& c = attached.value();
  c.beat(proto::monotonicNs());
  proto::ShmState st{};
  for (int i = 0; i < 10000 && !c.readState(st); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GT(st.tick, 0u);
  ASSERT_TRUE(c.pushArm(proto::monotonicNs()));
  const proto::WireVec3 start{st.X_WD[0], st.X_WD[1], st.X_WD[2]};
  // +y: away from the peg-in-hole contact the idle hand rests in (as the UDP test)
  const proto::WireVec3 target{start[0] + 0.01, start[1] + 0.05, start[2] + 0.005};
  const double d0 = dist(start, target);
  bool reached = false;
  std::uint64_t seq = 0;
  for (int i = 0; i < 30000 && !reached; ++i) {  // ~1 kHz for at most ~30 s
    c.beat(proto::monotonicNs());
    (void)c.pushPose(poseAt(target), proto::monotonicNs(), &seq);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (c.readState(st) && st.last_command_sequence > 0 &&
        dist({st.X_WD[0], st.X_WD[1], st.X_WD[2]}, target) < 0.1 * d0)
      reached = true;
  }
  ASSERT_TRUE(reached) << "device at " << st.X_WD[0] << " " << st.X_WD[1] << " " << st.X_WD[2];
  EXPECT_NE(st.state_flags & proto::kStateStreaming, 0u);
  EXPECT_LE(st.last_command_sequence, seq);
  EXPECT_GT(st.last_command_sequence, 0u);
  EXPECT_EQ(st.fault_bits, 0u);

  const auto stop = hapticd::testing::awaitStreamStop(c, st);
  ASSERT_TRUE(stop.faulted);
  EXPECT_TRUE(stop.saw_ramp);
  EXPECT_EQ(st.force_scale, 0.0);
  // hapticctl sees the same latched fault (one gate for UDP and shm clients)
  EXPECT_NE(statusJson()["faults"].get<std::string>().find("stream_lost"), std::string::npos);
  ASSERT_TRUE(c.pushArm(proto::monotonicNs()));
  bool cleared = false;
  for (int i = 0; i < 30000 && !cleared; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    cleared = c.readState(st) && st.fault_bits == 0;
  }
  EXPECT_TRUE(cleared);

  // the segment is removed when the daemon ends
  kill(pid_, SIGTERM);
  EXPECT_EQ(waitExit(pid_, 60.0), 0) << slurp(dir_ / "d.err");
  pid_ = -1;
  const int fd = shm_open(shm_.c_str(), O_RDONLY, 0);
  EXPECT_LT(fd, 0) << shm_ << " still exists";
  if (fd >= 0)
    close(fd);
}

#ifdef HAPTICD_HAVE_SCENEGEN
// A scene with a body of every kind: a static floor, the probe (kinematic, held), a kinematic
// slider a client moves, a dynamic lid (no gravity: it stays where it is).
std::vector<std::uint8_t> editScene() {
  using hapticd::scenes::GltfBuilder;
  using hapticd::scenes::Json;
  using hapticd::scenes::jsonVec;
  GltfBuilder b;
  auto box = [&](const char* name, hapticd::scenes::Vec3 at, double size, Json motion, bool probe) {
    const int shape =
        b.addShape({{"type", "box"}, {"box", {{"size", jsonVec({size, size, size})}}}});
    Json physics = {{"collider", {{"geometry", {{"shape", shape}}}}}};
    if (!motion.is_null())
      physics["motion"] = motion;
    Json node = {{"name", name},
                 {"translation", jsonVec(at)},
                 {"extensions", {{"KHR_physics_rigid_bodies", physics}}}};
    if (probe)
      node["extras"] = {{"haptic", {{"probe", true}}}};
    b.addRoot(b.addNode(node));
  };
  box("Floor", {0.0, -0.5, 0.0}, 0.8, nullptr, false);
  box("Probe", {0.0, 0.1, 0.0}, 0.02, {{"isKinematic", true}}, true);
  box("Slider", {0.3, 0.1, 0.0}, 0.05, {{"isKinematic", true}}, false);
  box("Lid", {-0.3, 0.1, 0.0}, 0.05, {{"mass", 1.0}}, false);
  return b.finish("edits");
}

std::uint32_t bodyIndex(const hapticd::scene::SceneModel& m, const std::string& name) {
  for (std::size_t i = 0; i < m.bodies.size(); ++i)
    if (m.bodies[i].name == name)
      return static_cast<std::uint32_t>(i);
  ADD_FAILURE() << "no body " << name;
  return 0;
}

using hapticd::testing::listedBody;

TEST_F(NetTest, ASceneUpdateMovesARealKinematicBodyAndStatesListItAndItsContacts) {
  const auto bytes = editScene();
  std::ofstream(dir_ / "edits.glb", std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  auto report = hapticd::scene::loadScene(bytes, "edits.glb");
  ASSERT_TRUE(report.ok()) << report.message();
  const auto& model = *report.scene;
  const std::uint32_t floor = bodyIndex(model, "Floor"), slider = bodyIndex(model, "Slider"),
                      lid = bodyIndex(model, "Lid"), probe = bodyIndex(model, "Probe");
  startDaemon((dir_ / "edits.glb").string());
  auto c = client();
  ASSERT_TRUE(c);
  ASSERT_TRUE(c->subscribe(200, proto::kSubscribeBodies | proto::kSubscribeContacts));
  proto::State st;
  ASSERT_TRUE(receiveUntil(
      *c, [&](const proto::State& s) { return listedBody(s, slider) != nullptr; }, 30.0, &st));
  EXPECT_NEAR(listedBody(st, slider)->X_WB.p[0], 0.3, 1e-6);
  EXPECT_EQ(listedBody(st, floor), nullptr);  // static bodies are not listed
  EXPECT_NE(listedBody(st, lid), nullptr);
  EXPECT_EQ(st.contacts.size(), 0u);  // the probe touches nothing yet

  // refused, named, nothing changed
  proto::SceneUpdate bad;
  bad.poses.push_back({lid, {}});
  auto r = c->sceneUpdate(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("poses[0]: body " + std::to_string(lid) +
                                   " 'Lid' is dynamic, not kinematic"),
            std::string::npos)
      << r.error().message;
  bad.poses = {{slider, {}}, {floor, {}}};
  r = c->sceneUpdate(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(
      r.error().message.find("poses[1]: body " + std::to_string(floor) + " 'Floor' is static"),
      std::string::npos)
      << r.error().message;
  bad.poses = {{probe, {}}};
  EXPECT_FALSE(c->sceneUpdate(bad));
  bad.poses = {{static_cast<std::uint32_t>(model.bodies.size()), {}}};
  r = c->sceneUpdate(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("does not exist"), std::string::npos) << r.error().message;
  ASSERT_TRUE(receiveUntil(
      *c, [](const proto::State&) { return true; }, 30.0, &st));
  EXPECT_NEAR(listedBody(st, slider)->X_WB.p[0], 0.3, 1e-6);  // the slider did not move

  // moved: acknowledged, then listed at the new pose
  proto::SceneUpdate move;
  proto::WirePose to;
  to.p = {0.3, 0.25, 0.1};
  move.poses.push_back({slider, to});
  auto ok = c->sceneUpdate(move);
  ASSERT_TRUE(ok) << ok.error().message;
  ASSERT_TRUE(receiveUntil(
      *c,
      [&](const proto::State& s) {
        const auto* b = listedBody(s, slider);
        return b != nullptr && dist(b->X_WB.p, to.p) < 1e-9;
      },
      30.0, &st));

  // moved onto the probe: the state carries the contacts, and the minor-1 fields are filled
  const proto::WireVec3 probe_at = st.X_WP.p;
  move.poses[0].X_WB.p = {probe_at[0] + 0.03, probe_at[1], probe_at[2]};
  ASSERT_TRUE(c->sceneUpdate(move));
  ASSERT_TRUE(receiveUntil(
      *c, [](const proto::State& s) { return !s.contacts.empty(); }, 30.0, &st))
      << "contact_count " << st.contact_count;
  EXPECT_GT(st.contact_count, 0u);
  EXPECT_LE(st.contacts.size(), static_cast<std::size_t>(st.contact_count));
  if (proto::kVersionMinor >= 1) {
    EXPECT_GT(st.pairs_tested, 0u);
    EXPECT_GT(st.tick_ns, 0u);
  }

  // the same through hapticctl, as a user types it: move, a refusal with the daemon's text,
  // remove and add
  const std::string S = std::to_string(slider), L = std::to_string(lid);
  CtlRun mv = ctl({"move", S, "0.3", "0.25", "-0.1"});
  EXPECT_EQ(mv.code, 0) << mv.err;
  ASSERT_TRUE(receiveUntil(
      *c,
      [&](const proto::State& s) {
        const auto* b = listedBody(s, slider);
        return b != nullptr && dist(b->X_WB.p, proto::WireVec3{0.3, 0.25, -0.1}) < 1e-9;
      },
      30.0, &st));
  CtlRun no = ctl({"move", L, "0", "0", "0"});
  EXPECT_EQ(no.code, 1);
  EXPECT_NE(no.err.find("'Lid' is dynamic, not kinematic"), std::string::npos) << no.err;
  CtlRun rm = ctl({"remove", L});
  EXPECT_EQ(rm.code, 0) << rm.err;
  ASSERT_TRUE(receiveUntil(
      *c, [&](const proto::State& s) { return listedBody(s, lid) == nullptr; }, 30.0, &st));
  CtlRun ad = ctl({"add", L, "-0.3", "0.5", "0.2"});
  EXPECT_EQ(ad.code, 0) << ad.err;
  ASSERT_TRUE(receiveUntil(
      *c, [&](const proto::State& s) { return listedBody(s, lid) != nullptr; }, 30.0, &st));

  const auto j = statusJson();
  EXPECT_EQ(j["scene"], "edits.glb");
}
#endif

TEST_F(NetTest, HapticctlPoseReplayRecordAndWatch) {
  startDaemon();
  CtlRun p = ctl({"pose", "0.01", "0.02", "0.03", "--seconds", "1.0"});
  EXPECT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(p.out.rfind("device at ", 0), 0u) << p.out;

  std::ofstream(dir_ / "stream.csv") << "t,px,py,pz,qx,qy,qz,qw,buttons\n0,0,0,0,0,0,0,1,0\n"
                                        "0.05,0.001,0,0,0,0,0,1,0\n0.1,0.002,0,0,0,0,0,1,0\n";
  CtlRun r = ctl({"replay", (dir_ / "stream.csv").string(), "--rate", "200"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("replayed"), std::string::npos);
  std::ofstream(dir_ / "bad.csv") << "t,px,py,pz,qx,qy,qz,qw,buttons\n0,0,0,zero,0,0,0,1,0\n";
  CtlRun rb = ctl({"replay", (dir_ / "bad.csv").string()});
  EXPECT_EQ(rb.code, 2);
  EXPECT_NE(rb.err.find("bad.csv:2"), std::string::npos) << rb.err;

  CtlRun rec = ctl({"record", (dir_ / "rec.csv").string(), "--seconds", "0.5"});
  ASSERT_EQ(rec.code, 0) << rec.err;
  std::ifstream in(dir_ / "rec.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header,
            "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
            "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
            "pairs_skipped,tick_ns");
  std::string line;
  std::size_t rows = 0, timed_rows = 0;
  long long prev_tick = -1;
  while (std::getline(in, line)) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 26) << line;
    const long long tick = std::stoll(line.substr(0, line.find(',')));
    EXPECT_GT(tick, prev_tick);
    prev_tick = tick;
    ++rows;
    // every column is filled: the last, tick_ns, is the tick's compute time (> 0)
    const std::string tick_ns = line.substr(line.rfind(',') + 1);
    ASSERT_FALSE(tick_ns.empty()) << line;
    timed_rows += std::stoll(tick_ns) > 0 ? 1u : 0u;
  }
  EXPECT_GT(rows, 0u);
  EXPECT_EQ(timed_rows, rows);

  CtlRun w = ctl({"watch", "--count", "3", "--rate", "50"});
  EXPECT_EQ(w.code, 0) << w.err;
  EXPECT_EQ(std::count(w.out.begin(), w.out.end(), '\n'), 3) << w.out;
  EXPECT_NE(w.out.find("tick p50"), std::string::npos) << w.out;
  EXPECT_NE(w.out.find("faults"), std::string::npos);
}

TEST_F(NetTest, WithAKeyFileOnlyClientsWithTheKeyAreServed) {
  const std::string key = proto::keyToHex(proto::randomKey());
  std::ofstream(dir_ / "key") << key << "\n";
  std::ofstream(dir_ / "wrong") << proto::keyToHex(proto::randomKey()) << "\n";
  startDaemon(kSource + "/scenes/peg_in_hole.glb",
              "key_file = \"" + (dir_ / "key").string() + "\"\n");
  CtlRun keyed =
      ctl({"load", kSource + "/scenes/gears.glb", "--key-file", (dir_ / "key").string()});
  EXPECT_EQ(keyed.code, 0) << keyed.err;
  CtlRun st = ctl({"status", "--json", "--key-file", (dir_ / "key").string()});
  ASSERT_EQ(st.code, 0) << st.err;
  EXPECT_EQ(nlohmann::json::parse(st.out)["scene"], "gears.glb");
  CtlRun unkeyed = ctl({"load", kSource + "/scenes/dynamic.glb", "--timeout-ms", "500"});
  EXPECT_EQ(unkeyed.code, 1);
  CtlRun wrong = ctl({"arm", "--key-file", (dir_ / "wrong").string(), "--timeout-ms", "500"});
  EXPECT_EQ(wrong.code, 1);
  st = ctl({"status", "--json", "--key-file", (dir_ / "key").string()});
  ASSERT_EQ(st.code, 0) << st.err;
  const auto j = nlohmann::json::parse(st.out);
  EXPECT_EQ(j["scene"], "gears.glb");  // the unkeyed upload changed nothing
  std::uint64_t refused = 0;
  for (auto& [name, n] : j["refused"].items())
    refused += n.get<std::uint64_t>();
  EXPECT_GT(refused, 0u) << j.dump();
}

TEST_F(NetTest, NoDaemonAnswersIsExitOneWithAClearMessage) {
  port_ = 1;  // a privileged port no daemon of this test serves
  CtlRun r = ctl({"status", "--timeout-ms", "300"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no daemon at 127.0.0.1:1"), std::string::npos) << r.err;
  CtlRun l = ctl({"arm", "--timeout-ms", "300"});
  EXPECT_EQ(l.code, 1);
  EXPECT_NE(l.err.find("no daemon at 127.0.0.1:1"), std::string::npos) << l.err;
}

TEST_F(NetTest, TenClientsSubscribedAtOnceAllGetStatesAndTheFigures) {
  startDaemon();
  auto before = statusJson();
  std::vector<std::unique_ptr<proto::Client>> clients;
  for (int i = 0; i < 10; ++i) {
    clients.push_back(client("c" + std::to_string(i)));
    ASSERT_TRUE(clients.back());
    ASSERT_TRUE(clients.back()->subscribe(1000));
  }
  auto j = statusJson();
  EXPECT_EQ(j["subscribers"].get<std::uint32_t>(), 10u);
  for (auto& c : clients) {
    int got = 0;
    EXPECT_TRUE(receiveUntil(*c, [&](const proto::State&) { return ++got >= 20; }));
  }
  // let the daemon run a while with ten 1 kHz subscribers, draining every client
  const auto end = SteadyClock::now() + std::chrono::seconds(2);
  while (SteadyClock::now() < end)
    for (auto& c : clients)
      while (c->receiveState(0)) {
      }
  auto with10 = statusJson();

  // round trip: a pose command out, the state that echoes its sequence back
  auto& c0 = *clients[0];
  ASSERT_TRUE(c0.arm());
  std::vector<double> rtt_us;
  for (int i = 0; i < 300; ++i) {
    for (auto& c : clients)
      while (c->receiveState(0)) {
      }
    const auto t0 = SteadyClock::now();
    auto seq = c0.sendPose(poseAt({0.0, 0.0, 0.0}));
    ASSERT_TRUE(seq);
    if (receiveUntil(
            c0, [&](const proto::State& s) { return s.last_command_sequence >= seq.value(); }, 5.0))
      rtt_us.push_back(std::chrono::duration<double, std::micro>(SteadyClock::now() - t0).count());
  }
  ASSERT_FALSE(rtt_us.empty());
  std::sort(rtt_us.begin(), rtt_us.end());
  auto q = [&](double f) {
    return rtt_us[static_cast<std::size_t>(f * static_cast<double>(rtt_us.size() - 1))];
  };
  std::printf(
      "NetFigures: round trip pose -> state over UDP (10 clients at 1 kHz): n=%zu p50 %.1f us "
      "p99 %.1f us max %.1f us\n",
      rtt_us.size(), q(0.5), q(0.99), rtt_us.back());
  std::printf(
      "NetFigures: daemon tick compute before clients p50 %.1f us p99 %.1f us; "
      "with ten 1 kHz subscribers (cumulative histogram) p50 %.1f us p99 %.1f us max "
      "%.1f us; misses %llu\n",
      before["tick_ns"]["p50"].get<double>() / 1e3, before["tick_ns"]["p99"].get<double>() / 1e3,
      with10["tick_ns"]["p50"].get<double>() / 1e3, with10["tick_ns"]["p99"].get<double>() / 1e3,
      with10["tick_ns"]["max"].get<double>() / 1e3,
      static_cast<unsigned long long>(with10["tick_misses"].get<std::uint64_t>()));
  EXPECT_EQ(rtt_us.size(), 300u);  // every command's echo came back
}

}  // namespace
