// runDaemon() in-process with fake backends: start, status (the status file), stop on SIGTERM
// with the force ramp, reload on SIGHUP with good and bad scenes and configs, realtime refused
// (prefer runs with a warning, require refuses to start), device lost and back, headless replay
// on the virtual clock with a record.
#include "daemon/daemon.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "daemon/build_progress.h"
#include "protocol/messages.h"
#include "tests/daemon/daemon_fixture.h"
#include "tests/daemon/fakes.h"

namespace hapticd::daemon {
namespace {

namespace fs = std::filesystem;
using testing::FakeDevice;
using testing::FakeSimulation;

// A scratch folder per test.
class DaemonTest : public ::testing::Test {
 protected:
  // every thread of this process blocks the daemon's signals; runDaemon takes them
  void SetUp() override { testing::blockDaemonSignals(); }

  Backends fakeBackends() {
    Backends b;
    b.make_device = [this](
                        std::string_view spec,
                        const device::DeviceOptions&) -> Result<std::unique_ptr<device::Device>> {
      if (spec == "missing")
        return Error{"no such device"};
      auto d = std::make_unique<FakeDevice>();
      if (spec.rfind("end:", 0) == 0)
        d->end_after = std::stoull(std::string(spec.substr(4)));
      d->depth_offset = 0.002;
      d->on_close = [this](const FakeDevice& closed) {
        reads_at_close_ = closed.reads;
        if (device_ == &closed)
          device_ = nullptr;  // never read through a pointer to a destroyed device
      };
      ++devices_opened_;
      device_ = d.get();
      return std::unique_ptr<device::Device>(std::move(d));
    };
    // [scene] path "good:NAME" is a scene called NAME; anything else is refused
    b.load_scene = [](const Config& c) -> Result<std::shared_ptr<const scene::SceneModel>> {
      const std::string& p = c.scene.path.empty() ? "good:" + c.scene.demo : c.scene.path;
      if (p.rfind("good:", 0) != 0)
        return Error{"file '" + p + "': not a scene"};
      auto m = std::make_shared<scene::SceneModel>();
      m->name = p.substr(5);
      m->bodies.resize(2);
      m->bodies[0].name = "Probe";
      m->bodies[1].name = "Box";
      return std::shared_ptr<const scene::SceneModel>(m);
    };
    b.make_simulation = [](std::shared_ptr<const scene::SceneModel>,
                           const sim::SimOptions&) -> Result<std::unique_ptr<sim::Simulation>> {
      return std::unique_ptr<sim::Simulation>(std::make_unique<FakeSimulation>());
    };
    return b;
  }

  // memory locking granted, SCHED_FIFO refused
  Backends fifoRefusedBackends() {
    Backends b = fakeBackends();
    b.realtime.lock_memory = [](int) { return 0; };
    b.realtime.set_fifo = [](int) { return EPERM; };
    return b;
  }

  nlohmann::json status() { return testing::readStatus(dir_ / "status.json"); }

  // waits (bounded by a generous count of polls, never asserting a duration) for a status
  bool waitFor(const std::function<bool(const nlohmann::json&)>& pred) {
    return testing::waitForStatus(dir_ / "status.json", pred);
  }

  void writeConfig(const std::string& text) { std::ofstream(dir_ / "hapticd.toml") << text; }

  CommandLine baseCli() {
    CommandLine cli;
    cli.realtime = "off";
    cli.status_file = (dir_ / "status.json").string();
    cli.udp = "127.0.0.1:0";  // the network thread on any free port
    cli.shm = "";             // no shared memory (daemon_edit_test covers it)
    return cli;
  }

