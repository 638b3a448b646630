// hapticctl's daemon commands (client/daemon_commands.h) called as a library against fakes of
// the daemon (tests/client/fake_daemon.h): an in-process proto::Server on loopback with
// recording handlers, and an in-process ShmServer. Contents and order are asserted, never
// timing.
#include "client/daemon_commands.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <thread>
#include <tuple>

#include "client/state_format.h"
#include "core/scene/loader.h"
#include "protocol/auth.h"
#include "protocol/udp.h"
#include "tests/client/fake_daemon.h"

namespace hapticd::client {
namespace {

using testing::FakeDaemon;
using testing::FakeShmDaemon;
using testing::stateFor;

std::filesystem::path tempFile(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("hapticctl-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string f;
  while (std::getline(in, f, ','))
    out.push_back(f);
  if (!line.empty() && line.back() == ',')
    out.emplace_back();
  return out;
}

// The rows of a CSV file whose first line must be `header`, each split into fields; a row whose
// field count differs from the header's is reported and left out.
std::vector<std::vector<std::string>> csvRows(const std::filesystem::path& file,
                                              const std::string& header) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, header) << file;
  const std::size_t columns = split(header).size();
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    auto f = split(line);
    EXPECT_EQ(f.size(), columns) << line;
    if (f.size() == columns)
      rows.push_back(std::move(f));
  }
  return rows;
}

double num(const std::string& s) {
  return std::strtod(s.c_str(), nullptr);
}

std::array<double, 4> aboutZ(double deg) {
  const double h = 0.5 * deg * std::numbers::pi / 180.0;
  return {0.0, 0.0, std::sin(h), std::cos(h)};
}
double rotationGap(const std::array<double, 4>& q, const std::array<double, 4>& r) {
  return 1.0 - std::fabs(q[0] * r[0] + q[1] * r[1] + q[2] * r[2] + q[3] * r[3]);
}

// the lines of `text`, each parsed as JSON
std::vector<nlohmann::json> jsonLines(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
    out.push_back(nlohmann::json::parse(line));
  return out;
}

// ---- record ---------------------------------------------------------------------------------

struct RecordCheck {
  std::size_t rows = 0;
  std::uint64_t gaps = 0;                    // ticks missing between rows, counted from the file
  std::vector<std::uint64_t> missing_ticks;  // state ticks (1-based)
};

// Reads a record file and checks every column of every row against stateFor(tick)
// (device pose from `device` when given).
RecordCheck checkRecord(const std::filesystem::path& file,
                        const proto::WirePose* device = nullptr) {
  RecordCheck c;
  EXPECT_EQ(split(recordHeader()).size(), 27u);
  std::uint64_t prev = 0;
  for (const auto& f : csvRows(file, recordHeader())) {
    const std::uint64_t tick = std::stoull(f[0]) + 1;  // the record's tick is State::tick − 1
    if (c.rows > 0) {
      EXPECT_GT(tick, prev) << "rows out of tick order";
      for (std::uint64_t m = prev + 1; m < tick; ++m)
        c.missing_ticks.push_back(m);
      c.gaps += tick - prev - 1;
    }
    prev = tick;
    ++c.rows;
    const proto::State s = stateFor(tick);
    const proto::WirePose& d = device ? *device : s.X_WD;
    const std::vector<double> want{static_cast<double>(s.sim_time_ns) * 1e-9,
                                   d.p[0],
                                   d.p[1],
                                   d.p[2],
                                   d.q[0],
                                   d.q[1],
                                   d.q[2],
                                   d.q[3],
                                   s.X_WP.p[0],
                                   s.X_WP.p[1],
                                   s.X_WP.p[2],
                                   s.X_WP.q[0],
                                   s.X_WP.q[1],
                                   s.X_WP.q[2],
                                   s.X_WP.q[3],
                                   s.force_n[0],
                                   s.force_n[1],
                                   s.force_n[2],
                                   s.torque_nm[0],
                                   s.torque_nm[1],
                                   s.torque_nm[2],
                                   static_cast<double>(s.contact_count),
                                   s.max_penetration_m,
                                   static_cast<double>(s.pairs_tested),
                                   static_cast<double>(s.pairs_skipped),
                                   static_cast<double>(s.tick_ns)};
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_FALSE(f[i + 1].empty()) << "column " << i + 1 << " empty in the row of tick " << f[0];
      EXPECT_EQ(num(f[i + 1]), want[i]) << "column " << i + 1 << " of tick " << tick;
    }
  }
  return c;
}

std::uint64_t reportedMissing(const std::string& out) {
  const auto at = out.find(" ticks missing");
  if (at == std::string::npos)
    return ~0ull;
  const auto start = out.rfind(' ', at - 1);
  return std::stoull(out.substr(start + 1, at - start - 1));
}

// `hapticctl record` of `seconds` into the temp file `name` (and the body poses into the temp
// file `bodies`, when given): its exit code, what it said, the files
struct Recorded {
  int rc = -1;
  std::string out, err, file, bodies_file;
};
Recorded record(const DaemonTarget& t,
                const std::string& name,
                double seconds,
                const std::string& bodies = "") {
  RecordOptions o;
  o.file = tempFile(name).string();
  o.bodies_file = bodies.empty() ? "" : tempFile(bodies).string();
  o.seconds = seconds;
  std::ostringstream out, err;
  const int rc = runRecord(t, o, out, err);
  return {rc, out.str(), err.str(), o.file, o.bodies_file};
}

