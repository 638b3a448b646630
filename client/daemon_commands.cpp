#include "client/daemon_commands.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

#include "client/pose_stream.h"
#include "client/tick_order.h"
#include "core/scene/bundle.h"
#include "protocol/client.h"
#include "protocol/command_gate.h"
#include "protocol/server.h"  // monotonicNs
#include "protocol/shm.h"

namespace hapticd::client {
namespace {

using Clock = std::chrono::steady_clock;

std::string address(const DaemonTarget& t) {
  const bool v6 = t.host.find(':') != std::string::npos;
  return (v6 ? "[" + t.host + "]" : t.host) + ":" + std::to_string(t.port);
}

// Connects, or says why not on `err` (exit code 1).
std::unique_ptr<proto::Client> connect(const DaemonTarget& t, std::ostream& err) {
  proto::ClientConfig c;
  c.server = address(t);
  c.timeout_ms = t.timeout_ms;
  if (!t.key_file.empty()) {
    std::ifstream in(t.key_file);
    if (!in) {
      err << "hapticctl: --key-file " << t.key_file << ": cannot read\n";
      return nullptr;
    }
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string why;
    auto key = proto::parseKeyHex(text, &why);
    if (!key) {
      err << "hapticctl: --key-file " << t.key_file << ": " << why << "\n";
      return nullptr;
    }
    c.key = *key;
  }
  auto client = proto::Client::connect(c);
  if (!client) {
    err << "hapticctl: no daemon at " << c.server << " (" << client.error().message << ")\n";
    return nullptr;
  }
  return std::move(client.value());
}

std::string faultText(std::uint32_t bits) {
  if (bits == 0)
    return "none";
  std::string s;
  auto add = [&](std::uint32_t bit, const char* name) {
    if ((bits & bit) != 0)
      s += (s.empty() ? "" : ",") + std::string(name);
  };
  add(proto::kFaultStreamLost, "stream_lost");
  add(proto::kFaultDevice, "device");
  add(proto::kFaultForceClamped, "force_clamped");
  add(proto::kFaultNotFinite, "not_finite");
  add(proto::kFaultTickOverrun, "tick_overrun");
  return s;
}

double norm(const proto::WireVec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

proto::PoseCommand poseCommand(double px,
                               double py,
                               double pz,
                               double qx,
                               double qy,
                               double qz,
                               double qw,
                               std::uint32_t buttons) {
  proto::PoseCommand c;
  const double n = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  c.X_WT.p = {px, py, pz};
  c.X_WT.q = {qx / n, qy / n, qz / n, qw / n};
  c.buttons = buttons;
  return c;
}

bool finite(std::initializer_list<double> v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// ---- the two ways to a daemon: UDP (proto::Client) and shared memory (proto::ShmClient) ----

std::uint64_t nowNs() {
  return proto::monotonicNs();
}

/// What pose, replay, watch and record need of a transport.
class Link {
 public:
  virtual ~Link() = default;
  /// Takes control (arm); false with *why set.
  virtual bool arm(std::string* why) = 0;
  /// Queues one pose command; false with *why set when it cannot be sent.
  virtual bool sendPose(const proto::PoseCommand& cmd, std::string* why) = 0;
  /// States at up to rate_hz (UDP: the server's rate; shared memory: every new tick seen).
  virtual bool subscribe(std::uint32_t rate_hz, std::uint32_t flags, std::string* why) = 0;
  /// The next state not seen yet, waiting up to timeout_ms.
  virtual std::optional<proto::State> receiveState(int timeout_ms) = 0;
  /// The servo rate, Hz (0 when not known).
  virtual std::uint32_t tickRateHz() = 0;
  /// The largest state rate the daemon serves, Hz.
  virtual std::uint32_t maxStateRateHz() const = 0;
  /// Handles what is waiting without blocking (heartbeats, errors).
  virtual void pump() = 0;
  /// Ends the session.
  virtual void close() = 0;
};

class UdpLink final : public Link {
 public:
  explicit UdpLink(std::unique_ptr<proto::Client> c) : c_(std::move(c)) {}
  bool arm(std::string* why) override {
    auto r = c_->arm();
    if (!r)
      *why = r.error().message;
    return r.ok();
  }
  bool sendPose(const proto::PoseCommand& cmd, std::string* why) override {
    auto r = c_->sendPose(cmd);
    if (!r)
      *why = r.error().message;
    return r.ok();
  }
  bool subscribe(std::uint32_t rate_hz, std::uint32_t flags, std::string* why) override {
    auto r = c_->subscribe(rate_hz, flags);
    if (!r)
      *why = r.error().message;
    return r.ok();
  }
  std::optional<proto::State> receiveState(int timeout_ms) override {
    return c_->receiveState(timeout_ms);
  }
  std::uint32_t tickRateHz() override { return c_->welcome().tick_rate_hz; }
  std::uint32_t maxStateRateHz() const override {
    const std::uint32_t m = c_->welcome().max_state_rate_hz;
    return m == 0 ? proto::kMaxStateRateHz : std::min(m, proto::kMaxStateRateHz);
  }
  void pump() override { c_->pump(); }
  void close() override { c_->bye(); }

 private:
  std::unique_ptr<proto::Client> c_;
};

class ShmLink final : public Link {
 public:
  explicit ShmLink(proto::ShmClient c) : c_(std::move(c)) {}
  bool arm(std::string* why) override {
    c_.beat(nowNs());
    if (!pushWaiting([&] { return c_.pushArm(nowNs()); })) {
      *why = "the command ring stayed full (is the daemon consuming it?)";
      return false;
    }
    return true;
  }
  bool sendPose(const proto::PoseCommand& cmd, std::string* why) override {
    c_.beat(nowNs());
    if (!pushWaiting([&] { return c_.pushPose(cmd, nowNs()); })) {
      *why = "the command ring stayed full (is the daemon consuming it?)";
      return false;
    }
    return true;
  }
  bool subscribe(std::uint32_t, std::uint32_t, std::string*) override { return true; }
  std::optional<proto::State> receiveState(int timeout_ms) override {
    const std::uint64_t end =
        nowNs() + static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * 1'000'000;
    proto::ShmState s{};
    for (;;) {
      c_.beat(nowNs());
      if (c_.readState(s) && (!seen_ || s.tick != last_tick_)) {
        seen_ = true;
        last_tick_ = s.tick;
        noteRate(s);
        proto::State out;
        proto::toState(s, out);
        return out;
      }
      if (nowNs() >= end)
        return std::nullopt;
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
  }
  std::uint32_t tickRateHz() override {
    // measured from two states' servo clocks: ticks per second of sim time
    for (int i = 0; i < 3 && rate_hz_ == 0; ++i)
      (void)receiveState(200);
    return rate_hz_;
  }
  std::uint32_t maxStateRateHz() const override { return proto::kMaxStateRateHz; }
  void pump() override { c_.beat(nowNs()); }
  void close() override {}
  bool serverAlive(std::uint64_t timeout_ns) const { return c_.serverAlive(nowNs(), timeout_ns); }

 private:
  template <class F>
  bool pushWaiting(F push) {
    // the daemon drains the ring every tick: a full ring empties within a few ticks
    const std::uint64_t end = nowNs() + 500'000'000;
    while (!push()) {
      if (nowNs() >= end)
        return false;
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    return true;
  }
  void noteRate(const proto::ShmState& s) {
    if (rate_hz_ == 0 && have_ref_ && s.tick > ref_tick_ && s.sim_time_ns > ref_ns_) {
      const double hz = 1e9 * static_cast<double>(s.tick - ref_tick_) /
                        static_cast<double>(s.sim_time_ns - ref_ns_);
      if (std::isfinite(hz) && hz >= 1.0)
        rate_hz_ = static_cast<std::uint32_t>(std::lround(std::min(hz, 1e6)));
    }
    have_ref_ = true;
    ref_tick_ = s.tick;
    ref_ns_ = s.sim_time_ns;
  }

  proto::ShmClient c_;
  bool seen_ = false;
  std::uint64_t last_tick_ = 0;
  bool have_ref_ = false;
  std::uint64_t ref_tick_ = 0;
  std::uint64_t ref_ns_ = 0;
  std::uint32_t rate_hz_ = 0;
};

// The link a command uses: shared memory when t.shm_name is set, else UDP. nullptr after saying
// why on `err` (exit code 1).
std::unique_ptr<Link> openLink(const DaemonTarget& t, const char* command, std::ostream& err) {
  if (t.shm_name.empty()) {
    auto c = connect(t, err);
    if (!c)
      return nullptr;
    return std::make_unique<UdpLink>(std::move(c));
  }
  auto c = proto::ShmClient::attach(t.shm_name);
  if (!c) {
    err << "hapticctl " << command << ": --shm " << t.shm_name << ": " << c.error().message << "\n";
    return nullptr;
  }
  auto link = std::make_unique<ShmLink>(std::move(c).value());
  // the daemon beats every tick; wait a little for a first beat, as UDP waits for Welcome
  const std::uint64_t timeout_ns =
      static_cast<std::uint64_t>(std::max(t.timeout_ms, 1)) * 1'000'000;
  const std::uint64_t end = nowNs() + timeout_ns;
  while (!link->serverAlive(timeout_ns)) {
    if (nowNs() >= end) {
      err << "hapticctl " << command << ": --shm " << t.shm_name << ": the daemon's heartbeat is "
          << "older than " << t.timeout_ms << " ms (is hapticd running?)\n";
      return nullptr;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return link;
}

// Streams `cmd` for `seconds` at `rate_hz` (at least once), keeping the newest state.
bool streamPose(Link& c,
                const proto::PoseCommand& cmd,
                double seconds,
                double rate_hz,
                std::optional<proto::State>& last,
                std::string* why) {
  const auto period = std::chrono::duration<double>(1.0 / std::max(rate_hz, 1.0));
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
proto::PoseCommand commandOf(const PoseSample& s) {
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

std::string formatContacts(const proto::State& s, std::size_t n) {
  std::vector<proto::State::Contact> c = s.contacts;
  std::sort(c.begin(), c.end(), [](const auto& a, const auto& b) { return a.depth_m > b.depth_m; });
  std::string out;
  char buf[160];
  for (std::size_t i = 0; i < std::min(n, c.size()); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.3g m at (%.4g, %.4g, %.4g)", i == 0 ? "" : ", ",
                  c[i].depth_m, c[i].p_W[0], c[i].p_W[1], c[i].p_W[2]);
    out += buf;
  }
  return out;
}

nlohmann::json stateJson(const proto::State& s, std::size_t deepest) {
  nlohmann::json j;
  j["tick"] = s.tick;
  j["t_s"] = static_cast<double>(s.sim_time_ns) * 1e-9;
  j["tick_ns"] = {
      {"p50", s.tick_p50_ns}, {"p99", s.tick_p99_ns}, {"max", s.tick_max_ns}, {"this", s.tick_ns}};
  j["tick_misses"] = s.tick_misses;
  j["pairs_tested"] = s.pairs_tested;
  j["pairs_skipped"] = s.pairs_skipped;
  j["device"] = {{"p", s.X_WD.p}, {"q", s.X_WD.q}};
  j["proxy"] = {{"p", s.X_WP.p}, {"q", s.X_WP.q}};
  j["force_n"] = s.force_n;
  j["force_norm_n"] = norm(s.force_n);
  j["torque_nm"] = s.torque_nm;
  j["torque_norm_nm"] = norm(s.torque_nm);
  j["force_scale"] = s.force_scale;
  j["contacts"] = s.contact_count;
  j["max_penetration_m"] = s.max_penetration_m;
  std::vector<proto::State::Contact> c = s.contacts;
  std::sort(c.begin(), c.end(), [](const auto& a, const auto& b) { return a.depth_m > b.depth_m; });
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < std::min(deepest, c.size()); ++i)
    list.push_back({{"p", c[i].p_W}, {"n", c[i].n_W}, {"depth_m", c[i].depth_m}});
  j["deepest"] = list;
  j["faults"] = faultText(s.fault_bits);
  j["fault_bits"] = s.fault_bits;
  j["armed"] = (s.state_flags & proto::kStateArmed) != 0;
  j["state_flags"] = s.state_flags;
  j["last_command_sequence"] = s.last_command_sequence;
  return j;
}

}  // namespace

const char* recordHeader() {
  return "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
         "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
         "pairs_skipped,tick_ns";
}

int runStatus(const DaemonTarget& t, const StatusOptions& o, std::ostream& out, std::ostream& err) {
  auto c = connect(t, err);
  if (!c)
    return 1;
  auto r = c->status();
  c->bye();
  if (!r) {
    err << "hapticctl status: " << r.error().message << "\n";
    return 1;
  }
  const proto::StatusReply& s = r.value();
  nlohmann::json refused = nlohmann::json::object();
  for (std::size_t i = 1; i < s.refused.size() && i < proto::kErrcCount; ++i)
    refused[proto::errcName(static_cast<proto::Errc>(i))] = s.refused[i];
  if (o.json) {
    nlohmann::json j;
    j["daemon"] = address(t);
    j["device"] = s.device;
    j["scene"] = s.scene;
    j["plan"] = s.plan;
    j["uptime_s"] = static_cast<double>(s.uptime_ns) * 1e-9;
    j["ticks"] = s.ticks;
    j["tick_misses"] = s.tick_misses;
    j["tick_rate_hz"] = s.tick_rate_hz;
    j["measured_tick_hz"] = s.measured_tick_hz;
    j["tick_ns"] = {{"p50", s.tick_p50_ns}, {"p99", s.tick_p99_ns}, {"max", s.tick_max_ns}};
    j["faults"] = faultText(s.fault_bits);
    j["fault_bits"] = s.fault_bits;
    j["armed"] = (s.state_flags & proto::kStateArmed) != 0;
    j["state_flags"] = s.state_flags;
    j["sessions"] = s.sessions;
    j["subscribers"] = s.subscribers;
    j["state_rate_hz"] = s.state_rate_hz;
    j["packets_received"] = s.packets_received;
    j["packets_sent"] = s.packets_sent;
    j["commands_accepted"] = s.commands_accepted;
    j["commands_dropped"] = s.commands_dropped;
    j["refused"] = refused;
    j["shm"] = {{"name", s.shm_name},
                {"serving", (s.shm_flags & proto::kShmServing) != 0},
                {"client_attached", (s.shm_flags & proto::kShmClientAttached) != 0},
                {"client_alive", (s.shm_flags & proto::kShmClientAlive) != 0},
                {"commands", s.shm_commands},
                {"commands_refused", s.shm_commands_refused}};
    j["edits"] = {{"batches_applied", s.edit_batches_applied},
                  {"batches_dropped", s.edit_batches_dropped},
                  {"entries_applied", s.edits_applied},
                  {"entries_refused", s.edits_refused}};
    out << j.dump(2) << "\n";
    return 0;
  }
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "daemon %s\ndevice %s\nscene %s\nticks %" PRIu64
                " (%.1f Hz measured, %.1f Hz "
                "configured), misses %" PRIu64
                "\ntick compute p50 %.1f us, p99 %.1f us, max "
                "%.1f us\nfaults %s, %s\nsessions %u, subscribers %u (%u states/s)\npackets "
                "received %" PRIu64 ", sent %" PRIu64 "\ncommands accepted %" PRIu64
                ", dropped %" PRIu64 "\n",
                address(t).c_str(), s.device.c_str(), s.scene.c_str(), s.ticks, s.measured_tick_hz,
                s.tick_rate_hz, s.tick_misses, s.tick_p50_ns / 1e3, s.tick_p99_ns / 1e3,
                s.tick_max_ns / 1e3, faultText(s.fault_bits).c_str(),
                (s.state_flags & proto::kStateArmed) != 0 ? "armed" : "disarmed", s.sessions,
                s.subscribers, s.state_rate_hz, s.packets_received, s.packets_sent,
                s.commands_accepted, s.commands_dropped);
  out << buf << "refused";
  bool any = false;
  for (auto& [name, n] : refused.items()) {
    if (n.get<std::uint64_t>() == 0)
      continue;
    out << " " << name << "=" << n.get<std::uint64_t>();
    any = true;
  }
  out << (any ? "" : " none") << "\n";
  if ((s.shm_flags & proto::kShmServing) != 0)
    out << "shm " << s.shm_name << ", client "
        << ((s.shm_flags & proto::kShmClientAlive) != 0      ? "alive"
            : (s.shm_flags & proto::kShmClientAttached) != 0 ? "attached, not beating"
                                                             : "none")
        << ", commands " << s.shm_commands << ", refused " << s.shm_commands_refused << "\n";
  else
    out << "shm off\n";
  out << "scene updates applied " << s.edit_batches_applied << " (entries " << s.edits_applied
      << ", refused at the tick " << s.edits_refused << "), dropped " << s.edit_batches_dropped
      << "\nplan:\n"
      << s.plan << (s.plan.empty() || s.plan.back() == '\n' ? "" : "\n");
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
  auto c = connect(t, err);
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
  auto c = connect(t, err);
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
  if (!finite({o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw}) ||
      o.qx * o.qx + o.qy * o.qy + o.qz * o.qz + o.qw * o.qw < 1e-12) {
    err << "hapticctl pose: the position must be finite and the quaternion finite and nonzero\n";
    return 2;
  }
  auto c = openLink(t, "pose", err);
  if (!c)
    return 1;
  std::string why;
  if (o.arm && !c->arm(&why)) {
    err << "hapticctl pose: arm: " << why << "\n";
    return 1;
  }
  if (!c->subscribe(static_cast<std::uint32_t>(std::clamp(o.rate_hz, 1.0, 1000.0)), 0, &why)) {
    err << "hapticctl pose: subscribe: " << why << "\n";
    return 1;
  }
  std::optional<proto::State> last;
  const bool sent = streamPose(*c, poseCommand(o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw, 0),
                               o.seconds, o.rate_hz, last, &why);
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
  auto parsed = parsePoseStream(text.value(), o.file);
  if (!parsed) {
    err << "hapticctl replay: " << parsed.error().message << "\n";
    return 2;
  }
  const std::vector<proto::PoseStreamRow>& rows = parsed.value();
  auto c = openLink(t, "replay", err);
  if (!c)
    return 1;
  std::string why;
  if (o.arm && !c->arm(&why)) {
    err << "hapticctl replay: arm: " << why << "\n";
    return 1;
  }
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
    const PoseSample s = samplePoseStream(rows, t0 + ts, &hint);
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
  std::FILE* f = std::fopen(o.file.c_str(), "w");
  if (f == nullptr) {
    err << "hapticctl record: cannot create " << o.file << "\n";
    return 2;
  }
  auto c = openLink(t, "record", err);
  if (!c) {
    std::fclose(f);
    return 1;
  }
  // one state per tick: the tick rate, at most the daemon's largest state rate
  const std::uint32_t max_rate = c->maxStateRateHz();
  const std::uint32_t tick_hz = t.shm_name.empty() ? c->tickRateHz() : 0;
  std::uint32_t rate = o.rate_hz > 0 ? o.rate_hz : (tick_hz > 0 ? tick_hz : max_rate);
  rate = std::clamp<std::uint32_t>(rate, 1, max_rate);
  std::string why;
  if (!c->subscribe(rate, proto::kSubscribeEachTick, &why)) {
    err << "hapticctl record: subscribe: " << why << "\n";
    std::fclose(f);
    return 1;
  }
  if (tick_hz > rate)
    err << "hapticctl record: the daemon ticks at " << tick_hz << " Hz and will send " << rate
        << " states/s: ticks in between will be missing\n";
  std::fprintf(f, "%s\n", recordHeader());
  bool write_failed = false;
  TickOrder order([&](const proto::State& s) {
    const auto& d = s.X_WD;
    const auto& p = s.X_WP;
    const int n = std::fprintf(
        f,
        "%" PRIu64
        ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%.17g,%u,%u,%u\n",
        s.tick - 1, static_cast<double>(s.sim_time_ns) * 1e-9, d.p[0], d.p[1], d.p[2], d.q[0],
        d.q[1], d.q[2], d.q[3], p.p[0], p.p[1], p.p[2], p.q[0], p.q[1], p.q[2], p.q[3],
        s.force_n[0], s.force_n[1], s.force_n[2], s.torque_nm[0], s.torque_nm[1], s.torque_nm[2],
        s.contact_count, s.max_penetration_m, s.pairs_tested, s.pairs_skipped, s.tick_ns);
    if (n < 0)
      write_failed = true;
  });
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(std::max(o.seconds, 0.0)));
  while (Clock::now() < end) {
    const int ms = static_cast<int>(
        std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count());
    auto s = c->receiveState(std::max(ms, 1));
    if (!s || s->tick == 0)
      continue;  // nothing, or a state before the first tick
    (void)order.push(*s);
  }
  order.flush();
  c->close();
  const bool ok = std::fclose(f) == 0 && !write_failed;
  if (!ok) {
    err << "hapticctl record: writing " << o.file << " failed\n";
    return 2;
  }
  if (order.written() == 0) {
    err << "hapticctl record: no state came from the daemon\n";
    return 1;
  }
  const std::uint64_t first = order.firstTick() - 1, last = order.lastTick() - 1;
  out << "recorded " << order.written() << " rows to " << o.file << " (ticks " << first << ".."
      << last << ", " << order.missing() << " ticks missing)\n";
  if (order.missing() > 0)
    err << "hapticctl record: warning: " << order.missing() << " of the " << (last - first + 1)
        << " ticks from " << first << " to " << last
        << " are missing (states lost, late, or sent below the tick rate): the record is not "
           "complete\n";
  return 0;
}

int runWatch(const DaemonTarget& t, const WatchOptions& o, std::ostream& out, std::ostream& err) {
  auto c = openLink(t, "watch", err);
  if (!c)
    return 1;
  const std::uint32_t rate = std::clamp<std::uint32_t>(o.rate_hz, 1, 1000);
  std::string why;
  if (!c->subscribe(rate, proto::kSubscribeContacts, &why)) {
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
    if (o.json) {
      out << stateJson(*s, o.deepest).dump() << "\n" << std::flush;
      ++lines;
      continue;
    }
    // the 1.0 line as it was, then what minor 1 and the contact list add
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "tick %" PRIu64
                  " t %.3f s | tick p50 %.1f us p99 %.1f us max %.1f us | force "
                  "%.4g N torque %.4g N m scale %.2f | contacts %u | faults %s%s",
                  s->tick, static_cast<double>(s->sim_time_ns) * 1e-9, s->tick_p50_ns / 1e3,
                  s->tick_p99_ns / 1e3, s->tick_max_ns / 1e3, norm(s->force_n), norm(s->torque_nm),
                  s->force_scale, s->contact_count, faultText(s->fault_bits).c_str(),
                  (s->state_flags & proto::kStateArmed) != 0 ? " | armed" : " | disarmed");
    std::string line = buf;
    std::snprintf(buf, sizeof buf,
                  " | this tick %.1f us, pairs %u tested %u skipped, max pen %.3g m",
                  s->tick_ns / 1e3, s->pairs_tested, s->pairs_skipped, s->max_penetration_m);
    line += buf;
    const std::string deepest = formatContacts(*s, o.deepest);
    if (!deepest.empty())
      line += " | deepest " + deepest;
    out << line << "\n" << std::flush;
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
    if (!finite({o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw}) ||
        o.qx * o.qx + o.qy * o.qy + o.qz * o.qz + o.qw * o.qw < 1e-12) {
      err << "hapticctl " << verb
          << ": the position must be finite and the quaternion finite and nonzero\n";
      return 2;
    }
    const proto::PoseCommand c = poseCommand(o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw, 0);
    (o.kind == Kind::kMove ? u.poses : u.added).push_back({o.body, c.X_WT});
  }
  auto c = connect(t, err);
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