  testing::ScratchDir dir_{"hapticd_daemon_test"};
  FakeDevice* device_ = nullptr;
  std::size_t devices_opened_ = 0;    ///< how many devices the daemon made
  std::uint64_t reads_at_close_ = 0;  ///< the last destroyed device's read count
};

TEST_F(DaemonTest, StartsServesAndStopsOnSigtermWithTheRampThenExitsZero) {
  CommandLine cli = baseCli();
  std::thread helper([&] {
    ASSERT_TRUE(waitFor([](const auto& j) { return j.value("tick", 0) > 200; }));
    const auto j = status();
    EXPECT_EQ(j["phase"], "running");
    EXPECT_TRUE(j["device"]["connected"].get<bool>());
    EXPECT_EQ(j["scene"]["name"], "peg_in_hole");  // the built-in demo by default
    EXPECT_GT(j["peak_force_n"].get<double>(), 0.5);
    kill(getpid(), SIGTERM);
  });
  const int code = runDaemon(cli, fakeBackends());
  helper.join();
  EXPECT_EQ(code, kExitOk);
  const auto j = status();
  EXPECT_EQ(j["phase"], "stopped");
  EXPECT_TRUE(j["stopping"].get<bool>());
  EXPECT_FALSE(j["running"].get<bool>());
  EXPECT_EQ(j["output_gain"].get<double>(), 0.0);
  EXPECT_EQ(j["force_n"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(devices_opened_, 1u);
  EXPECT_EQ(device_, nullptr);  // closed on the way out
}

TEST_F(DaemonTest, SighupReloadsGoodScenesAndKeepsTheOldOnBadScenesAndConfigs) {
  writeConfig("[scene]\npath = \"good:first\"\n");
  CommandLine cli = baseCli();
  cli.config_path = (dir_ / "hapticd.toml").string();
  std::thread helper([&] {
    ASSERT_TRUE(waitFor([](const auto& j) { return j.value("tick", 0) > 10; }));
    EXPECT_EQ(status()["scene"]["name"], "first");

    writeConfig("[scene]\npath = \"broken.glb\"\n");  // a scene the loader refuses
    kill(getpid(), SIGHUP);
    ASSERT_TRUE(waitFor([](const auto& j) {
      return j["last_reload"].template get<std::string>().find("refused") != std::string::npos;
    }));
    auto j = status();
    EXPECT_NE(j["last_reload"].get<std::string>().find("broken.glb"), std::string::npos);
    EXPECT_EQ(j["scene"]["name"], "first");
    EXPECT_EQ(j["scene"]["generation"], 1);

    writeConfig("[scene]\npath = \"good:second\"\n");
    kill(getpid(), SIGHUP);
    ASSERT_TRUE(waitFor([](const auto& s) { return s["scene"]["generation"] == 2; }));
    EXPECT_EQ(status()["scene"]["name"], "second");

    writeConfig("[scene]\npath = \"good:third\"\nbogus_key = 1\n");  // a bad config
    kill(getpid(), SIGHUP);
    ASSERT_TRUE(waitFor([](const auto& s) {
      return s["last_reload"].template get<std::string>().find("bogus_key") != std::string::npos;
    }));
    j = status();
    EXPECT_NE(j["last_reload"].get<std::string>().find("hapticd.toml:3"), std::string::npos);
    EXPECT_EQ(j["scene"]["name"], "second");
    EXPECT_EQ(j["scene"]["generation"], 2);
    kill(getpid(), SIGTERM);
  });
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitOk);
  helper.join();
}

// A reload whose scene takes long to build (a decomposition): the old scene keeps ticking, the
// status file says what the build is doing, and the new scene replaces the old when it is ready.
// The fake loader of "slow:NAME" reports progress and waits for the test's word (no clock).
TEST_F(DaemonTest, ALongBuildKeepsTheOldSceneTickingAndShowsItsProgress) {
  std::atomic<bool> release{false};
  Backends backends = fakeBackends();
  const auto good = backends.load_scene;
  backends.load_scene = [&](const Config& c) {
    if (c.scene.path.rfind("slow:", 0) != 0)
      return good(c);
    reportBuildProgress("loading scene 'slow': decomposing mesh 1 (mesh 0 'Bunny'), 3 pieces");
    while (!release.load())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    Config named = c;
    named.scene.path = "good:" + c.scene.path.substr(5);
    return good(named);
  };
  writeConfig("[scene]\npath = \"good:first\"\n");
  CommandLine cli = baseCli();
  cli.config_path = (dir_ / "hapticd.toml").string();
  std::thread helper([&] {
    ASSERT_TRUE(waitFor([](const auto& j) { return j.value("tick", 0) > 10; }));
    EXPECT_EQ(status()["loading"], "");
    writeConfig("[scene]\npath = \"slow:second\"\n");
    kill(getpid(), SIGHUP);
    ASSERT_TRUE(waitFor([](const auto& j) {
      return j.value("loading", std::string()).find("decomposing mesh 1") != std::string::npos;
    }));
    const auto before = status()["tick"].get<std::uint64_t>();
    // the servo loop runs the old scene meanwhile: its ticks go on, it is still the scene
    ASSERT_TRUE(waitFor([&](const auto& j) { return j.value("tick", 0ull) > before + 200; }));
    auto j = status();
    EXPECT_EQ(j["scene"]["name"], "first");
    EXPECT_EQ(j["scene"]["generation"], 1);
    EXPECT_NE(j["loading"].get<std::string>().find("loading scene 'slow': decomposing mesh 1"),
              std::string::npos)
        << j["loading"];
    release = true;
    ASSERT_TRUE(waitFor([](const auto& s) { return s["scene"]["generation"] == 2; }));
    j = status();
    EXPECT_EQ(j["scene"]["name"], "second");
    EXPECT_TRUE(waitFor([](const auto& s) { return s["loading"] == ""; }));
    kill(getpid(), SIGTERM);
  });
  EXPECT_EQ(runDaemon(cli, backends), kExitOk);
  release = true;
  helper.join();
}

TEST_F(DaemonTest, RealtimeRefusedUnderPreferRunsWithAWarning) {
  Backends b = fakeBackends();
  b.realtime.lock_memory = [](int) { return EPERM; };
  b.realtime.set_fifo = [](int) { return EPERM; };
  b.realtime.pin_to_cpu = [](int) { return EINVAL; };
  CommandLine cli = baseCli();
  cli.realtime = "prefer";
  cli.cpu = 0;
  cli.ticks = 300;
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, b), kExitOk);
  const std::string err = ::testing::internal::GetCapturedStderr();
  if (memoryLockingSupported())
    EXPECT_NE(err.find("warning: realtime = \"prefer\": mlockall"), std::string::npos) << err;
  else  // AddressSanitizer
    EXPECT_NE(err.find("warning: mlockall skipped"), std::string::npos) << err;
  EXPECT_NE(err.find("warning: realtime = \"prefer\": SCHED_FIFO priority 80 refused"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("pinning the servo thread to CPU 0 refused"), std::string::npos) << err;
  const auto j = status();
  EXPECT_EQ(j["tick"], 300);
  EXPECT_FALSE(j["realtime"]["fifo"].get<bool>());
  EXPECT_FALSE(j["realtime"]["memory_locked"].get<bool>());
  EXPECT_EQ(j["realtime"]["servo_scheduling"], "SCHED_OTHER");
}

TEST_F(DaemonTest, RealtimeRefusedUnderRequireRefusesToStart) {
  Backends b = fifoRefusedBackends();
  CommandLine cli = baseCli();
  cli.realtime = "require";
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, b), kExitFailure);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("realtime = \"require\": SCHED_FIFO priority 80 refused"), std::string::npos)
      << err;
}

