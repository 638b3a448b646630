#include "client/daemon_commands.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <ostream>
#include <thread>
#include <vector>

#include "client/link.h"
#include "client/replay_stream.h"
#include "client/state_format.h"
#include "client/tick_order.h"
#include "core/scene/bundle.h"
#include "core/scene/loader.h"
#include "protocol/client.h"
#include "protocol/server.h"  // monotonicNs

namespace hapticd::client {
namespace {

using Clock = std::chrono::steady_clock;

// The pose as typed, its quaternion normalised; nullopt (with why on `err`, exit code 2) when
// it is not finite or the quaternion is zero.
std::optional<proto::WirePose> wirePose(const TargetPose& o, const char* verb, std::ostream& err) {
  const double n = std::sqrt(o.qx * o.qx + o.qy * o.qy + o.qz * o.qz + o.qw * o.qw);
  const double v[] = {o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw};
  if (!std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); }) ||
      !(n >= 1e-6)) {
    err << "hapticctl " << verb
        << ": the position must be finite and the quaternion finite and nonzero\n";
    return std::nullopt;
  }
  proto::WirePose x;
  x.p = {o.px, o.py, o.pz};
  x.q = {o.qx / n, o.qy / n, o.qz / n, o.qw / n};
  return x;
}

// Streams `cmd` for `seconds` at `rate_hz` (at least once), keeping the newest state.
bool streamPose(Link& c,
                const proto::PoseCommand& cmd,
                double seconds,
                double rate_hz,
                std::optional<proto::State>& last,
                std::string* why) {
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);  // rate_hz > 0, checked
  const auto end = Clock::now() + std::chrono::duration<double>(std::max(seconds, 0.0));
  do {
    if (!c.sendPose(cmd, why))
      return false;
    const auto next = Clock::now() + std::chrono::duration_cast<Clock::duration>(period);
    while (Clock::now() < next) {
      const int ms = static_cast<int>(
          std::chrono::duration_cast<std::chrono::milliseconds>(next - Clock::now()).count());
      if (auto s = c.receiveState(std::max(ms, 0)))
        last = std::move(*s);
      else if (ms <= 0)
        break;
    }
  } while (Clock::now() < end);
  return true;
}

// the sample on the wire: the one conversion of the client's replay
proto::PoseCommand commandOf(const ReplaySample& s) {
  const geom::Vec3& p = s.X_WD.translation;
  const geom::Quat& q = s.X_WD.rotation;
  proto::PoseCommand c;
  c.X_WT.p = {p.x, p.y, p.z};
  c.X_WT.q = {q.x, q.y, q.z, q.w};
  c.v_W = {s.v_W.x, s.v_W.y, s.v_W.z};
  c.w_W = {s.w_W.x, s.w_W.y, s.w_W.z};
  c.buttons = s.buttons;
  return c;
}

// An output written under a temporary name in its folder and renamed into place by commit(), so
// that a failed command leaves no file behind (and an older file of that name as it was).
class OutputFile {
 public:
  ~OutputFile() {
    if (f_) {
      f_.reset();
      std::remove(tmp_.c_str());
    }
  }
  // creates the temporary file; false (errno set) when it cannot
  bool open(const std::string& path) {
    path_ = path;
    tmp_ = path + ".tmp-" + std::to_string(::getpid());
    f_.reset(std::fopen(tmp_.c_str(), "w"));
    return f_ != nullptr;
  }
  explicit operator bool() const { return f_ != nullptr; }
  std::FILE* get() const { return f_.get(); }
  // closes and renames into place; false when the close or the rename failed (then removed)
  bool commit() {
    const bool closed = std::fclose(f_.release()) == 0;
    if (closed && std::rename(tmp_.c_str(), path_.c_str()) == 0)
      return true;
    std::remove(tmp_.c_str());
    return false;
  }

 private:
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f_{nullptr, &std::fclose};
  std::string path_, tmp_;
};

