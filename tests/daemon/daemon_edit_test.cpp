// runDaemon() in-process with fake backends (a scene of static, kinematic, dynamic, probe and
// inactive bodies; a simulation with the scene-edit contract), driven over UDP by proto::Client
// and over shared memory by proto::ShmClient: a scene update moving a kinematic body is
// acknowledged and later states list it at its new pose; bad updates get an Error naming the entry
// and change nothing; with a key only keyed peers change the scene; states carry contacts and the
// minor-1 fields; a shm client's commands drive the device, the segment's state echoes their
// sequence, a stopped stream ramps to zero and latches a fault until re-armed; shm = "" creates
// no segment; a segment that cannot be created, or one another live daemon holds, is a warning
// and the daemon runs; one whose server stopped beating is taken over. Waits are bounded by
// generous poll counts; no wall-clock duration is asserted.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "daemon/build_progress.h"
#include "daemon/daemon.h"
#include "protocol/auth.h"
#include "protocol/client.h"
#include "protocol/server.h"
#include "protocol/shm.h"
#include "tests/daemon/daemon_fixture.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

namespace fs = std::filesystem;
using testing::EditableSimulation;
using testing::FakeDevice;
using SteadyClock = std::chrono::steady_clock;

class DaemonEditTest : public ::testing::Test {
 protected:
  void SetUp() override { testing::blockDaemonSignals(); }

  std::string shmName() const {
    return "/hapticd-test-" + std::to_string(getpid()) + "-" + testing::testName();
  }

