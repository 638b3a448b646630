// The edges a user hits, each tried on the real hapticd binary as a new user would: a headless
// replay (virtual clock) while another hapticd holds the default port and segment, `--udp ""`
// and `[network] udp = ""`, a foreign file at the segment's name, shm readers beside a commander.
// Waits are bounded by polls and kills (a hang fails the test); no wall-clock duration is asserted.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/daemon/daemon_fixture.h"

namespace {

namespace fs = std::filesystem;
using hapticd::testing::ScratchDir;
using hapticd::testing::slurp;
const std::string kSource = HAPTICD_SOURCE_DIR;

// One hapticd child with its own output files and status file in the test's scratch folder.
class Hapticd {
 public:
  Hapticd(const ScratchDir& dir, std::string name) : dir_(dir), name_(std::move(name)) {}
  ~Hapticd() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      hapticd::testing::waitExit(pid_, 30.0);
    }
  }
  Hapticd(const Hapticd&) = delete;
  Hapticd& operator=(const Hapticd&) = delete;

  // exactly these arguments (no port or segment added) and --status-file
  void start(std::vector<std::string> args) {
    std::vector<std::string> all{HAPTICD_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"--status-file", file("status.json")});
    pid_ = hapticd::testing::spawn(all, dir_ / (name_ + ".out"), dir_ / (name_ + ".err"));
    ASSERT_GT(pid_, 0);
  }
  int wait(double limit_s = 240.0) {
    const int code = hapticd::testing::waitExit(pid_, limit_s);
    pid_ = -1;
    return code;
  }
  int run(std::vector<std::string> args) {
    start(std::move(args));
    return wait();
  }
  bool running() const { return pid_ > 0 && hapticd::testing::running(pid_); }
  void signal(int sig) const { kill(pid_, sig); }
  nlohmann::json status() const {
    return hapticd::testing::parseJsonOrEmpty(slurp(file("status.json")));
  }
  std::string err() const { return slurp(dir_ / (name_ + ".err")); }
  std::string file(const std::string& what) const { return (dir_ / (name_ + "." + what)).string(); }

 private:
  const ScratchDir& dir_;
  std::string name_;
  pid_t pid_ = -1;
};

// errno of a bind to 127.0.0.1:port (0: it bound, so nothing holds the port)
int bindErrno(std::uint16_t port) {
  const int s = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  const int rc = bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  const int e = rc == 0 ? 0 : errno;
  close(s);
  return e;
}

std::vector<std::string> replayArgs(const std::string& scene) {
  return {"--scene",  kSource + "/scenes/" + scene + ".glb",
          "--device", "replay:" + kSource + "/tests/streams/" + scene + ".csv",
          "--clock",  "virtual"};
}

// The README's headless replay, word for word but for the record path, while a real-clock
// hapticd on the defaults (UDP 127.0.0.1:47100, segment /hapticd) runs: the replay serves
// neither, so it neither fails on the port nor touches the other daemon's segment.
TEST(EdgesTest, VirtualClockReplayRunsBesideADaemonOnTheDefaultPortAndSegment) {
  ScratchDir dir("hapticd_edges_test");
  Hapticd real(dir, "real");
  real.start({"--realtime", "off"});
  // running on the defaults, or refused because something else holds the port already: either
  // way the default port is taken while the replay runs
  ASSERT_TRUE(hapticd::testing::pollUntil([&] {
    return !real.running() || real.status().value("tick", 0) > 50;
  })) << real.err();
  ASSERT_EQ(bindErrno(47100), EADDRINUSE) << real.err();
  const bool real_serves_shm = real.running() && real.status()["shm"].value("serving", false);

  Hapticd replay(dir, "replay");
  auto args = replayArgs("peg_in_hole");
  args.insert(args.end(), {"--record", replay.file("csv")});
  ASSERT_EQ(replay.run(args), 0) << replay.err();
  EXPECT_EQ(replay.err().find("Address already in use"), std::string::npos) << replay.err();
  EXPECT_EQ(replay.err().find("warning"), std::string::npos) << replay.err();
  const auto j = replay.status();
  EXPECT_EQ(j["network"]["udp"], "") << j.dump();
  EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
  EXPECT_GT(slurp(replay.file("csv")).size(), 100000u);

  if (real.running()) {
    // the real daemon kept its segment and still serves
    if (real_serves_shm) {
      EXPECT_TRUE(fs::exists("/dev/shm/hapticd"));
    }
    EXPECT_TRUE(real.status()["shm"].value("serving", false) == real_serves_shm);
    real.signal(SIGTERM);
    EXPECT_EQ(real.wait(), 0) << real.err();
  }
}