TEST(DaemonCommands, RecordWritesEveryColumnWithTheDaemonsValuesAndCountsMissingTicks) {
  FakeDaemon d(/*tick_rate_hz=*/500, /*skip_every=*/7);  // ticks 7, 14, 21, ... never shown
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Recorded r = record(d.target(), "rec.csv", 0.3);
  ASSERT_EQ(r.rc, 0) << r.err;
  const RecordCheck c = checkRecord(r.file);
  ASSERT_GT(c.rows, 20u);
  // every tick the fake never showed is missing, and every missing tick is counted
  ASSERT_GT(c.gaps, 0u);
  std::uint64_t first = 0, last = 0;
  {
    std::ifstream in(r.file);
    std::string line;
    std::getline(in, line);
    bool any = false;
    while (std::getline(in, line)) {
      last = std::stoull(line.substr(0, line.find(','))) + 1;
      if (!any)
        first = last;
      any = true;
    }
  }
  for (std::uint64_t k = first; k <= last; ++k) {
    if (k % 7 == 0) {
      EXPECT_NE(std::find(c.missing_ticks.begin(), c.missing_ticks.end(), k), c.missing_ticks.end())
          << "tick " << k << " was never shown but is in the record";
    }
  }
  EXPECT_EQ(reportedMissing(r.out), c.gaps) << r.out;
  EXPECT_EQ(
      r.out.rfind("recorded " + std::to_string(c.rows) + " rows to " + r.file + " (ticks ", 0), 0u)
      << r.out;
  EXPECT_NE(r.err.find("warning: " + std::to_string(c.gaps) + " of the"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("not complete"), std::string::npos) << r.err;
}

TEST(DaemonCommands, RecordWarnsExactlyWhenTicksAreMissing) {
  FakeDaemon d(500, 0);
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Recorded r = record(d.target(), "rec_full.csv", 0.2);
  ASSERT_EQ(r.rc, 0) << r.err;
  const RecordCheck c = checkRecord(r.file);
  EXPECT_GT(c.rows, 10u);
  EXPECT_EQ(reportedMissing(r.out), c.gaps) << r.out;
  // each_tick: no tick twice; a tick is only missed when the fake's server thread was off the
  // CPU for a whole tick (2 ms), which the count then says
  if (c.gaps == 0) {
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  } else {
    EXPECT_NE(r.err.find("warning: " + std::to_string(c.gaps) + " of the"), std::string::npos)
        << r.err;
  }
}

TEST(DaemonCommands, RecordWithoutADaemonExits1) {
  DaemonTarget t;
  t.port = 1;
  t.timeout_ms = 200;
  RecordOptions o;
  o.file = tempFile("rec_none.csv").string();
  std::ostringstream out, err;
  EXPECT_EQ(runRecord(t, o, out, err), 1);
  EXPECT_NE(err.str().find("no daemon at 127.0.0.1:1"), std::string::npos) << err.str();
}

// ---- replay ---------------------------------------------------------------------------------

// 0 → 0.05 s: p to (0.01, 0.02, −0.03), 0° → 90° about z; 0.05 → 0.105 s: p to (0.03, ...),
// 90° → 180° written as −(0, 0, 1, 0) (the shorter arc must be taken); buttons 1, 2, 4.
const char* kStream =
    "t,px,py,pz,qx,qy,qz,qw,buttons\n"
    "0,0,0,0,0,0,0,1,1\n"
    "0.05,0.01,0.02,-0.03,0,0,0.70710678118654752,0.70710678118654752,2\n"
    "0.105,0.03,0.02,-0.03,0,0,-1,0,4\n";

struct Expected {
  std::array<double, 3> p;
  std::array<double, 4> q;
  std::uint32_t buttons;
};

// The stream at t, from the closed forms above.
Expected expectedAt(double t) {
  if (t < 0.05) {
    const double u = t / 0.05;
    return {{0.01 * u, 0.02 * u, -0.03 * u}, aboutZ(90.0 * u), 1};
  }
  if (t < 0.105) {
    const double u = (t - 0.05) / 0.055;
    return {{0.01 + 0.02 * u, 0.02, -0.03}, aboutZ(90.0 + 90.0 * u), 2};
  }
  return {{0.03, 0.02, -0.03}, {0.0, 0.0, -1.0, 0.0}, 4};
}

// The send times of a replay of kStream at `rate`: k/rate up to 0.105, then 0.105 itself.
std::vector<double> sendTimes(double rate) {
  std::vector<double> t;
  for (std::uint64_t k = 0; static_cast<double>(k) / rate <= 0.105 + 1e-12; ++k)
    t.push_back(static_cast<double>(k) / rate);
  if (t.back() < 0.105 - 1e-12)
    t.push_back(0.105);
  return t;
}

// replay options for `text` written to a temp file `name`
ReplayOptions replayOf(const std::string& name, const char* text = kStream) {
  const auto file = tempFile(name);
  std::ofstream(file) << text;
  ReplayOptions o;
  o.file = file.string();
  return o;
}

void expectPoses(const std::vector<proto::PoseCommand>& got, double rate) {
  const auto times = sendTimes(rate);
  ASSERT_EQ(got.size(), times.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    const Expected e = expectedAt(times[i]);
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_NEAR(got[i].X_WT.p[k], e.p[k], 1e-15) << "pose " << i << " t " << times[i];
    EXPECT_LT(rotationGap(got[i].X_WT.q, e.q), 1e-14) << "pose " << i << " t " << times[i];
    EXPECT_EQ(got[i].buttons, e.buttons) << "pose " << i << " t " << times[i];
  }
}

TEST(DaemonCommands, ReplaySendsTheInterpolatedStreamInOrderAtTheTickRate) {
  FakeDaemon d(/*tick_rate_hz=*/100);
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("stream.csv");
  std::ostringstream out, err;
  ASSERT_EQ(runReplay(d.target(), o, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("replayed 12 pose commands"), std::string::npos) << out.str();
  const auto cmds = d.commands();
  ASSERT_FALSE(cmds.empty());
  EXPECT_EQ(cmds.front().kind, proto::CommandEvent::Kind::kArm);  // control first
  const auto poses = d.poses(12);
  std::vector<proto::PoseCommand> got;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(poses[i].sequence, poses[i - 1].sequence);  // in order
    }
    got.push_back(poses[i].pose);
  }
  expectPoses(got, 100.0);
  // the first segment's velocity travels with the pose; the last pose stands still
  EXPECT_NEAR(got[1].v_W[0], 0.01 / 0.05, 1e-9);
  EXPECT_NEAR(got[1].w_W[2], (std::numbers::pi / 2) / 0.05, 1e-6);
  EXPECT_EQ(got.back().v_W, (proto::WireVec3{0.0, 0.0, 0.0}));
}