  Backends backends() {
    Backends b;
    b.make_device =
        [this](std::string_view,
               const device::DeviceOptions& options) -> Result<std::unique_ptr<device::Device>> {
      device_options_ = options;
      auto d = std::make_unique<FakeDevice>();
      d->depth_offset = 0.002;  // the wall is touched most of the time
      d->follow_commands = follow_commands_;
      d->on_home = [this](const geom::Pose& X) {  // servo thread; read after the run
        last_home_ = X;
        homes_set_.fetch_add(1, std::memory_order_release);
      };
      device_ = d.get();
      return std::unique_ptr<device::Device>(std::move(d));
    };
    b.load_scene = [](const Config&) -> Result<std::shared_ptr<const scene::SceneModel>> {
      return std::shared_ptr<const scene::SceneModel>(testing::editableSceneModel());
    };
    // an upload: the bytes as they arrived, kept for the test; "bad..." refused
    b.load_scene_bytes = [this](std::span<const std::uint8_t> bytes, const std::string& name,
                                const Config&) -> Result<std::shared_ptr<const scene::SceneModel>> {
      uploaded_.assign(bytes.begin(), bytes.end());
      if (name.rfind("slow", 0) == 0) {  // a long build (a decomposition): until released
        reportBuildProgress("loading scene '" + name +
                            "': decomposing mesh 1 (mesh 0 'Bunny'), 3 pieces, 0.5 s");
        while (!release_.load())
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      if (name.rfind("bad", 0) == 0)
        return Error{"scene '" + name + "': not a scene"};
      auto m = testing::editableSceneModel(name);
      if (name.rfind("moved", 0) == 0)  // the held body starts elsewhere
        m->bodies[static_cast<std::size_t>(m->probe_body)].X_WB.translation =
            geom::Vec3(0.5, 2.0, -3.0);
      return std::shared_ptr<const scene::SceneModel>(std::move(m));
    };
    b.make_simulation = [](std::shared_ptr<const scene::SceneModel> model,
                           const sim::SimOptions&) -> Result<std::unique_ptr<sim::Simulation>> {
      return std::unique_ptr<sim::Simulation>(std::make_unique<EditableSimulation>(model));
    };
    return b;
  }

  CommandLine cli(const std::string& shm) {
    CommandLine c;
    c.realtime = "off";
    c.status_file = (dir_ / "status.json").string();
    c.udp = "127.0.0.1:0";
    c.shm = shm;
    return c;
  }

  nlohmann::json status() { return testing::readStatus(dir_ / "status.json"); }
  bool waitStatus(const std::function<bool(const nlohmann::json&)>& pred) {
    return testing::waitForStatus(dir_ / "status.json", pred);
  }

  // Runs the daemon on this thread while `body` runs on another; body ends it with SIGTERM.
  int runWith(const CommandLine& c, const std::function<void()>& body) {
    std::thread helper([&] {
      if (waitStatus([](const nlohmann::json& j) {
            return j.value("tick", 0) > 50 && j.contains("network");
          }))
        body();
      else
        ADD_FAILURE() << "the daemon did not start";
      kill(getpid(), SIGTERM);
    });
    const int code = runDaemon(c, backends());
    helper.join();
    return code;
  }

  std::vector<std::uint8_t> uploaded_;  // what load_scene_bytes was given (builder thread)
  std::atomic<bool> release_{true};     // a "slow..." upload's build waits for it

  std::unique_ptr<proto::Client> client(std::optional<proto::Key> key = std::nullopt) {
    const std::string a = status()["network"]["udp"];
    proto::ClientConfig c;
    c.key = key;
    c.server = a;
    c.name = "daemon_edit_test";
    c.timeout_ms = 10000;
    auto r = proto::Client::connect(c);
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    return r ? std::move(r.value()) : nullptr;
  }

  static bool until(proto::Client& c,
                    const std::function<bool(const proto::State&)>& pred,
                    proto::State* last = nullptr) {
    return testing::receiveUntil(c, pred, 30.0, last);
  }

  testing::ScratchDir dir_{"hapticd_daemon_edit_test"};
  FakeDevice* device_ = nullptr;
  device::DeviceOptions device_options_;  // what the daemon opened the device with
  bool follow_commands_ = false;
  std::atomic<int> homes_set_{0};  // Device::setHome calls (servo thread)
  geom::Pose last_home_;           // the last one's pose
};

proto::WirePose wireAt(double x, double y, double z) {
  proto::WirePose p;
  p.p = {x, y, z};
  return p;
}

using testing::listedBody;

// an upload is built from its bytes as they arrived (no file in between), named by the upload;
// a refused one keeps the running scene and answers with the loader's text
TEST_F(DaemonEditTest, AnUploadIsBuiltFromItsBytes) {
  std::vector<std::uint8_t> bytes(70000);  // several chunks
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  const std::string tmp_before = [] {
    std::string names;
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
      if (e.path().filename().string().rfind("hapticd-upload-", 0) == 0)
        names += e.path().string() + " ";
    return names;
  }();
  EXPECT_EQ(runWith(cli(""),
                    [&] {
                      auto c = client();
                      ASSERT_TRUE(c);
                      auto ok = c->load(bytes, "uploaded.glb");
                      ASSERT_TRUE(ok) << ok.error().message;
                      EXPECT_EQ(uploaded_, bytes);
                      ASSERT_TRUE(waitStatus([](const nlohmann::json& j) {
                        return j["scene"]["name"] == "uploaded.glb";
                      }));
                      EXPECT_EQ(status()["scene"]["generation"], 2);
                      auto bad = c->load(bytes, "bad.glb");
                      ASSERT_FALSE(bad);
                      EXPECT_EQ(bad.error().message, "scene refused: scene 'bad.glb': not a scene");
                      EXPECT_EQ(status()["scene"]["name"], "uploaded.glb");
                    }),
            kExitOk);
  std::string tmp_after;
  for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
    if (e.path().filename().string().rfind("hapticd-upload-", 0) == 0)
      tmp_after += e.path().string() + " ";
  EXPECT_EQ(tmp_after, tmp_before);  // no upload file was left (none is written)
}

// while an upload builds for long, the running scene stays, a status reply (protocol 1.2) says
// what the build is doing, and another upload is refused at once with that progress
TEST_F(DaemonEditTest, AnUploadDuringALongBuildIsRefusedWithItsProgress) {
  release_ = false;
  const std::vector<std::uint8_t> bytes(100, 7);
  EXPECT_EQ(runWith(cli(""),
                    [&] {
                      auto first = client();
                      auto second = client();
                      ASSERT_TRUE(first && second);
                      std::thread slow([&] {
                        auto ok = first->load(bytes, "slow.glb");
                        EXPECT_TRUE(ok) << ok.error().message;
                      });
                      EXPECT_TRUE(waitStatus([](const nlohmann::json& j) {
                        return j.value("loading", std::string()).find("decomposing mesh 1") !=
                               std::string::npos;
                      }));
                      auto st = second->status();
                      EXPECT_TRUE(st) << st.error().message;
                      if (st) {
                        EXPECT_EQ(st.value().loading,
                                  "loading scene 'slow.glb': decomposing mesh 1 (mesh 0 'Bunny'), "
                                  "3 pieces, 0.5 s");
                        EXPECT_EQ(st.value().scene, "edits");  // the running scene stays
                      }
                      auto refused = second->load(bytes, "other.glb");
                      EXPECT_FALSE(refused);
                      if (!refused) {
                        EXPECT_NE(refused.error().message.find(
                                      "another scene is being built (loading scene 'slow.glb': "
                                      "decomposing mesh 1"),
                                  std::string::npos)
                            << refused.error().message;
                      }
                      release_ = true;
                      slow.join();
                      EXPECT_TRUE(waitStatus([](const nlohmann::json& j) {
                        return j["scene"]["name"] == "slow.glb" && j["loading"] == "";
                      }));
                      auto after = second->status();
                      ASSERT_TRUE(after);
                      EXPECT_EQ(after.value().loading, "");
                    }),
            kExitOk);
  release_ = true;
}

TEST_F(DaemonEditTest, ASceneUpdateMovingAKinematicBodyIsAckedAndLaterStatesListItThere) {
  const int code = runWith(cli(""), [&] {
    auto c = client();
    ASSERT_TRUE(c);
    ASSERT_TRUE(c->subscribe(200, proto::kSubscribeBodies));
    proto::State st;
    ASSERT_TRUE(until(
        *c, [](const proto::State& s) { return listedBody(s, 3) != nullptr; }, &st));
    EXPECT_EQ(listedBody(st, 3)->X_WB.p, (proto::WireVec3{3.0, 0.0, 0.0}));
    EXPECT_EQ(listedBody(st, 4), nullptr);  // inactive at the start

    proto::SceneUpdate u;
    u.poses.push_back({3, wireAt(3.0, 0.25, -0.5)});
    u.added.push_back({4, wireAt(0.0, 1.0, 2.0)});
    auto r = c->sceneUpdate(u);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(until(
        *c,
        [](const proto::State& s) {
          const auto* b = listedBody(s, 3);
          return b != nullptr && b->X_WB.p == proto::WireVec3{3.0, 0.25, -0.5};
        },
        &st));
    ASSERT_NE(listedBody(st, 4), nullptr);  // the same update, the same state
    EXPECT_EQ(listedBody(st, 4)->X_WB.p, (proto::WireVec3{0.0, 1.0, 2.0}));

    proto::SceneUpdate out;
    out.removed.push_back(4);
    ASSERT_TRUE(c->sceneUpdate(out));
    EXPECT_TRUE(until(*c, [](const proto::State& s) { return listedBody(s, 4) == nullptr; }));
    EXPECT_TRUE(waitStatus([](const nlohmann::json& j) {
      return j["edits"]["batches_applied"] == 2 && j["edits"]["entries_applied"] == 3;
    })) << status().dump();
    auto sr = c->status();  // the protocol's StatusReply (minor 1) counts them too
    ASSERT_TRUE(sr) << sr.error().message;
    EXPECT_EQ(sr.value().edit_batches_applied, 2u);
    EXPECT_EQ(sr.value().edits_applied, 3u);
    EXPECT_EQ(sr.value().edits_refused, 0u);
    EXPECT_EQ(sr.value().shm_flags, 0u);  // this daemon serves no shm
    EXPECT_TRUE(sr.value().shm_name.empty());
  });
  EXPECT_EQ(code, kExitOk);
}

TEST_F(DaemonEditTest, BadUpdatesGetAnErrorNamingTheEntryAndNothingChanges) {
  const int code = runWith(cli(""), [&] {
    auto c = client();
    ASSERT_TRUE(c);
    ASSERT_TRUE(c->subscribe(200, proto::kSubscribeBodies));
    auto refused = [&](const proto::SceneUpdate& u, const std::string& want) {
      auto r = c->sceneUpdate(u);
      ASSERT_FALSE(r) << "accepted: " << want;
      EXPECT_NE(r.error().message.find(want), std::string::npos) << r.error().message;
    };
    proto::SceneUpdate u;
    // a good entry first, then the bad one: the whole update is refused
    u.poses = {{3, wireAt(9.0, 9.0, 9.0)}, {3, wireAt(8.0, 8.0, 8.0)}, {2, wireAt(0, 0, 0)}};
    refused(u, "poses[2]: body 2 'lid' is dynamic, not kinematic");
    u = {};
    u.poses = {{17, wireAt(0, 0, 0)}};
    refused(u, "poses[0]: body 17 does not exist (scene 'edits' has 6 bodies");
    u = {};
    u.removed = {5, 0};
    refused(u, "removed[1]: body 0 'floor' is static");
    u = {};
    u.added = {{0, wireAt(0, 0, 0)}};
    refused(u, "added[0]: body 0 'floor' is static");
    u = {};
    u.poses = {{1, wireAt(0, 0, 0)}};
    refused(u, "poses[0]: body 1 'Probe' is the probe (held) body");
    u = {};
    proto::WirePose skew = wireAt(0, 0, 0);
    skew.q = {0.0, 0.0, 0.0, 1.0005};  // inside the wire's tolerance, so it reaches the daemon
    u.poses = {{3, skew}};
    EXPECT_TRUE(c->sceneUpdate(u));  // and it is normalised, not refused
    proto::State st;
    ASSERT_TRUE(until(
        *c,
        [](const proto::State& s) {
          const auto* b = listedBody(s, 3);
          return b != nullptr && b->X_WB.p == proto::WireVec3{0.0, 0.0, 0.0};
        },
        &st));
    EXPECT_NEAR(listedBody(st, 3)->X_WB.q[3], 1.0, 1e-12);
    // nothing of the refused updates reached the servo: only the last one was applied
    EXPECT_TRUE(waitStatus([](const nlohmann::json& j) {
      return j["edits"]["batches_applied"] == 1 && j["edits"]["entries_applied"] == 1;
    })) << status().dump();
    EXPECT_EQ(status()["edits"]["entries_refused"], 0);
    EXPECT_NE(listedBody(st, 5), nullptr);  // the crate was not removed by the refused update
  });
  EXPECT_EQ(code, kExitOk);
}

TEST_F(DaemonEditTest, WithAKeyOnlyAuthenticatedPeersChangeTheScene) {
  const proto::Key key = proto::randomKey();
  std::ofstream(dir_ / "key") << proto::keyToHex(key) << "\n";
  std::ofstream(dir_ / "hapticd.toml")
      << "[network]\nkey_file = \"" << (dir_ / "key").string() << "\"\n";
  CommandLine c = cli("");
  c.config_path = (dir_ / "hapticd.toml").string();
  const int code = runWith(c, [&] {
    proto::SceneUpdate u;
    u.poses.push_back({3, wireAt(3.0, 0.75, 0.0)});
    auto plain = client();
    ASSERT_TRUE(plain);
    auto r = plain->sceneUpdate(u);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("needs a tag"), std::string::npos) << r.error().message;
    auto keyed = client(key);
    ASSERT_TRUE(keyed);
    ASSERT_TRUE(keyed->subscribe(200, proto::kSubscribeBodies));
    // the refused update changed nothing: the slider is where the scene put it
    proto::State st;
    ASSERT_TRUE(until(
        *keyed, [](const proto::State& s) { return listedBody(s, 3) != nullptr; }, &st));
    EXPECT_EQ(listedBody(st, 3)->X_WB.p, (proto::WireVec3{3.0, 0.0, 0.0}));
    auto ok = keyed->sceneUpdate(u);
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_TRUE(until(*keyed, [](const proto::State& s) {
      const auto* b = listedBody(s, 3);
      return b != nullptr && b->X_WB.p == proto::WireVec3{3.0, 0.75, 0.0};
    }));
    EXPECT_TRUE(
        waitStatus([](const nlohmann::json& j) { return j["edits"]["batches_applied"] == 1; }));
  });
  EXPECT_EQ(code, kExitOk);
}