TEST_F(DaemonTest, CheckConfigRunsTheRealtimeAndSceneStepsAndStartsNothing) {
  Backends b = fifoRefusedBackends();
  CommandLine cli = baseCli();
  cli.realtime = "require";
  cli.check_config = true;
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, b), kExitFailure);  // as RealtimeRefusedUnderRequireRefusesToStart
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("realtime = \"require\": SCHED_FIFO priority 80 refused"), std::string::npos)
      << err;
  ASSERT_EQ(devices_opened_, 1u);  // the steps before it ran, in start-up's order
  EXPECT_EQ(device_, nullptr);     // and it was closed again
  EXPECT_EQ(reads_at_close_, 0u);
  devices_opened_ = 0;

  cli = baseCli();
  cli.check_config = true;
  cli.scene = "nothing.glb";  // the fake loader refuses it, as at start-up
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitFailure);
  err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("cannot load the scene: file 'nothing.glb'"), std::string::npos) << err;

  cli = baseCli();
  cli.check_config = true;
  devices_opened_ = 0;
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitOk);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(out, "configuration ok (built-in defaults): scene 'peg_in_hole', device 'sim'\n");
  ASSERT_EQ(devices_opened_, 1u);  // the sim device is opened (it has no effect outside)
  EXPECT_EQ(reads_at_close_, 0u);
  EXPECT_FALSE(fs::exists(dir_ / "status.json"));  // nothing ran
}

TEST_F(DaemonTest, DeviceLostAndBack) {
  CommandLine cli = baseCli();
  std::thread helper([&] {
    ASSERT_TRUE(waitFor([](const auto& j) { return j.value("tick", 0) > 50; }));
    device_->lost_flag = true;
    ASSERT_TRUE(
        waitFor([](const auto& s) { return !s["device"]["connected"].template get<bool>(); }));
    auto j = status();
    EXPECT_EQ(j["device"]["lost_count"], 1);
    EXPECT_EQ(j["force_n"], nlohmann::json({0.0, 0.0, 0.0}));
    device_->lost_flag = false;
    ASSERT_TRUE(
        waitFor([](const auto& s) { return s["device"]["connected"].template get<bool>(); }));
    EXPECT_EQ(status()["device"]["lost_count"], 1);
    kill(getpid(), SIGTERM);
  });
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitOk);
  helper.join();
}