TEST(DaemonCommands, ReplayRateIsClampedToTheTickRate) {
  FakeDaemon d(100);
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("stream2.csv");
  o.rate_hz = 1000;
  std::ostringstream out, err;
  ASSERT_EQ(runReplay(d.target(), o, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("at 100 Hz"), std::string::npos) << out.str();
  std::vector<proto::PoseCommand> got;
  for (const auto& e : d.poses(12))
    got.push_back(e.pose);
  expectPoses(got, 100.0);
  // a lower rate than the tick rate is kept
  FakeDaemon d2(100);
  o.rate_hz = 40;
  std::ostringstream out2, err2;
  ASSERT_EQ(runReplay(d2.target(), o, out2, err2), 0) << err2.str();
  got.clear();
  for (const auto& e : d2.poses(sendTimes(40).size()))
    got.push_back(e.pose);
  expectPoses(got, 40.0);
}

TEST(DaemonCommands, ALongReplayReportsProgressOnStderrUnlessQuiet) {
  FakeDaemon d(20);
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("long.csv", "0,0,0,0,0,0,0,1,0\n2.5,0.1,0,0,0,0,0,1,0\n");
  std::ostringstream out, err;
  ASSERT_EQ(runReplay(d.target(), o, out, err), 0) << err.str();
  // sends run to t = 2.5 s of the stream, so at least the line of the first second comes
  std::istringstream lines(err.str());
  std::string line;
  std::size_t n = 0;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.rfind("hapticctl replay: ", 0), 0u) << line;
    EXPECT_NE(line.find(" / 2.5 s, "), std::string::npos) << line;
    EXPECT_NE(line.find(" of 51 poses sent"), std::string::npos) << line;
    ++n;
  }
  EXPECT_GE(n, 1u) << err.str();
  EXPECT_NE(out.str().find("replayed 51 pose commands"), std::string::npos) << out.str();
  o.quiet = true;
  std::ostringstream out2, err2;
  ASSERT_EQ(runReplay(d.target(), o, out2, err2), 0) << err2.str();
  EXPECT_TRUE(err2.str().empty()) << err2.str();
}

TEST(DaemonCommands, AStreamTooLongToReplayIsRefusedNotOverflowed) {
  FakeDaemon d(1000);
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("huge.csv", "0,0,0,0,0,0,0,1,0\n1e300,0,0,0,0,0,0,1,0\n");
  std::ostringstream out, err;
  EXPECT_EQ(runReplay(d.target(), o, out, err), 2);
  EXPECT_NE(err.str().find("too long to replay"), std::string::npos) << err.str();
  EXPECT_TRUE(d.poses(0).empty());
}

TEST(DaemonCommands, ReplayRefusesBadFilesWithFileLineAndExit2) {
  DaemonTarget t;  // never reached: the file is checked first
  t.port = 1;
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"t,px,py,pz,qx,qy,qz,qw,buttons\n0,0,0,zero,0,0,0,1,0\n", "bad.csv:2: column 4 (pz)"},
      {"0,0,0,0,0,0,0,1,0\n0,0,0,0,0,0,0,1,0\n", "bad.csv:2: t 0 is not after"},
      {"0,0,0,0,0,0,0,1,0\n1,0,0,0,0,0,0.5,0.5,0\n", "bad.csv:2: quaternion (0, 0, 0.5, 0.5)"},
  };
  for (const auto& c : cases) {
    const auto file = tempFile("bad.csv");
    std::ofstream(file) << c.text;
    ReplayOptions o;
    o.file = file.string();
    std::ostringstream out, err;
    EXPECT_EQ(runReplay(t, o, out, err), 2) << c.text;
    EXPECT_NE(err.str().find(c.message), std::string::npos) << err.str();
  }
  ReplayOptions o;
  o.file = tempFile("does-not-exist.csv").string();
  std::ostringstream out, err;
  EXPECT_EQ(runReplay(t, o, out, err), 2);
  EXPECT_NE(err.str().find("cannot open"), std::string::npos);
}