TEST_F(DaemonEditTest, StatesCarryContactsAndTheMinorOneFieldsWhileTheProbeTouches) {
  const int code = runWith(cli(""), [&] {
    auto c = client();
    ASSERT_TRUE(c);
    ASSERT_TRUE(c->subscribe(500, proto::kSubscribeContacts | proto::kSubscribeBodies));
    proto::State st;
    ASSERT_TRUE(until(
        *c, [](const proto::State& s) { return !s.contacts.empty(); }, &st));
    EXPECT_EQ(st.contacts.size(), 2u);  // the fake's two points per touch
    EXPECT_EQ(st.contact_count, 2u);
    EXPECT_EQ(st.contacts[0].n_W, (proto::WireVec3{0.0, 1.0, 0.0}));
    EXPECT_GT(st.contacts[0].depth_m, 0.0);
    EXPECT_EQ(st.bodies.size(), 4u);
    // the minor-1 fields reach the wire once the codec speaks minor 1 (the cli branch)
    if (proto::kVersionMinor >= 1) {
      EXPECT_EQ(st.pairs_tested, 3u);
      EXPECT_GT(st.max_penetration_m, 0.0);
      EXPECT_GT(st.tick_ns, 0u);
    }
    // the daemon side of them, whatever the codec: the status file
    EXPECT_TRUE(waitStatus([](const nlohmann::json& j) {
      return j["pairs_tested"].get<std::uint32_t>() > 0 &&
             j["last_tick_ns"].get<std::int64_t>() > 0;
    })) << status().dump();
  });
  EXPECT_EQ(code, kExitOk);
}