// The names of the scene's bodies by index (node names, as the daemon's --record-bodies);
// false after saying why on `err`.
bool bodyNames(const std::string& scene_file, std::vector<std::string>& names, std::ostream& err) {
  const scene::LoadReport report = scene::loadSceneFile(scene_file);
  if (!report.ok()) {
    err << "hapticctl record: --scene " << scene_file << ": " << report.message() << "\n";
    return false;
  }
  for (const scene::Body& b : report.scene->bodies)
    names.push_back(b.name);
  return true;
}

// States for `seconds` into `order` (tick order); true when the daemon went away first.
bool receiveFor(Link& c, double seconds, TickOrder& order) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    const int ms = static_cast<int>(
        std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count());
    auto s = c.receiveState(std::max(ms, 1));
    if (!s && c.gone())
      return true;
    if (!s || s->tick == 0)
      continue;  // nothing, or a state before the first tick
    (void)order.push(*s);
  }
  return false;
}

// "recorded N rows to FILE (ticks A..B, M ticks missing)", and a warning when M > 0
void reportRecord(const TickOrder& order,
                  const RecordOptions& o,
                  std::ostream& out,
                  std::ostream& err) {
  const std::uint64_t first = order.firstTick() - 1, last = order.lastTick() - 1;
  out << "recorded " << order.written() << " rows to " << o.file << " (ticks " << first << ".."
      << last << ", " << order.missing() << " ticks missing)\n";
  if (!o.bodies_file.empty())
    out << "recorded the body poses of those ticks to " << o.bodies_file << "\n";
  if (order.missing() > 0)
    err << "hapticctl record: warning: " << order.missing() << " of the " << (last - first + 1)
        << " ticks from " << first << " to " << last
        << " are missing (states lost, late, or sent below the tick rate): the record is not "
           "complete\n";
}

}  // namespace

int runStatus(const DaemonTarget& t, const StatusOptions& o, std::ostream& out, std::ostream& err) {
  auto c = connectUdp(t, err);
  if (!c)
    return 1;
  auto r = c->status();
  if (!r) {
    c->bye();
    err << "hapticctl status: " << r.error().message << "\n";
    return 1;
  }
  // force and contacts are in the state stream, not in the status: one state of a recent tick
  std::optional<proto::State> state;
  if (c->subscribe(proto::kMaxStateRateHz, proto::kSubscribeContacts))
    state = c->receiveState(std::clamp(t.timeout_ms, 1, 1000));
  c->bye();
  if (o.json)
    out << statusJson(r.value(), address(t), state).dump(2) << "\n";
  else
    out << statusText(r.value(), address(t), state);
  return 0;
}

int runLoad(const DaemonTarget& t, const std::string& file, std::ostream& out, std::ostream& err) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    err << "hapticctl load: cannot open " << file << "\n";
    return 2;
  }
  // the scene with its external buffers read in beside it (one GLB): the daemon never resolves a
  // client's relative path against its own folders
  scene::LoadOptions beside;
  beside.allowed_uri_dir = std::filesystem::absolute(file).parent_path();
  auto bundled = scene::bundleScene(std::vector<std::uint8_t>((std::istreambuf_iterator<char>(in)),
                                                              std::istreambuf_iterator<char>()),
                                    beside);
  if (!bundled) {
    err << "hapticctl load: " << file << ": " << bundled.error().message << "\n";
    return 1;
  }
  const std::vector<std::uint8_t>& bytes = bundled.value();
  auto c = connectUdp(t, err);
  if (!c)
    return 1;
  std::string name =
      file.substr(file.find_last_of('/') == std::string::npos ? 0 : file.find_last_of('/') + 1);
  if (name.size() > proto::kMaxSceneNameBytes)
    name.resize(proto::kMaxSceneNameBytes);
  auto r = c->load(bytes, name);
  c->bye();
  if (!r) {
    err << "hapticctl load: " << file << " refused: " << r.error().message << "\n";
    return 1;
  }
  out << "loaded " << name << " (" << bytes.size() << " bytes)\n";
  return 0;
}