// ---- move, add, remove ----------------------------------------------------------------------

TEST(DaemonCommands, MoveAddRemoveDeliverTheSceneUpdate) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  SceneEditOptions move;
  move.kind = SceneEditOptions::Kind::kMove;
  move.body = 3;
  move.px = 0.5;
  move.py = -0.25;
  move.pz = 2.0;
  move.qz = 1.0;
  move.qw = 1.0;  // normalised before sending
  std::ostringstream out, err;
  ASSERT_EQ(runSceneEdit(d.target(), move, out, err), 0) << err.str();
  EXPECT_EQ(out.str(), "moved body 3 at 0.5 -0.25 2\n");
  SceneEditOptions add;
  add.kind = SceneEditOptions::Kind::kAdd;
  add.body = 5;
  add.px = 1.0;
  ASSERT_EQ(runSceneEdit(d.target(), add, out, err), 0) << err.str();
  SceneEditOptions remove;
  remove.kind = SceneEditOptions::Kind::kRemove;
  remove.body = 7;
  ASSERT_EQ(runSceneEdit(d.target(), remove, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("removed body 7"), std::string::npos);

  const auto u = d.updates();
  ASSERT_EQ(u.size(), 3u);
  ASSERT_EQ(u[0].poses.size(), 1u);
  EXPECT_TRUE(u[0].added.empty());
  EXPECT_TRUE(u[0].removed.empty());
  EXPECT_EQ(u[0].poses[0].body_index, 3u);
  EXPECT_EQ(u[0].poses[0].X_WB.p, (proto::WireVec3{0.5, -0.25, 2.0}));
  EXPECT_NEAR(u[0].poses[0].X_WB.q[2], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(u[0].poses[0].X_WB.q[3], std::sqrt(0.5), 1e-15);
  ASSERT_EQ(u[1].added.size(), 1u);
  EXPECT_TRUE(u[1].poses.empty());
  EXPECT_EQ(u[1].added[0].body_index, 5u);
  EXPECT_EQ(u[1].added[0].X_WB.p, (proto::WireVec3{1.0, 0.0, 0.0}));
  EXPECT_EQ(u[1].added[0].X_WB.q, (std::array<double, 4>{0.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(u[2].removed, (std::vector<std::uint32_t>{7}));
  EXPECT_TRUE(u[2].poses.empty());
  EXPECT_TRUE(u[2].added.empty());
}

TEST(DaemonCommands, ARefusedSceneUpdateExits1WithTheDaemonsText) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  d.refuseUpdatesWith("body 9 is static: only kinematic bodies can be moved");
  SceneEditOptions move;
  move.body = 9;
  std::ostringstream out, err;
  EXPECT_EQ(runSceneEdit(d.target(), move, out, err), 1);
  EXPECT_NE(err.str().find("hapticctl move: body 9: "), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("body 9 is static: only kinematic bodies can be moved"),
            std::string::npos)
      << err.str();
  EXPECT_TRUE(out.str().empty());
  EXPECT_FALSE(d.updates().empty());  // it did reach the daemon
}

TEST(DaemonCommands, SceneEditWithABadPoseExits2AndSendsNothing) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  SceneEditOptions move;
  move.body = 1;
  move.qw = 0.0;  // a zero quaternion
  std::ostringstream out, err;
  EXPECT_EQ(runSceneEdit(d.target(), move, out, err), 2);
  move.qw = 1.0;
  move.px = std::nan("");
  EXPECT_EQ(runSceneEdit(d.target(), move, out, err), 2);
  EXPECT_TRUE(d.updates().empty());
}

// ---- watch ----------------------------------------------------------------------------------

// `hapticctl watch --json` of `count` lines at `rate_hz`: its exit code, stderr, the lines parsed
struct Watched {
  int rc = -1;
  std::string err;
  std::vector<nlohmann::json> lines;
};
Watched watchJson(const DaemonTarget& t,
                  std::uint32_t rate_hz,
                  std::uint64_t count,
                  bool bodies = false) {
  WatchOptions o;
  o.rate_hz = rate_hz;
  o.count = count;
  o.json = true;
  o.bodies = bodies;
  std::ostringstream out, err;
  const int rc = runWatch(t, o, out, err);
  return {rc, err.str(), rc == 0 ? jsonLines(out.str()) : std::vector<nlohmann::json>{}};
}

TEST(DaemonCommands, WatchJsonCarriesTheMinorOneFieldsAndTheDeepestContacts) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Watched w = watchJson(d.target(), 50, 3);
  ASSERT_EQ(w.rc, 0) << w.err;
  std::size_t n = 0;
  for (const nlohmann::json& j : w.lines) {
    ++n;
    const std::uint64_t tick = j["tick"];
    const proto::State s = stateFor(tick);
    EXPECT_EQ(j["pairs_tested"], s.pairs_tested);
    EXPECT_EQ(j["pairs_skipped"], s.pairs_skipped);
    EXPECT_EQ(j["tick_ns"]["this"], s.tick_ns);
    EXPECT_EQ(j["tick_ns"]["p99"], s.tick_p99_ns);
    EXPECT_EQ(j["max_penetration_m"], s.max_penetration_m);
    EXPECT_EQ(j["contacts"], s.contact_count);
    EXPECT_EQ(j["force_n"][0], s.force_n[0]);
    EXPECT_EQ(j["faults"], "none");
    EXPECT_EQ(j["armed"], true);
    ASSERT_EQ(j["deepest"].size(), 3u);
    EXPECT_EQ(j["deepest"][0]["depth_m"], 1e-4 * 3);  // sorted deepest first
    EXPECT_EQ(j["deepest"][1]["depth_m"], 1e-4 * 2);
    EXPECT_EQ(j["deepest"][2]["depth_m"], 1e-4 * 1);
    EXPECT_EQ(j["deepest"][0]["p"][0], 0.1);
  }
  EXPECT_EQ(n, 3u);
}

TEST(DaemonCommands, WatchTextLineShowsPercentilesPairsAndDeepestContacts) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  WatchOptions o;
  o.rate_hz = 50;
  o.count = 2;
  o.deepest = 2;
  std::ostringstream out, err;
  ASSERT_EQ(runWatch(d.target(), o, out, err), 0) << err.str();
  const std::string s = out.str();
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 2) << s;
  // the 1.0 line first, unchanged, for scripts that read it
  EXPECT_EQ(s.rfind("tick ", 0), 0u) << s;
  EXPECT_NE(s.find(" s | tick p50 11.0 us p99 22.0 us max 33.0 us | force "), std::string::npos)
      << s;
  EXPECT_NE(s.find(" | faults none | armed | this tick "), std::string::npos) << s;
  // then the minor-1 fields of that tick and the deepest contacts
  const std::uint64_t tick = std::stoull(s.substr(5, s.find(' ', 5) - 5));
  const proto::State st = stateFor(tick);
  char want[160];
  std::snprintf(want, sizeof want, "this tick %.1f us, pairs %u tested %u skipped, max pen %.3g m",
                st.tick_ns / 1e3, st.pairs_tested, st.pairs_skipped, st.max_penetration_m);
  EXPECT_NE(s.find(want), std::string::npos) << want << "\n" << s;
  EXPECT_NE(s.find(" | deepest 0.0003 m at (0.1, 0, "), std::string::npos) << s;
  EXPECT_NE(s.find(", 0.0002 m at (0, 0, "), std::string::npos) << s;
  EXPECT_EQ(s.find("0.0001 m at"), std::string::npos) << s;  // only the deepest two
}