TEST_F(DaemonEditTest, AShmClientDrivesTheDeviceAndAStoppedStreamRampsThenFaultsUntilRearmed) {
  follow_commands_ = true;
  const int code = runWith(cli(shmName()), [&] {
    ASSERT_TRUE(status()["shm"]["serving"].get<bool>()) << status().dump();
    EXPECT_EQ(status()["shm"]["name"], shmName());
    auto attached = proto::ShmClient::attach(shmName());
    ASSERT_TRUE(attached) << attached.error().message;
    proto::ShmClient& shm = attached.value();
    shm.beat(proto::monotonicNs());
    ASSERT_TRUE(shm.pushArm(proto::monotonicNs()));
    proto::PoseCommand cmd;
    cmd.X_WT.p = {0.01, 0.02, 0.03};
    std::uint64_t seq = 0;
    proto::ShmState st{};
    bool followed = false;
    for (int i = 0; i < 20000 && !followed; ++i) {  // ~1 kHz, bounded
      shm.beat(proto::monotonicNs());
      (void)shm.pushPose(cmd, proto::monotonicNs(), &seq);  // a full ring just waits
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (shm.readState(st) && st.last_command_sequence == seq && st.X_WD[0] == 0.01 &&
          st.X_WD[1] == 0.02 && st.X_WD[2] == 0.03)
        followed = true;
    }
    ASSERT_TRUE(followed) << "last sequence " << st.last_command_sequence << " of " << seq;
    EXPECT_NE(st.state_flags & proto::kStateStreaming, 0u);
    EXPECT_NE(st.state_flags & proto::kStateArmed, 0u);
    EXPECT_EQ(st.fault_bits, 0u);

    // the stream stops (the heartbeat goes on): the ramp, then the latched fault
    const auto stop = testing::awaitStreamStop(shm, st);
    ASSERT_TRUE(stop.faulted);
    EXPECT_TRUE(stop.saw_ramp);
    EXPECT_EQ(st.force_scale, 0.0);
    EXPECT_EQ(st.force_n[0] * st.force_n[0] + st.force_n[1] * st.force_n[1] +
                  st.force_n[2] * st.force_n[2],
              0.0);
    // latched until re-armed, on the same gate the UDP clients use
    // (a read that meets the servo thread preempted mid-write fails: it is read again)
    for (int i = 0; i < 50; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      bool read = false;
      for (int t = 0; t < 1000 && !(read = shm.readState(st)); ++t)
        std::this_thread::yield();
      ASSERT_TRUE(read);
      EXPECT_NE(st.fault_bits & proto::kFaultStreamLost, 0u);
    }
    ASSERT_TRUE(shm.pushArm(proto::monotonicNs()));
    bool cleared = false;
    for (int i = 0; i < 30000 && !cleared; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      cleared = shm.readState(st) && st.fault_bits == 0;
    }
    EXPECT_TRUE(cleared);
    // the status (written every 0.5 s: read after the stream-stop part) sees the client
    EXPECT_TRUE(waitStatus([&](const nlohmann::json& j) {
      shm.beat(proto::monotonicNs());
      return j["shm"]["client_alive"].get<bool>() && j["shm"]["client_attached"].get<bool>();
    })) << status().dump();
    EXPECT_GT(status()["shm"]["commands"].get<std::uint64_t>(), 0u);
    EXPECT_EQ(status()["shm"]["commands_refused"].get<std::uint64_t>(), 0u);
    // the protocol's StatusReply (minor 1) says the same
    auto c = client();
    ASSERT_TRUE(c);
    auto sr = c->status();
    ASSERT_TRUE(sr) << sr.error().message;
    EXPECT_EQ(sr.value().shm_name, shmName());
    EXPECT_NE(sr.value().shm_flags & proto::kShmServing, 0u);
    EXPECT_NE(sr.value().shm_flags & proto::kShmClientAttached, 0u);
    EXPECT_GT(sr.value().shm_commands, 0u);
    EXPECT_EQ(sr.value().shm_commands_refused, 0u);
  });
  EXPECT_EQ(code, kExitOk);
  // unlinked at exit
  const int fd = shm_open(shmName().c_str(), O_RDONLY, 0);
  EXPECT_LT(fd, 0);
  if (fd >= 0)
    close(fd);
}