TEST_F(DaemonTest, VirtualClockReplayEndsAtTheEndOfTheStreamWithARecord) {
  CommandLine cli = baseCli();
  cli.device = "end:5000";
  cli.clock = "virtual";
  cli.record = (dir_ / "out.csv").string();
  cli.record_bodies = (dir_ / "bodies.csv").string();
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitOk);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("hapticd: end of stream: 5000 ticks, 5.000 s simulated time"),
            std::string::npos)
      << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1);  // a one-line summary
  std::ifstream rec(dir_ / "out.csv");
  std::string header, line;
  std::getline(rec, header);
  EXPECT_EQ(header,
            "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
            "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
            "pairs_skipped,tick_ns");
  int rows = 0;
  while (std::getline(rec, line))
    ++rows;
  EXPECT_EQ(rows, 5000);
  std::ifstream bodies(dir_ / "bodies.csv");
  std::getline(bodies, header);
  EXPECT_EQ(header, "tick,t,body,px,py,pz,qx,qy,qz,qw");
  std::getline(bodies, line);
  EXPECT_EQ(line.rfind("0,0,Probe,", 0), 0u) << line;
  std::getline(bodies, line);
  EXPECT_EQ(line.rfind("0,0,Box,", 0), 0u) << line;
}

// a fault has a name in the log, the status line and the summary, and one number (the
// protocol's) wherever a number is shown; the summary counts the faults latched over the run
TEST_F(DaemonTest, FaultsAreNamedAndNumberedAsOnTheWire) {
  Backends b = fakeBackends();
  b.make_simulation = [](std::shared_ptr<const scene::SceneModel>,
                         const sim::SimOptions&) -> Result<std::unique_ptr<sim::Simulation>> {
    auto s = std::make_unique<FakeSimulation>();
    s->nan_at_step = 100;
    return std::unique_ptr<sim::Simulation>(std::move(s));
  };
  CommandLine cli = baseCli();
  cli.device = "end:500";
  cli.clock = "virtual";
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, b), kExitOk);
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("warning: fault latched at tick 99: not_finite: "), std::string::npos) << err;
  EXPECT_NE(out.find(", faults not_finite (latched 1 times since start: not_finite), "),
            std::string::npos)
      << out;
  const auto j = status();
  EXPECT_EQ(j["faults"]["bits"], proto::kFaultNotFinite);
  EXPECT_EQ(j["faults"]["names"], "not_finite");
  EXPECT_TRUE(j["faults"]["non_finite"].get<bool>());
  EXPECT_EQ(j["faults"]["latched_since_start"], 1);
  EXPECT_EQ(faultNames(kFaultStreamLost | kFaultMisses), "stream_lost,tick_overrun");
  EXPECT_EQ(faultNames(0), "none");
}

TEST_F(DaemonTest, AnAddressInUseIsRefusedNamingTheKey) {
  const int sock = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(sock, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(getsockname(sock, reinterpret_cast<sockaddr*>(&a), &len), 0);
  CommandLine cli = baseCli();
  cli.udp = "127.0.0.1:" + std::to_string(ntohs(a.sin_port));
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitFailure);
  const std::string err = ::testing::internal::GetCapturedStderr();
  close(sock);
  EXPECT_NE(err.find("error: [network] udp " + *cli.udp + ": "), std::string::npos) << err;
  EXPECT_EQ(err.find("protocol."), std::string::npos) << err;  // no key that does not exist
}

TEST_F(DaemonTest, StartupFailuresAreClearAndExitNonZero) {
  CommandLine cli = baseCli();
  cli.device = "missing";
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitFailure);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("device: no such device"),
            std::string::npos);

  cli = baseCli();
  cli.scene = "nothing.glb";
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitFailure);
  EXPECT_NE(
      ::testing::internal::GetCapturedStderr().find("cannot load the scene: file 'nothing.glb'"),
      std::string::npos);

  writeConfig("[servo]\nrate_hz = -3\n");
  cli = baseCli();
  cli.config_path = (dir_ / "hapticd.toml").string();
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(runDaemon(cli, fakeBackends()), kExitBadConfig);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("hapticd.toml:2: [servo] rate_hz"),
            std::string::npos);
}

}  // namespace
}  // namespace hapticd::daemon