// ---- shared memory --------------------------------------------------------------------------

TEST(DaemonCommandsShm, PoseOverSharedMemory) {
  FakeShmDaemon d("pose");
  ASSERT_TRUE(d.error().empty()) << d.error();
  PoseOptions o;
  std::tie(o.px, o.py, o.pz) = std::tuple(0.01, 0.02, 0.03);
  o.seconds = 0.1;
  o.rate_hz = 100;
  std::ostringstream out, err;
  ASSERT_EQ(runPose(d.target(), o, out, err), 0) << err.str();
  EXPECT_EQ(out.str().rfind("device at 0.01 0.02 0.03,", 0), 0u) << out.str();  // the fake echoes
  const auto ev = d.events();
  ASSERT_GE(ev.size(), 2u);
  EXPECT_EQ(ev.front().kind, proto::ShmCommandEvent::Kind::kArm);
  for (std::size_t i = 1; i < ev.size(); ++i) {
    EXPECT_EQ(ev[i].kind, proto::ShmCommandEvent::Kind::kPose);
    EXPECT_GT(ev[i].sequence, ev[i - 1].sequence);
    EXPECT_EQ(ev[i].pose.X_WT.p, (proto::WireVec3{0.01, 0.02, 0.03}));
  }
}

TEST(DaemonCommandsShm, ReplayOverSharedMemorySendsTheInterpolatedStream) {
  FakeShmDaemon d("replay");
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("shm_stream.csv");
  o.rate_hz = 100;
  std::ostringstream out, err;
  ASSERT_EQ(runReplay(d.target(), o, out, err), 0) << err.str();
  // the fake's clock says 500 Hz (2 ms of sim time per tick): 100 Hz is kept
  EXPECT_NE(out.str().find("at 100 Hz"), std::string::npos) << out.str();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  std::vector<proto::PoseCommand> got;
  while (got.size() < 12 && std::chrono::steady_clock::now() < until) {
    got.clear();
    for (const auto& e : d.events())
      if (e.kind == proto::ShmCommandEvent::Kind::kPose)
        got.push_back(e.pose);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  expectPoses(got, 100.0);
}

TEST(DaemonCommandsShm, ReplayOverSharedMemoryDefaultsToTheMeasuredTickRate) {
  FakeShmDaemon d("replay_rate");
  ASSERT_TRUE(d.error().empty()) << d.error();
  ReplayOptions o = replayOf("shm_stream2.csv");
  std::ostringstream out, err;
  ASSERT_EQ(runReplay(d.target(), o, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("replayed " + std::to_string(sendTimes(500).size()) + " pose commands"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("at 500 Hz"), std::string::npos) << out.str();
}

TEST(DaemonCommandsShm, RecordOverSharedMemoryWritesEveryColumn) {
  FakeShmDaemon d("record");
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Recorded r = record(d.target(), "shm_rec.csv", 0.2);
  ASSERT_EQ(r.rc, 0) << r.err;
  const RecordCheck c = checkRecord(r.file);
  EXPECT_GT(c.rows, 5u);
  EXPECT_EQ(reportedMissing(r.out), c.gaps) << r.out;
}

TEST(DaemonCommandsShm, WatchOverSharedMemoryPrintsAtMostTheRate) {
  FakeShmDaemon d("watch");
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Watched w = watchJson(d.target(), 1000, 3);
  ASSERT_EQ(w.rc, 0) << w.err;
  std::uint64_t prev = 0;
  std::size_t n = 0;
  for (const nlohmann::json& j : w.lines) {
    const std::uint64_t tick = j["tick"];
    EXPECT_GT(tick, prev);
    prev = tick;
    EXPECT_EQ(j["pairs_tested"], stateFor(tick).pairs_tested);
    EXPECT_EQ(j["tick_ns"]["this"], stateFor(tick).tick_ns);
    EXPECT_TRUE(j["deepest"].empty());  // the segment lists no contacts
    ++n;
  }
  EXPECT_EQ(n, 3u);
}

TEST(DaemonCommandsShm, NoSegmentExits1WithWhy) {
  DaemonTarget t;
  t.shm_name = "/hapticctl-test-none-" + std::to_string(::getpid());
  t.port = 1;
  PoseOptions o;
  std::ostringstream out, err;
  EXPECT_EQ(runPose(t, o, out, err), 1);
  EXPECT_NE(err.str().find("hapticctl pose: --shm " + t.shm_name), std::string::npos) << err.str();
}

// ---- the edges a user hits ------------------------------------------------------------------

// a loopback UDP port nothing listens on (bound for a moment, then closed)
std::uint16_t closedPort() {
  auto s = proto::UdpSocket::bind(proto::parseAddress("127.0.0.1:0").value());
  return s ? s.value().localAddress().port() : 1;
}

TEST(DaemonCommandsEdges, NoDaemonFailsAtOnceOnPortUnreachable) {
  DaemonTarget t;
  t.port = closedPort();
  t.timeout_ms = 60000;  // waiting it out would take a minute and say "within 60000 ms"
  std::ostringstream out, err;
  EXPECT_EQ(runStatus(t, {}, out, err), 1);
  EXPECT_NE(err.str().find("no daemon at 127.0.0.1:" + std::to_string(t.port) +
                           ": the port is unreachable"),
            std::string::npos)
      << err.str();
  EXPECT_EQ(err.str().find("within"), std::string::npos) << err.str();
  EXPECT_TRUE(out.str().empty());
}

TEST(DaemonCommandsEdges, AWrongKeyIsReportedAsAWrongKey) {
  const proto::Key key = proto::randomKey();
  FakeDaemon d(1000, 0, key);
  ASSERT_TRUE(d.error().empty()) << d.error();
  DaemonTarget t = d.target();
  t.timeout_ms = 300;
  t.key_file = tempFile("wrong.key").string();
  std::ofstream(t.key_file) << proto::keyToHex(proto::randomKey()) << "\n";
  std::ostringstream out, err;
  EXPECT_EQ(runArm(t, true, out, err), 1);
  EXPECT_NE(err.str().find("hapticctl: wrong key: hapticd at 127.0.0.1:"), std::string::npos)
      << err.str();
  EXPECT_EQ(err.str().find("no daemon"), std::string::npos) << err.str();
  EXPECT_TRUE(d.commands().empty());
  // the right key arms
  std::ofstream(t.key_file) << proto::keyToHex(key) << "\n";
  std::ostringstream out2, err2;
  EXPECT_EQ(runArm(t, true, out2, err2), 0) << err2.str();
  ASSERT_EQ(d.commands().size(), 1u);
  EXPECT_TRUE(d.commands()[0].authenticated);
}

TEST(DaemonCommandsEdges, PoseRefusesNegativeSecondsAndARateNotAbove0) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  struct Case {
    double seconds, rate_hz;
    const char* message;
  };
  for (const Case& c : {Case{-1.0, 200.0, "--seconds must be a finite number ≥ 0 (got -1)"},
                        Case{std::nan(""), 200.0, "--seconds must be"},
                        Case{0.5, 0.0, "--rate must be a finite number > 0, Hz (got 0)"},
                        Case{0.5, -5.0, "--rate must be"},
                        Case{0.5, std::numeric_limits<double>::infinity(), "--rate must be"}}) {
    PoseOptions o;
    o.seconds = c.seconds;
    o.rate_hz = c.rate_hz;
    std::ostringstream out, err;
    EXPECT_EQ(runPose(d.target(), o, out, err), 2) << c.message;
    EXPECT_NE(err.str().find(std::string("hapticctl pose: ") + c.message), std::string::npos)
        << err.str();
  }
  EXPECT_TRUE(d.commands().empty());  // refused before connecting
}

TEST(DaemonCommandsEdges, AFailedRecordLeavesNoFileAndAnOlderOneAsItWas) {
  DaemonTarget t;
  t.port = closedPort();
  RecordOptions o;
  o.file = tempFile("failed.csv").string();
  o.bodies_file = tempFile("failed_bodies.csv").string();
  std::filesystem::remove(o.file);
  std::ofstream(o.bodies_file) << "an older file\n";
  std::ostringstream out, err;
  EXPECT_EQ(runRecord(t, o, out, err), 1);
  EXPECT_FALSE(std::filesystem::exists(o.file));
  std::ifstream older(o.bodies_file);
  std::string line;
  std::getline(older, line);
  EXPECT_EQ(line, "an older file");
  // nothing else left in the folder from this record
  for (const auto& e : std::filesystem::directory_iterator(tempFile("").parent_path()))
    EXPECT_EQ(e.path().filename().string().find("failed.csv.tmp"), std::string::npos);
  // a daemon that went away: no file either
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  d.stop();
  std::ostringstream out2, err2;
  EXPECT_EQ(runRecord(d.target(), o, out2, err2), 1);
  EXPECT_FALSE(std::filesystem::exists(o.file));
  // a bad number refused before anything is created
  o.seconds = -2.0;
  std::ostringstream out3, err3;
  EXPECT_EQ(runRecord(t, o, out3, err3), 2);
  EXPECT_NE(err3.str().find("--seconds must be a finite number ≥ 0"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(o.file));
}

// Reads a bodies file and checks every row against stateFor(tick) (names: `names`, else
// body<index>); the number of rows.
std::size_t checkBodies(const std::filesystem::path& file, const std::vector<std::string>& names) {
  EXPECT_EQ(std::string(bodiesHeader()), "tick,t,body,px,py,pz,qx,qy,qz,qw");
  std::size_t rows = 0;
  for (const auto& f : csvRows(file, bodiesHeader())) {
    const std::string line = f[0] + "," + f[1] + "," + f[2];
    const std::uint64_t tick = std::stoull(f[0]) + 1;
    const proto::State s = stateFor(tick);
    const auto& b = s.bodies[rows % 2];  // each tick lists body 1, then body 4
    EXPECT_EQ(num(f[1]), static_cast<double>(s.sim_time_ns) * 1e-9);
    EXPECT_EQ(f[2], names.empty() ? "body" + std::to_string(b.body_index) : names[b.body_index]);
    for (std::size_t i = 0; i < 3; ++i)
      EXPECT_EQ(num(f[3 + i]), b.X_WB.p[i]) << line;
    for (std::size_t i = 0; i < 4; ++i)
      EXPECT_EQ(num(f[6 + i]), b.X_WB.q[i]) << line;
    ++rows;
  }
  return rows;
}

TEST(DaemonCommandsEdges, RecordBodiesWritesTheRecordBodiesColumnsForEveryRecordedTick) {
  FakeDaemon d(500, 0);
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Recorded r = record(d.target(), "with_bodies.csv", 0.2, "bodies.csv");
  ASSERT_EQ(r.rc, 0) << r.err;
  const RecordCheck c = checkRecord(r.file);
  ASSERT_GT(c.rows, 10u);
  EXPECT_EQ(checkBodies(r.bodies_file, {}), 2 * c.rows);  // two bodies in every recorded tick
  EXPECT_NE(r.out.find("recorded the body poses of those ticks to " + r.bodies_file),
            std::string::npos)
      << r.out;
  RecordOptions o;
  o.file = r.file;
  o.bodies_file = r.bodies_file;
  o.seconds = 0.2;
  // with the scene: the bodies by their node names, as the daemon's --record-bodies
  const std::string scene = std::string(HAPTICD_SOURCE_DIR) + "/scenes/dynamic.glb";
  const scene::LoadReport report = scene::loadSceneFile(scene);
  ASSERT_TRUE(report.ok()) << report.message();
  std::vector<std::string> names;
  for (const auto& b : report.scene->bodies)
    names.push_back(b.name);
  ASSERT_GT(names.size(), 4u);
  o.scene_file = scene;
  std::ostringstream out2, err2;
  ASSERT_EQ(runRecord(d.target(), o, out2, err2), 0) << err2.str();
  EXPECT_EQ(checkBodies(o.bodies_file, names), 2 * checkRecord(o.file).rows);
  // a scene that does not load: exit 2, nothing written
  o.scene_file = tempFile("not-a-scene.glb").string();
  std::ofstream(o.scene_file) << "not glTF";
  std::filesystem::remove(o.bodies_file);
  std::ostringstream out3, err3;
  EXPECT_EQ(runRecord(d.target(), o, out3, err3), 2);
  EXPECT_NE(err3.str().find("hapticctl record: --scene " + o.scene_file), std::string::npos)
      << err3.str();
  EXPECT_FALSE(std::filesystem::exists(o.bodies_file));
}

TEST(DaemonCommandsEdges, RecordBodiesOverSharedMemory) {
  FakeShmDaemon d("record_bodies");
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Recorded r = record(d.target(), "shm_with_bodies.csv", 0.2, "shm_bodies.csv");
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::size_t rows = checkRecord(r.file).rows;
  ASSERT_GT(rows, 5u);
  EXPECT_EQ(checkBodies(r.bodies_file, {}), 2 * rows);
}

TEST(DaemonCommandsEdges, WatchBodiesShowsEveryBodyPose) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  const Watched w = watchJson(d.target(), 50, 2, /*bodies=*/true);
  ASSERT_EQ(w.rc, 0) << w.err;
  std::size_t n = 0;
  for (const nlohmann::json& j : w.lines) {
    const proto::State s = stateFor(j["tick"]);
    ASSERT_EQ(j["bodies"].size(), 2u);
    for (std::size_t b = 0; b < 2; ++b) {
      EXPECT_EQ(j["bodies"][b]["body"], s.bodies[b].body_index);
      EXPECT_EQ(j["bodies"][b]["p"], s.bodies[b].X_WB.p);
      EXPECT_EQ(j["bodies"][b]["q"], s.bodies[b].X_WB.q);
    }
    EXPECT_EQ(j["bodies_truncated"], false);
    ++n;
  }
  EXPECT_EQ(n, 2u);
  WatchOptions o;
  o.rate_hz = 50;
  o.count = 2;
  o.bodies = true;
  o.json = false;
  std::ostringstream text, err2;
  ASSERT_EQ(runWatch(d.target(), o, text, err2), 0) << err2.str();
  const std::string line = text.str().substr(0, text.str().find('\n'));
  const proto::State s = stateFor(std::stoull(line.substr(5, line.find(' ', 5) - 5)));
  char want[160];
  std::snprintf(want, sizeof want, " | bodies 2: 1 at (%.4g, %.4g, %.4g), 4 at (%.4g, %.4g, %.4g)",
                s.bodies[0].X_WB.p[0], s.bodies[0].X_WB.p[1], s.bodies[0].X_WB.p[2],
                s.bodies[1].X_WB.p[0], s.bodies[1].X_WB.p[1], s.bodies[1].X_WB.p[2]);
  EXPECT_NE(line.find(want), std::string::npos) << want << "\n" << line;
  // without --bodies the line and the object say nothing of bodies
  o.bodies = false;
  std::ostringstream plain, err3;
  ASSERT_EQ(runWatch(d.target(), o, plain, err3), 0) << err3.str();
  EXPECT_EQ(plain.str().find("bodies"), std::string::npos) << plain.str();
}

TEST(DaemonCommandsEdges, StatusShowsForceAndContactsOfARecentTick) {
  FakeDaemon d;
  ASSERT_TRUE(d.error().empty()) << d.error();
  StatusOptions o;
  o.json = true;
  std::ostringstream out, err;
  ASSERT_EQ(runStatus(d.target(), o, out, err), 0) << err.str();
  const nlohmann::json j = nlohmann::json::parse(out.str());
  EXPECT_EQ(j["device"], "fake");
  ASSERT_TRUE(j["state"].is_object()) << out.str();
  const proto::State s = stateFor(j["state"]["tick"]);
  EXPECT_EQ(j["state"]["force_n"], s.force_n);
  EXPECT_EQ(j["state"]["torque_nm"], s.torque_nm);
  EXPECT_EQ(j["state"]["contacts"], s.contact_count);
  EXPECT_EQ(j["state"]["deepest_m"], 1e-4 * 3);
  EXPECT_EQ(j["state"]["max_penetration_m"], s.max_penetration_m);
  // the text says the same, on the line after the commands
  o.json = false;
  std::ostringstream text, err2;
  ASSERT_EQ(runStatus(d.target(), o, text, err2), 0) << err2.str();
  const std::string t = text.str();
  const auto at = t.find("\nforce ");
  ASSERT_NE(at, std::string::npos) << t;
  const auto tick_at = t.find("(tick ", at);
  const std::uint64_t tick = std::stoull(t.substr(tick_at + 6));
  const proto::State st = stateFor(tick);
  char want[200];
  std::snprintf(want, sizeof want, "force %.4g N (%.4g, %.4g, %.4g), torque %.4g N m, contacts %u",
                norm(st.force_n), st.force_n[0], st.force_n[1], st.force_n[2], norm(st.torque_nm),
                st.contact_count);
  EXPECT_EQ(t.find(want), at + 1) << want << "\n" << t;
}

TEST(DaemonCommandsEdges, WatchAndRecordSayWhenTheDaemonGoesAway) {
  for (const bool record_it : {false, true}) {
    FakeDaemon d;
    ASSERT_TRUE(d.error().empty()) << d.error();
    std::ostringstream out, err;
    int rc = -1;
    std::thread command([&] {
      if (record_it) {
        RecordOptions o;
        o.file = tempFile("gone.csv").string();
        o.seconds = 60.0;  // the daemon goes long before
        rc = runRecord(d.target(), o, out, err);
      } else {
        WatchOptions o;  // until interrupted
        rc = runWatch(d.target(), o, out, err);
      }
    });
    EXPECT_TRUE(d.waitForSession());
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // subscribed, states coming
    d.stop();
    command.join();
    EXPECT_EQ(rc, 1);
    EXPECT_NE(err.str().find("went away"), std::string::npos) << err.str();
  }
}

}  // namespace
}  // namespace hapticd::client