// Segments in /dev/shm whose header names this process as the server.
int segmentsServedByThisProcess() {
  int n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/dev/shm", ec)) {
    if (!e.is_regular_file(ec) || e.file_size(ec) < sizeof(proto::ShmHeader))
      continue;
    const int fd = open(e.path().c_str(), O_RDONLY);
    if (fd < 0)
      continue;
    void* p = mmap(nullptr, sizeof(proto::ShmHeader), PROT_READ, MAP_SHARED, fd, 0);
    close(fd);
    if (p == MAP_FAILED)
      continue;
    const auto* h = static_cast<const proto::ShmHeader*>(p);
    if (h->magic == proto::kShmMagic &&
        h->server_pid.load() == static_cast<std::uint64_t>(getpid()))
      ++n;
    munmap(p, sizeof(proto::ShmHeader));
  }
  return n;
}

TEST_F(DaemonEditTest, ShmOffCreatesNoSegment) {
  std::ofstream(dir_ / "hapticd.toml") << "[network]\nshm = \"\"\n";
  CommandLine c = cli("");
  c.shm.reset();  // from the file, not the command line
  c.config_path = (dir_ / "hapticd.toml").string();
  const int code = runWith(c, [&] {
    const auto j = status();
    EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
    EXPECT_EQ(j["shm"]["name"], "");
    EXPECT_EQ(segmentsServedByThisProcess(), 0);
  });
  EXPECT_EQ(code, kExitOk);
}