int runArm(const DaemonTarget& t, bool arm, std::ostream& out, std::ostream& err) {
  auto c = connectUdp(t, err);
  if (!c)
    return 1;
  auto r = arm ? c->arm() : c->disarm();
  c->bye();
  if (!r) {
    err << "hapticctl " << (arm ? "arm" : "disarm") << ": " << r.error().message << "\n";
    return 1;
  }
  out << (arm ? "armed\n" : "disarmed\n");
  return 0;
}

int runPose(const DaemonTarget& t, const PoseOptions& o, std::ostream& out, std::ostream& err) {
  const auto target = wirePose(o, "pose", err);
  if (!target)
    return 2;
  if (!(o.seconds >= 0.0) || !std::isfinite(o.seconds)) {
    err << "hapticctl pose: --seconds must be a finite number ≥ 0 (got " << o.seconds << ")\n";
    return 2;
  }
  if (!(o.rate_hz > 0.0) || !std::isfinite(o.rate_hz)) {
    err << "hapticctl pose: --rate must be a finite number > 0, Hz (got " << o.rate_hz << ")\n";
    return 2;
  }
  auto c = openLink(t, "pose", LinkUse::kSendCommands, o.arm, err);
  if (!c)
    return 1;
  std::string why;
  if (!c->subscribe(static_cast<std::uint32_t>(std::clamp(o.rate_hz, 1.0, 1000.0)), 0, &why)) {
    err << "hapticctl pose: subscribe: " << why << "\n";
    return 1;
  }
  proto::PoseCommand cmd;
  cmd.X_WT = *target;
  std::optional<proto::State> last;
  const bool sent = streamPose(*c, cmd, o.seconds, o.rate_hz, last, &why);
  c->close();
  if (!sent) {
    err << "hapticctl pose: " << why << "\n";
    return 1;
  }
  if (!last) {
    err << "hapticctl pose: sent, but no state came back\n";
    return 1;
  }
  char buf[256];
  std::snprintf(buf, sizeof buf, "device at %.6g %.6g %.6g, force %.4g N, command %" PRIu64 "\n",
                last->X_WD.p[0], last->X_WD.p[1], last->X_WD.p[2], norm(last->force_n),
                last->last_command_sequence);
  out << buf;
  return 0;
}

int runReplay(const DaemonTarget& t, const ReplayOptions& o, std::ostream& out, std::ostream& err) {
  if (!(o.rate_hz >= 0.0) || !std::isfinite(o.rate_hz)) {
    err << "hapticctl replay: --rate must be a finite number ≥ 0 (0: the daemon's tick rate)\n";
    return 2;
  }
  auto text = proto::readPoseStreamFile(o.file);
  if (!text) {
    err << "hapticctl replay: cannot open " << o.file << ": " << text.error().message << "\n";
    return 2;
  }
  auto parsed = parseReplayStream(text.value(), o.file);
  if (!parsed) {
    err << "hapticctl replay: " << parsed.error().message << "\n";
    return 2;
  }
  const std::vector<proto::PoseStreamRow>& rows = parsed.value();
  auto c = openLink(t, "replay", LinkUse::kSendCommands, o.arm, err);
  if (!c)
    return 1;
  std::string why;
  // the send rate: the daemon's tick rate, or the one asked for clamped to it
  const std::uint32_t tick_hz = c->tickRateHz();
  double rate = o.rate_hz > 0.0 ? o.rate_hz : (tick_hz > 0 ? tick_hz : 1000.0);
  if (tick_hz > 0 && rate > tick_hz)
    rate = tick_hz;
  const double t0 = rows.front().t_s;
  const double duration = rows.back().t_s - t0;
  if (!(duration * rate < 1e15)) {  // also keeps the send count inside a u64
    err << "hapticctl replay: " << o.file << ": the stream lasts " << duration
        << " s: too long to replay at " << rate << " Hz\n";
    c->close();
    return 2;
  }
  // send times t0 + k/rate for k = 0..n, and the last row itself when it falls between
  const auto n = static_cast<std::uint64_t>(std::floor(duration * rate + 1e-9));
  const bool extra_last = static_cast<double>(n) / rate < duration - 1e-12;
  const std::uint64_t total = n + 1 + (extra_last ? 1 : 0);
  const bool progress = !o.quiet && duration > 2.0;
  const auto start = Clock::now();
  auto next_progress = start + std::chrono::seconds(1);
  std::size_t hint = 0;
  std::uint64_t sent = 0;
  for (std::uint64_t k = 0; k < total; ++k) {
    const double ts = k <= n ? static_cast<double>(k) / rate : duration;
    const ReplaySample s = sampleReplayStream(rows, t0 + ts, &hint);
    std::this_thread::sleep_until(
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(ts)));
    if (!c->sendPose(commandOf(s), &why)) {
      err << "hapticctl replay: at t = " << s.t_s << " s: " << why << "\n";
      c->close();
      return 1;
    }
    c->pump();
    ++sent;
    if (progress && Clock::now() >= next_progress) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "hapticctl replay: %.1f / %.1f s, %" PRIu64 " of %" PRIu64 " poses sent\n", ts,
                    duration, sent, total);
      err << buf << std::flush;
      next_progress += std::chrono::seconds(1);
    }
  }
  c->close();
  char buf[160];
  std::snprintf(buf, sizeof buf, " (%.6g s of stream at %.6g Hz)\n", duration, rate);
  out << "replayed " << sent << " pose commands from " << o.file << buf;
  return 0;
}