// A virtual-clock run still serves what it is asked to: --udp (here any free port).
TEST(EdgesTest, VirtualClockServesUdpWhenAskedOnTheCommandLine) {
  ScratchDir dir("hapticd_edges_test");
  Hapticd replay(dir, "replay");
  auto args = replayArgs("gears");
  args.insert(args.end(), {"--udp", "127.0.0.1:0"});
  ASSERT_EQ(replay.run(args), 0) << replay.err();
  const auto j = replay.status();
  const std::string udp = j["network"].value("udp", "");
  EXPECT_EQ(udp.rfind("127.0.0.1:", 0), 0u) << j.dump();
  EXPECT_NE(udp, "127.0.0.1:0") << j.dump();  // the port bound is named
  EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
}

// `--udp ""` turns UDP off on the real clock as `--shm ""` turns shared memory off; so does
// `[network] udp = ""` in the config file. The daemon then runs and stops as usual.
TEST(EdgesTest, EmptyUdpTurnsUdpOffOnTheCommandLineAndInTheConfigFile) {
  ScratchDir dir("hapticd_edges_test");
  {
    Hapticd d(dir, "cli");
    ASSERT_EQ(d.run({"--realtime", "off", "--ticks", "300", "--udp", "", "--shm", ""}), 0)
        << d.err();
    const auto j = d.status();
    EXPECT_EQ(j["tick"], 300);
    EXPECT_EQ(j["network"]["udp"], "") << j.dump();
    EXPECT_NE(j["network"].value("why_not", "").find("off"), std::string::npos) << j.dump();
    EXPECT_FALSE(j["shm"]["serving"].get<bool>());
    EXPECT_NE(d.err().find("network: UDP off"), std::string::npos) << d.err();
  }
  {
    std::ofstream(dir / "off.toml") << "[network]\nudp = \"\"\nshm = \"\"\n";
    Hapticd d(dir, "file");
    ASSERT_EQ(
        d.run({"--config", (dir / "off.toml").string(), "--realtime", "off", "--ticks", "300"}), 0)
        << d.err();
    EXPECT_EQ(d.status()["network"]["udp"], "") << d.status().dump();
    EXPECT_FALSE(d.status()["shm"]["serving"].get<bool>());
  }
  {
    // --check-config accepts it too; a malformed address is still refused, naming the key
    std::ofstream(dir / "bad.toml") << "[network]\nudp = \"nonsense\"\n";
    Hapticd d(dir, "bad");
    EXPECT_EQ(d.run({"--config", (dir / "bad.toml").string(), "--check-config"}), 2);
    EXPECT_NE(d.err().find("[network] udp"), std::string::npos) << d.err();
    Hapticd ok(dir, "ok");
    EXPECT_EQ(ok.run({"--config", (dir / "off.toml").string(), "--check-config"}), 0) << ok.err();
  }
}