TEST_F(DaemonEditTest, ASegmentThatCannotBeCreatedIsAWarningAndTheDaemonRuns) {
  // a directory where the segment would go: shm_open(O_CREAT | O_EXCL) fails
  const fs::path blocker = fs::path("/dev/shm") / shmName().substr(1);
  fs::create_directory(blocker);
  ::testing::internal::CaptureStderr();
  const int code = runWith(cli(shmName()), [&] {
    const auto j = status();
    EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
    EXPECT_NE(j["shm"]["why_not"].get<std::string>().find(
                  blocker.string() + " is not a hapticd segment (a directory)"),
              std::string::npos)
        << j.dump();
    EXPECT_TRUE(waitStatus([](const nlohmann::json& s) { return s.value("tick", 0) > 200; }));
  });
  const std::string err = ::testing::internal::GetCapturedStderr();
  fs::remove(blocker);
  EXPECT_EQ(code, kExitOk);
  EXPECT_NE(err.find("[network] shm \"" + shmName() + "\""), std::string::npos) << err;
  EXPECT_NE(err.find("running without shared memory"), std::string::npos) << err;
}

// Forks a process that serves segment `name` (as another hapticd would) and beats once at
// `beat_age_ns` in the past (0: never beats); returns its pid, -1 on failure.
pid_t forkShmServer(const std::string& name, std::uint64_t beat_age_ns) {
  int ready[2];
  if (pipe(ready) != 0)
    return -1;
  const pid_t other = fork();
  if (other == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlives this test process
    auto s = proto::ShmServer::create(name);
    if (s && beat_age_ns != 0)
      s.value().beat(proto::monotonicNs() - beat_age_ns);
    const char ok = s ? '1' : '0';
    (void)!write(ready[1], &ok, 1);
    for (;;)
      pause();
  }
  char ok = 0;
  const bool started = other > 0 && read(ready[0], &ok, 1) == 1 && ok == '1';
  close(ready[0]);
  close(ready[1]);
  if (!started && other > 0) {
    kill(other, SIGKILL);
    waitpid(other, nullptr, 0);
  }
  return started ? other : -1;
}