int runRecord(const DaemonTarget& t, const RecordOptions& o, std::ostream& out, std::ostream& err) {
  if (!(o.seconds >= 0.0) || !std::isfinite(o.seconds)) {
    err << "hapticctl record: --seconds must be a finite number ≥ 0 (got " << o.seconds << ")\n";
    return 2;
  }
  std::vector<std::string> names;
  if (!o.scene_file.empty() && !bodyNames(o.scene_file, names, err))
    return 2;
  OutputFile rows, bodies;
  for (auto [file, path] : {std::pair{&rows, &o.file}, std::pair{&bodies, &o.bodies_file}})
    if (!path->empty() && !file->open(*path)) {
      err << "hapticctl record: cannot create " << *path << ": " << std::strerror(errno) << "\n";
      return 2;
    }
  auto c = openLink(t, "record", LinkUse::kReadStates, false, err);
  if (!c)
    return 1;
  // one state per tick: the tick rate, at most the daemon's largest state rate
  const std::uint32_t max_rate = c->maxStateRateHz();
  const std::uint32_t tick_hz = t.shm_name.empty() ? c->tickRateHz() : 0;
  std::uint32_t rate = o.rate_hz > 0 ? o.rate_hz : (tick_hz > 0 ? tick_hz : max_rate);
  rate = std::clamp<std::uint32_t>(rate, 1, max_rate);
  std::string why;
  const std::uint32_t flags = proto::kSubscribeEachTick | (bodies ? proto::kSubscribeBodies : 0u);
  if (!c->subscribe(rate, flags, &why)) {
    err << "hapticctl record: subscribe: " << why << "\n";
    return 1;
  }
  if (tick_hz > rate)
    err << "hapticctl record: the daemon ticks at " << tick_hz << " Hz and will send " << rate
        << " states/s: ticks in between will be missing\n";
  std::fprintf(rows.get(), "%s\n", recordHeader());
  if (bodies)
    std::fprintf(bodies.get(), "%s\n", bodiesHeader());
  bool write_failed = false, truncated = false;
  TickOrder order([&](const proto::State& s) {
    write_failed = !writeRecordRow(rows.get(), s) || write_failed;
    if (bodies)
      write_failed = !writeBodyRows(bodies.get(), s, names) || write_failed;
    truncated = truncated || (s.state_flags & proto::kStateBodiesTruncated) != 0;
  });
  const bool gone = receiveFor(*c, o.seconds, order);
  order.flush();
  c->close();
  if (order.written() == 0) {  // the files are removed
    err << "hapticctl record: no state came from the daemon"
        << (gone ? " (it went away: its port is closed or its heartbeat stopped)" : "") << "\n";
    return 1;
  }
  if (write_failed || !rows.commit() || (bodies && !bodies.commit())) {
    err << "hapticctl record: writing " << o.file
        << (bodies ? " or " + o.bodies_file : std::string()) << " failed\n";
    return 2;
  }
  reportRecord(order, o, out, err);
  if (truncated)
    err << "hapticctl record: warning: some states listed only the first " << proto::kMaxStateBodies
        << " bodies: the others are missing from " << o.bodies_file << "\n";
  if (gone) {
    err << "hapticctl record: the daemon went away before the end: the record stops at tick "
        << order.lastTick() - 1 << "\n";
    return 1;
  }
  return 0;
}