// A file at /dev/shm/NAME that hapticd did not make (here: too small, another magic) is named in
// a warning with what was found, left exactly as it was, and the daemon runs without shared
// memory (docs/daemon.md "Shared memory").
TEST(EdgesTest, AForeignFileAtTheSegmentNameIsNamedInAWarningAndLeftAsItIs) {
  ScratchDir dir("hapticd_edges_test");
  const std::string name = "/hapticd-edges-test-" + std::to_string(getpid());
  const fs::path file = "/dev/shm" + name;
  struct Case {
    std::string content;
    std::string found;
  };
  const Case cases[] = {
      {"not a segment\n", "14 bytes, smaller than a segment header"},
      {std::string(65536, 'z'), "65536 bytes, magic 0x7a7a7a7a where a hapticd segment has"},
  };
  for (const Case& c : cases) {
    std::ofstream(file, std::ios::binary) << c.content;
    Hapticd d(dir, "foreign");
    ASSERT_EQ(d.run({"--realtime", "off", "--ticks", "300", "--udp", "", "--shm", name}), 0)
        << d.err();
    const std::string warning = "warning: [network] shm \"" + name + "\": " + file.string() +
                                " is not a hapticd segment (" + c.found;
    EXPECT_NE(d.err().find(warning), std::string::npos) << d.err();
    EXPECT_NE(d.err().find("left as it is; running without shared memory"), std::string::npos)
        << d.err();
    EXPECT_EQ(slurp(file), c.content);
    const auto j = d.status();
    EXPECT_FALSE(j["shm"]["serving"].get<bool>()) << j.dump();
    EXPECT_NE(j["shm"]["why_not"].get<std::string>().find("is not a hapticd segment"),
              std::string::npos)
        << j.dump();
    EXPECT_EQ(j["tick"], 300);
  }
  fs::remove(file);
}

// A `hapticctl watch --shm` (twice) during a `hapticctl replay --shm`: the replay commands
// through the segment, both watches read states beside it (read-only), all three exit 0.
TEST(EdgesTest, TwoShmWatchesDuringAShmReplay) {
  ScratchDir dir("hapticd_edges_test");
  const std::string name = "/hapticd-edges-readers-" + std::to_string(getpid());
  {
    // the first 6 s of the demo's stream
    std::ifstream in(kSource + "/tests/streams/peg_in_hole.csv");
    std::ofstream out(dir / "short.csv");
    std::string line;
    while (std::getline(in, line) && (line[0] == 't' || std::stod(line) <= 6.0))
      out << line << "\n";
  }
  Hapticd d(dir, "daemon");
  d.start({"--realtime", "off", "--udp", "127.0.0.1:0", "--shm", name, "--scene",
           kSource + "/scenes/peg_in_hole.glb"});
  ASSERT_TRUE(hapticd::testing::pollUntil([&] { return d.status().value("tick", 0) > 50; }))
      << d.err();
  const std::string udp = d.status()["network"]["udp"];
  const std::string port = udp.substr(udp.rfind(':') + 1);
  auto ctl = [&](const std::string& out_name, std::vector<std::string> args) {
    std::vector<std::string> all{HAPTICCTL_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"--shm=" + name, "--port", port});
    return hapticd::testing::spawn(all, dir / (out_name + ".out"), dir / (out_name + ".err"));
  };
  const pid_t replay = ctl("replay", {"replay", (dir / "short.csv").string(), "--quiet"});
  ASSERT_GT(replay, 0);
  // the replay is the segment's commander
  ASSERT_TRUE(hapticd::testing::pollUntil([&] {
    return d.status()["shm"].value("commands", 0) > 10;
  })) << d.status().dump()
      << slurp(dir / "replay.err");
  const pid_t w1 = ctl("watch1", {"watch", "--count", "20", "--rate", "1000", "--json"});
  const pid_t w2 = ctl("watch2", {"watch", "--count", "20", "--rate", "1000", "--json"});
  EXPECT_EQ(hapticd::testing::waitExit(w1, 60.0), 0) << slurp(dir / "watch1.err");
  EXPECT_EQ(hapticd::testing::waitExit(w2, 60.0), 0) << slurp(dir / "watch2.err");
  const bool replay_still_ran = hapticd::testing::running(replay);
  EXPECT_EQ(hapticd::testing::waitExit(replay, 120.0), 0) << slurp(dir / "replay.err");
  for (const char* w : {"watch1", "watch2"}) {
    const std::string text = slurp(dir / (std::string(w) + ".out"));
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 20) << w << ": " << text;
    EXPECT_NE(text.find("\"tick\""), std::string::npos) << text;
  }
  // the watches ran while the replay held the segment (a 6 s stream, 20 lines at 1 kHz)
  EXPECT_TRUE(replay_still_ran);
  const auto j = d.status();
  EXPECT_GT(j["shm"].value("commands", 0), 100) << j.dump();
  EXPECT_EQ(j["shm"].value("commands_refused", 1), 0) << j.dump();
  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(), 0) << d.err();
}

}  // namespace