TEST_F(DaemonEditTest, ASegmentWhoseServerStoppedBeatingIsTakenOver) {
  const pid_t other = forkShmServer(shmName(), 10'000'000'000ull);  // last beat 10 s ago
  ASSERT_GT(other, 0);
  const int code = runWith(cli(shmName()), [&] {
    const auto j = status();
    EXPECT_TRUE(j["shm"]["serving"].get<bool>()) << j.dump();
    auto c = proto::ShmClient::attach(shmName());
    ASSERT_TRUE(c) << c.error().message;
    proto::ShmState st{};
    bool fresh = false;
    for (int i = 0; i < 10000 && !fresh; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      fresh = c.value().readState(st) && st.tick > 0;
    }
    EXPECT_TRUE(fresh);  // this daemon's segment, not the old one
  });
  EXPECT_EQ(code, kExitOk);
  kill(other, SIGKILL);
  waitpid(other, nullptr, 0);
}

TEST_F(DaemonEditTest, ASegmentAnotherLiveDaemonServesIsLeftAlone) {
  const pid_t other = forkShmServer(shmName(), 1'000'000);  // alive, beat 1 ms ago
  ASSERT_GT(other, 0);
  ::testing::internal::CaptureStderr();
  const int code = runWith(cli(shmName()), [&] {
    const auto j = status();
    EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
    EXPECT_NE(j["shm"]["why_not"].get<std::string>().find(std::to_string(other)), std::string::npos)
        << j.dump();
  });
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, kExitOk);
  EXPECT_NE(err.find("served by another hapticd"), std::string::npos) << err;
  // the other one's segment is still there and still its own
  auto c = proto::ShmClient::attach(shmName());
  EXPECT_TRUE(c) << (c ? "" : c.error().message);
  kill(other, SIGKILL);
  waitpid(other, nullptr, 0);
  shm_unlink(shmName().c_str());
}

TEST_F(DaemonEditTest, TheSimHandStartsAtTheHeldBodysScenePoseUnlessConfiguredNot) {
  // device.sim_home_from_scene (default true): the sim device's home is the probe body's pose in
  // the scene (body 1 'Probe' at x = 1 in the editable scene), through the workspace mapping
  EXPECT_EQ(runWith(cli(""), [] {}), kExitOk);
  EXPECT_EQ(device_options_.sim_home.translation, geom::Vec3(1.0, 0.0, 0.0));
  EXPECT_EQ(device_options_.sim_home.rotation, geom::Pose{}.rotation);
  // off: the configured home (its default), whatever the scene says
  std::ofstream(dir_ / "home.toml") << "[device]\nsim_home_from_scene = false\n";
  CommandLine c = cli("");
  c.config_path = (dir_ / "home.toml").string();
  device_options_ = {};
  device_options_.sim_home.translation = geom::Vec3(-7.0);  // overwritten by the daemon
  EXPECT_EQ(runWith(c, [] {}), kExitOk);
  EXPECT_EQ(device_options_.sim_home.translation, device::DeviceOptions{}.sim_home.translation);
}

// A scene loaded later hands the device its held body's start (through the workspace mapping)
// when the servo takes it, so that the sim hand's idle motion moves around the new start
// (SimDevice.IdleMotionCentresOnTheNewHomeAfterSetHome holds the motion itself).
TEST_F(DaemonEditTest, ALoadedSceneGivesTheDeviceItsStartPose) {
  std::ofstream(dir_ / "ws.toml") << "[device]\nworkspace_translation_m = [0.0, 1.0, 0.0]\n";
  CommandLine c = cli("");
  c.config_path = (dir_ / "ws.toml").string();
  EXPECT_EQ(runWith(c,
                    [&] {
                      EXPECT_EQ(homes_set_.load(), 0);  // the first scene's start: at open
                      EXPECT_EQ(device_options_.sim_home.translation, geom::Vec3(1.0, -1.0, 0.0));
                      auto client_ = client();
                      ASSERT_TRUE(client_);
                      auto ok = client_->load(std::vector<std::uint8_t>(10, 1), "moved.glb");
                      ASSERT_TRUE(ok) << ok.error().message;
                      EXPECT_TRUE(testing::pollUntil(
                          [&] { return homes_set_.load(std::memory_order_acquire) == 1; }));
                    }),
            kExitOk);
  ASSERT_EQ(homes_set_.load(), 1);
  // the scene's (0.5, 2, -3) in device frame: minus the workspace translation
  EXPECT_EQ(last_home_.translation, geom::Vec3(0.5, 1.0, -3.0));
}

}  // namespace
}  // namespace hapticd::daemon