int runWatch(const DaemonTarget& t, const WatchOptions& o, std::ostream& out, std::ostream& err) {
  auto c = openLink(t, "watch", LinkUse::kReadStates, false, err);
  if (!c)
    return 1;
  const std::uint32_t rate = std::clamp<std::uint32_t>(o.rate_hz, 1, 1000);
  std::string why;
  const std::uint32_t flags = proto::kSubscribeContacts | (o.bodies ? proto::kSubscribeBodies : 0u);
  if (!c->subscribe(rate, flags, &why)) {
    err << "hapticctl watch: subscribe: " << why << "\n";
    return 1;
  }
  // over shared memory every tick is seen: print at most `rate` lines a second
  const bool throttle = !t.shm_name.empty();
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / static_cast<double>(rate)));
  auto next_line = Clock::now();
  std::uint64_t lines = 0;
  int silent_ms = 0;
  while (o.count == 0 || lines < o.count) {
    auto s = c->receiveState(200);
    if (!s && c->gone()) {
      err << "hapticctl watch: the daemon at " << (t.shm_name.empty() ? address(t) : t.shm_name)
          << " went away (its port is closed or its heartbeat stopped)\n";
      c->close();
      return 1;
    }
    if (!s) {
      silent_ms += 200;
      if (silent_ms >= std::max(t.timeout_ms, 1000)) {
        err << "hapticctl watch: no state from the daemon at "
            << (t.shm_name.empty() ? address(t) : t.shm_name) << " for " << silent_ms << " ms\n";
        c->close();
        return 1;
      }
      continue;
    }
    silent_ms = 0;
    if (throttle) {
      if (Clock::now() < next_line)
        continue;
      next_line = Clock::now() + period;
    }
    if (o.json)
      out << stateJson(*s, o.deepest, o.bodies).dump() << "\n" << std::flush;
    else
      out << stateLine(*s, o.deepest, o.bodies) << "\n" << std::flush;
    ++lines;
  }
  c->close();
  return 0;
}

int runSceneEdit(const DaemonTarget& t,
                 const SceneEditOptions& o,
                 std::ostream& out,
                 std::ostream& err) {
  using Kind = SceneEditOptions::Kind;
  const char* verb = o.kind == Kind::kMove ? "move" : o.kind == Kind::kAdd ? "add" : "remove";
  proto::SceneUpdate u;
  if (o.kind == Kind::kRemove) {
    u.removed.push_back(o.body);
  } else {
    const auto pose = wirePose(o, verb, err);
    if (!pose)
      return 2;
    (o.kind == Kind::kMove ? u.poses : u.added).push_back({o.body, *pose});
  }
  auto c = connectUdp(t, err);
  if (!c)
    return 1;
  auto r = c->sceneUpdate(u);
  c->bye();
  if (!r) {
    err << "hapticctl " << verb << ": body " << o.body << ": " << r.error().message << "\n";
    return 1;
  }
  char buf[200];
  if (o.kind == Kind::kRemove)
    std::snprintf(buf, sizeof buf, "removed body %u\n", o.body);
  else
    std::snprintf(buf, sizeof buf, "%s body %u at %.6g %.6g %.6g\n",
                  o.kind == Kind::kMove ? "moved" : "added", o.body, o.px, o.py, o.pz);
  out << buf;
  return 0;
}

}  // namespace hapticd::client
