#include "daemon/daemon.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "daemon/clock.h"
#include "daemon/log.h"
#include "daemon/notify.h"
#include "daemon/record_writer.h"
#include "daemon/servo_loop.h"
#include "protocol/server.h"
#include "protocol/shm.h"

namespace hapticd::daemon {
namespace {

using SteadyClock = std::chrono::steady_clock;

double secondsSince(SteadyClock::time_point t) {
  return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

// What the servo thread's real-time setup achieved, handed to the main thread before the loop.
struct ServoSetup {
  bool ok = false;
  std::string error;
  RealtimeReport report;
  std::string scheduling;
};

class Daemon {
 public:
  Daemon(const CommandLine& cli, const Backends& backends) : cli_(cli), backends_(backends) {}
  ~Daemon() { stopNetwork(); }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  int run();

 private:
  // --check-config: the start-up steps run() takes that change nothing outside this process
  // (process and servo-thread real-time setup, the scene and its simulation, the device spec
  // and, for sim and replay, the device itself, the network settings), each refused as run()
  // refuses it. Exit code as run()'s.
  int checkConfig();
  // A scene pipeline built off the servo thread (on the main thread at start-up, on the builder
  // thread on SIGHUP), with what the main thread records about it.
  struct Built {
    std::unique_ptr<ServoScene> scene;
    std::string name;
    std::string plan;  // scene::describePlan of its plan
    std::vector<std::string> body_names;
    std::shared_ptr<const scene::SceneModel> model;  // what scene updates are validated against
  };
  // The network thread's protocol server (issue 8): created before the servo loop runs.
  Result<bool> startNetwork();
  void stopNetwork();
  bool onCommand(const proto::CommandEvent& e);  // network thread: the command ring's producer
  // network thread: the edit ring's producer. Validates `u` against the running scene model;
  // false with *error naming the first bad entry (nothing queued), or the ring full.
  bool onSceneUpdate(const proto::SceneUpdate& u, std::string* error);
  // Main thread, before the servo thread starts: creates the shm segment ([network] shm); a
  // failure is a warning and the daemon runs without it.
  void startShm();
  bool fillState(proto::State& out) const;         // network thread
  void fillStatus(proto::StatusReply& out) const;  // network thread
  // Main thread: an uploaded scene waiting, and no build running: start building it.
  void startUpload();
  Result<Built> buildScene(const Config& config, std::uint64_t generation) const;
  // [servo] realtime, off with the virtual clock
  RealtimeOptions realtimeOptions() const;
  // the device's options: [device] with the sim hand's home at the held body's start pose
  device::DeviceOptions deviceOptions(const Built& built) const;
  // Main thread: hands a built scene to the servo loop.
  void install(Built built);
  // SIGHUP: starts the builder thread (one at a time); finishReload() applies its outcome.
  void startReload();
  void finishReload();
  void drainEvents();
  void writeStatus(const char* phase);
  void logStatusLine();
  std::string summary(ServoExit exit) const;

  const CommandLine& cli_;
  const Backends& backends_;
  Config config_;
  std::unique_ptr<Clock> clock_;
  std::unique_ptr<device::Device> device_;
  std::unique_ptr<ServoLoop> loop_;
  std::unique_ptr<proto::ShmServer> shm_;  // outlives the servo thread's run (reset after join)
  std::string shm_error_;                  // why [network] shm is not served ("" when it is)
  std::unique_ptr<RecordWriter> writer_;
  std::string scene_name_;
  std::uint64_t generation_ = 0;
  ServoSetup setup_;
  RealtimeReport process_rt_;
  std::string last_reload_ = "none";
  std::atomic<bool> servo_done_{false};
  // the reload builder: written by it before reload_done_, read by the main thread after
  Thread reload_thread_;
  std::atomic<bool> reload_done_{false};
  std::optional<Built> reload_result_;
  std::string reload_error_;
  Config reload_config_;
  std::vector<std::string> reload_warnings_;
  std::atomic<int> exit_reason_{-1};
  // network
  std::unique_ptr<proto::Server> server_;
  Thread net_thread_;
  std::atomic<bool> net_stop_{false};
  SteadyClock::time_point started_at_ = SteadyClock::now();
  double servo_rate_hz_ = 1000.0;  // [servo] rate_hz (restart-only), set before the network runs
  mutable std::mutex info_mutex_;  // guards the three strings below (network thread reads them)
  std::string info_device_;
  std::string info_scene_;
  std::string info_plan_;
  // the scene updates are validated against (network thread reads; guarded by info_mutex_):
  // set after the scene is offered, so that a batch validated against it meets it at the servo
  std::shared_ptr<const scene::SceneModel> edit_model_;
  std::uint64_t edit_generation_ = 0;
  std::uint64_t edit_batches_ = 0;   // network thread: batches numbered for the log
  std::unique_ptr<EditBatch> edit_;  // network thread: scratch (too big for the stack)
  std::mutex upload_mutex_;
  std::deque<proto::SceneUploadDone> uploads_;             // guarded by upload_mutex_
  std::optional<proto::SceneUploadDone> upload_building_;  // main thread: the one being built
};

Result<Daemon::Built> Daemon::buildScene(const Config& config, std::uint64_t generation) const {
  auto scene = backends_.load_scene(config);
  if (!scene)
    return scene.error();
  auto model = scene.value();
  auto sim = backends_.make_simulation(model, toSimOptions(config));
  if (!sim)
    return Error{"scene '" + model->name + "': " + sim.error().message};
  Built built;
  built.scene = std::make_unique<ServoScene>();
  built.scene->sim = std::move(sim.value());
  built.scene->generation = generation;
  built.name = model->name;
  built.model = model;
  built.plan = scene::describePlan(model->plan);
  built.body_names.reserve(model->bodies.size());
  for (const auto& b : model->bodies)
    built.body_names.push_back(b.name);
  return built;
}

RealtimeOptions Daemon::realtimeOptions() const {
  RealtimeOptions rt = toRealtimeOptions(config_);
  if (config_.servo.clock == ClockKind::kVirtual)
    rt.policy = RealtimePolicy::kOff;  // a FIFO thread that never sleeps starves the others
  return rt;
}

device::DeviceOptions Daemon::deviceOptions(const Built& built) const {
  device::DeviceOptions o = config_.device.options;
  if (config_.device.sim_home_from_scene && built.model && built.model->probe_body >= 0)
    o.sim_home = config_.device.workspace.toDevice(
        built.model->bodies[static_cast<std::size_t>(built.model->probe_body)].X_WB);
  return o;
}

void Daemon::install(Built built) {
  generation_ = built.scene->generation;
  scene_name_ = built.name;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    info_scene_ = built.name;
    info_plan_ = built.plan;
  }
  if (writer_)
    writer_->setBodyNames(generation_, std::move(built.body_names));
  auto model = std::move(built.model);
  loop_->offerScene(std::move(built.scene));
  std::lock_guard<std::mutex> lock(info_mutex_);
  edit_model_ = std::move(model);
  edit_generation_ = generation_;
}

void Daemon::startReload() {
  if (reload_thread_.joinable()) {
    logWarning("SIGHUP: a reload is still being built; this one is ignored");
    return;
  }
  notifyReloading();
  logInfo("SIGHUP: reloading the configuration and the scene");
  reload_done_ = false;
  reload_result_.reset();
  reload_error_.clear();
  auto started = reload_thread_.start("hapticd-build", 4 << 20, [this] {
    // off the main thread, so that a large scene does not hold up the watchdog and the log
    auto config = buildConfig(cli_);
    if (!config) {
      reload_error_ = config.error().message;
    } else {
      reload_warnings_ = config.value().warnings;
      Config next = config.value().config;
      reload_config_ = next;
      next.servo = config_.servo;  // restart-only sections keep running as they are
      next.device = config_.device;
      next.network = config_.network;
      auto built = buildScene(next, generation_ + 1);
      if (!built)
        reload_error_ = built.error().message;
      else
        reload_result_ = std::move(built.value());
    }
    reload_done_ = true;
  });
  if (!started)
    logError("reload: " + started.error().message);
}

void Daemon::finishReload() {
  if (!reload_thread_.joinable() || !reload_done_.load())
    return;
  reload_thread_.join();
  if (upload_building_) {
    const proto::SceneUploadDone up = std::move(*upload_building_);
    upload_building_.reset();
    if (!reload_result_) {
      logError("upload '" + up.name + "' refused, keeping scene '" + scene_name_ +
               "': " + reload_error_);
      if (server_)
        server_->finishScene(up.ticket, false, reload_error_);
      return;
    }
    reload_result_->name = up.name.empty() ? reload_result_->name : up.name;
    install(std::move(*reload_result_));
    reload_result_.reset();
    last_reload_ =
        "ok: uploaded scene '" + scene_name_ + "' generation " + std::to_string(generation_);
    logInfo("upload: scene '" + scene_name_ + "' (generation " + std::to_string(generation_) +
            ") handed to the servo loop");
    if (server_)
      server_->finishScene(up.ticket, true, "");
    return;
  }
  if (!reload_result_) {
    last_reload_ = "refused: " + reload_error_;
    logError("reload refused, keeping the running configuration and scene: " + reload_error_);
    notifyReady("running; last reload refused");
    return;
  }
  for (const auto& w : reload_warnings_)
    logWarning(w);
  Config next = reload_config_;
  static constexpr std::string_view kRestartOnly[] = {"servo", "device", "network"};
  if (const auto changed = changedKeys(config_, next, kRestartOnly); !changed.empty()) {
    std::string list;
    for (const auto& k : changed)
      list += (list.empty() ? "" : ", ") + k;
    logWarning("reload: changes to [servo], [device] and [network] take effect at restart (" +
               list + ")");
  }
  next.servo = config_.servo;
  next.device = config_.device;
  next.network = config_.network;
  config_ = next;
  setLogLevel(config_.log.level);
  install(std::move(*reload_result_));
  reload_result_.reset();
  last_reload_ = "ok: scene '" + scene_name_ + "' generation " + std::to_string(generation_);
  logInfo("reload: scene '" + scene_name_ + "' (generation " + std::to_string(generation_) +
          ") handed to the servo loop");
  notifyReady("running; reloaded");
}

void Daemon::startUpload() {
  if (reload_thread_.joinable())
    return;  // a build (SIGHUP or upload) runs; this one waits
  {
    std::lock_guard<std::mutex> lock(upload_mutex_);
    if (uploads_.empty())
      return;
    upload_building_ = std::move(uploads_.front());
    uploads_.pop_front();
  }
  reload_done_ = false;
  reload_result_.reset();
  reload_error_.clear();
  logInfo("upload: building scene '" + upload_building_->name + "' (" +
          std::to_string(upload_building_->bytes.size()) + " bytes)");
  auto started = reload_thread_.start("hapticd-build", 4 << 20, [this] {
    // the same loader as SIGHUP, on the uploaded bytes: they go to a private file that the
    // configured loader reads, then the file is removed; the loader's text names the upload
    const proto::SceneUploadDone& up = *upload_building_;
    std::error_code ec;
    std::string tmpl =
        (std::filesystem::temp_directory_path(ec) / "hapticd-upload-XXXXXX.glb").string();
    const int fd = mkstemps(tmpl.data(), 4);
    if (fd < 0) {
      reload_error_ = "cannot store the upload in " + tmpl + ": " + std::strerror(errno);
      reload_done_ = true;
      return;
    }
    std::size_t done = 0;
    while (done < up.bytes.size()) {
      const ssize_t n = ::write(fd, up.bytes.data() + done, up.bytes.size() - done);
      if (n <= 0)
        break;
      done += static_cast<std::size_t>(n);
    }
    ::close(fd);
    if (done != up.bytes.size()) {
      reload_error_ = "cannot store the upload in " + tmpl;
    } else {
      Config next = config_;
      next.scene.path = tmpl;
      auto built = buildScene(next, generation_ + 1);
      if (built) {
        reload_result_ = std::move(built.value());
      } else {
        std::string text = built.error().message;
        const std::string label = up.name.empty() ? std::string("upload") : up.name;
        for (std::size_t at = text.find(tmpl); at != std::string::npos; at = text.find(tmpl))
          text.replace(at, tmpl.size(), label);
        reload_error_ = text;
      }
    }
    std::filesystem::remove(tmpl, ec);
    reload_done_ = true;
  });
  if (!started) {
    logError("upload: " + started.error().message);
    if (server_)
      server_->finishScene(upload_building_->ticket, false, started.error().message);
    upload_building_.reset();
  }
}

bool Daemon::onCommand(const proto::CommandEvent& e) {
  const CommandKind kind = e.kind == proto::CommandEvent::Kind::kArm      ? CommandKind::kArm
                           : e.kind == proto::CommandEvent::Kind::kDisarm ? CommandKind::kDisarm
                                                                          : CommandKind::kPose;
  return loop_->sendCommand(gatedCommand(kind, e.session_id, e.sequence, e.pose));
}

namespace {
proto::WirePose toWire(const geom::Pose& X) {
  proto::WirePose w;
  w.p = {X.translation.x, X.translation.y, X.translation.z};
  w.q = {X.rotation.x, X.rotation.y, X.rotation.z, X.rotation.w};
  return w;
}
// after poseProblem() found nothing: the quaternion, within the wire's tolerance of unit length,
// is normalised
geom::Pose fromWire(const proto::WirePose& w) {
  return geom::Pose::fromXyzw(geom::Vec3(w.p[0], w.p[1], w.p[2]), w.q[0], w.q[1], w.q[2], w.q[3]);
}
// The pid of a live hapticd other than this process serving segment `name`, or 0 (no segment,
// a stale one, or this process's own). Stale: its server process is gone, or its heartbeat (each
// tick) stopped more than 5 s ago, so that a dead daemon's pid reused by another process does not
// keep the segment forever (a heartbeat of 0: the server has not ticked yet, it counts as live).
std::uint64_t liveShmOwner(const std::string& name) {
  const int fd = ::shm_open(name.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0)
    return 0;
  void* p = ::mmap(nullptr, sizeof(proto::ShmHeader), PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED)
    return 0;
  const auto* h = static_cast<const proto::ShmHeader*>(p);
  std::uint64_t pid = 0, beat = 0;
  if (h->magic == proto::kShmMagic) {
    pid = h->server_pid.load(std::memory_order_acquire);
    beat = h->server_heartbeat_ns.load(std::memory_order_acquire);
  }
  ::munmap(p, sizeof(proto::ShmHeader));
  const std::uint64_t now = proto::monotonicNs();
  if (beat != 0 && now > beat && now - beat > 5'000'000'000ull)
    return 0;
  if (pid == 0 || pid == static_cast<std::uint64_t>(::getpid()) || pid > 0x7fffffff)
    return 0;
  // alive: kill(pid, 0) succeeds, or fails only for permission (another user's process)
  if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM)
    return pid;
  return 0;
}
const char* motionName(scene::Motion m) {
  switch (m) {
    case scene::Motion::kStatic:
      return "static";
    case scene::Motion::kKinematic:
      return "kinematic";
    case scene::Motion::kDynamic:
      return "dynamic";
  }
  return "?";
}
// "" when `w` is a finite pose with a unit quaternion (the wire's tolerance), else what is wrong
std::string poseProblem(const proto::WirePose& w) {
  for (double v : w.p)
    if (!std::isfinite(v))
      return "its position is not finite";
  double n2 = 0.0;
  for (double v : w.q) {
    if (!std::isfinite(v))
      return "its quaternion is not finite";
    n2 += v * v;
  }
  if (std::fabs(std::sqrt(n2) - 1.0) > proto::kQuatNormTolerance) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "its quaternion has length %.6g, not 1", std::sqrt(n2));
    return buf;
  }
  return "";
}
// The protocol server's settings of [network] and [servo] rate_hz: the key file read and parsed,
// a non-loopback address refused without a key. Errors name the key.
Result<proto::ServerConfig> serverConfigOf(const Config& c) {
  proto::ServerConfig cfg;
  cfg.bind_address = c.network.udp;
  cfg.tick_rate_hz = static_cast<std::uint32_t>(std::lround(c.servo.rate_hz));
  cfg.rate_limit.packets_per_s = c.network.rate_limit_packets_per_s;
  cfg.rate_limit.burst = c.network.rate_limit_burst;
  cfg.max_datagram_bytes = static_cast<std::size_t>(c.network.max_datagram_bytes);
  cfg.max_state_rate_hz = static_cast<std::uint32_t>(std::lround(c.network.max_state_rate_hz));
  if (!c.network.key_file.empty()) {
    std::ifstream in(c.network.key_file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof())
      return Error{"[network] key_file: cannot read '" + c.network.key_file + "'"};
    std::string why;
    auto key = proto::parseKeyHex(text, &why);
    if (!key)
      return Error{"[network] key_file '" + c.network.key_file + "': " + why};
    cfg.key = *key;
  }
  auto address = proto::parseAddress(c.network.udp);
  if (!address)
    return Error{"[network] udp: " + address.error().message};
  if (!address.value().isLoopback() && !cfg.key)
    return Error{"[network] udp: " + address.value().toString() +
                 " is not a loopback address and [network] key_file is not set: set key_file "
                 "(64 hex digits) to serve other hosts"};
  return cfg;
}
std::uint32_t clampU32(std::int64_t ns) {
  return static_cast<std::uint32_t>(std::clamp<std::int64_t>(ns, 0, 0xffffffffLL));
}
}  // namespace

bool Daemon::fillState(proto::State& out) const {
  const ServoState st = loop_->state();
  if (st.tick == 0)
    return false;
  out.tick = st.tick;
  out.sim_time_ns = static_cast<std::uint64_t>(std::llround(st.t_s * 1e9));
  out.X_WD = toWire(st.X_W_device);
  out.X_WP = toWire(st.X_W_proxy);
  out.force_n = {st.force_W_n.x, st.force_W_n.y, st.force_W_n.z};
  out.torque_nm = {st.torque_W_nm.x, st.torque_W_nm.y, st.torque_W_nm.z};
  out.force_scale = std::clamp(st.output_gain * st.gate_scale, 0.0, 1.0);
  out.last_command_sequence = st.last_command_sequence;
  out.tick_misses = st.overruns;
  const auto& cmp = loop_->compute();
  out.tick_p50_ns = clampU32(cmp.quantileNs(0.5));
  out.tick_p99_ns = clampU32(cmp.quantileNs(0.99));
  out.tick_max_ns = clampU32(cmp.maxNs());
  out.fault_bits = wireFaultBits(st.faults);
  out.state_flags = wireStateFlags(st);
  out.contact_count = st.contacts;
  out.pairs_tested = st.pairs_tested;
  out.pairs_skipped = st.pairs_skipped;
  out.max_penetration_m =
      std::isfinite(st.max_penetration_m) ? std::max(0.0, st.max_penetration_m) : 0.0;
  out.tick_ns = clampU32(st.last_tick_ns);
  // the lists of the newest tick (published by the servo thread right after the state block: at
  // most a tick apart from the fields above)
  const ServoLists l = loop_->lists();
  out.contacts.clear();
  out.bodies.clear();
  out.contacts.reserve(l.contact_count);
  for (std::uint32_t i = 0; i < l.contact_count && i < kListContacts; ++i) {
    const sim::ContactPoint& c = l.contacts[i];
    proto::State::Contact w;
    w.p_W = {c.p_W.x, c.p_W.y, c.p_W.z};
    w.n_W = {c.n_W.x, c.n_W.y, c.n_W.z};
    w.depth_m = c.depth_m;
    out.contacts.push_back(w);
  }
  if (l.contacts_total > l.contact_count)
    out.state_flags |= proto::kStateContactsTruncated;
  out.bodies.reserve(l.body_count);
  for (std::uint32_t i = 0; i < l.body_count && i < kListBodies; ++i)
    out.bodies.push_back({l.bodies[i].body, toWire(l.bodies[i].X_WB)});
  if (l.bodies_total > l.body_count)
    out.state_flags |= proto::kStateBodiesTruncated;
  return true;
}

bool Daemon::onSceneUpdate(const proto::SceneUpdate& u, std::string* error) {
  std::shared_ptr<const scene::SceneModel> model;
  std::uint64_t generation = 0;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    model = edit_model_;
    generation = edit_generation_;
  }
  if (!model) {
    *error = "no scene is running";
    return false;
  }
  if (u.poses.size() > kMaxEditEntries || u.added.size() > kMaxEditEntries ||
      u.removed.size() > kMaxEditEntries) {
    *error = "more than " + std::to_string(kMaxEditEntries) + " entries in a list";
    return false;
  }
  const std::size_t n = model->bodies.size();
  // the first bad entry, named: "poses[2]: body 7 'lid' is dynamic, not kinematic"
  auto check = [&](const char* list, std::size_t i, std::uint32_t body, bool pose_for_kinematic,
                   const proto::WirePose* X) -> bool {
    const std::string at =
        std::string(list) + "[" + std::to_string(i) + "]: body " + std::to_string(body);
    if (body >= n) {
      *error = at + " does not exist (scene '" + model->name + "' has " + std::to_string(n) +
               " bodies, 0.." + std::to_string(n == 0 ? 0 : n - 1) + ")";
      return false;
    }
    const scene::Body& b = model->bodies[body];
    const std::string named = at + " '" + b.name + "'";
    if (static_cast<std::int32_t>(body) == model->probe_body || b.probe) {
      *error = named + " is the probe (held) body: clients cannot move, add or remove it";
      return false;
    }
    if (b.motion == scene::Motion::kStatic) {
      *error = named + " is static: static bodies are never moved, added or removed";
      return false;
    }
    if (pose_for_kinematic && b.motion != scene::Motion::kKinematic) {
      *error = named + " is " + motionName(b.motion) + ", not kinematic";
      return false;
    }
    if (X != nullptr) {
      if (const std::string p = poseProblem(*X); !p.empty()) {
        *error = named + ": " + p;
        return false;
      }
    }
    return true;
  };
  for (std::size_t i = 0; i < u.poses.size(); ++i)
    if (!check("poses", i, u.poses[i].body_index, true, &u.poses[i].X_WB))
      return false;
  for (std::size_t i = 0; i < u.added.size(); ++i)
    if (!check("added", i, u.added[i].body_index, false, &u.added[i].X_WB))
      return false;
  for (std::size_t i = 0; i < u.removed.size(); ++i)
    if (!check("removed", i, u.removed[i], false, nullptr))
      return false;

  EditBatch& b = *edit_;
  b.generation = generation;
  b.id = ++edit_batches_;
  b.pose_count = static_cast<std::uint32_t>(u.poses.size());
  b.add_count = static_cast<std::uint32_t>(u.added.size());
  b.remove_count = static_cast<std::uint32_t>(u.removed.size());
  for (std::size_t i = 0; i < u.poses.size(); ++i)
    b.poses[i] = {u.poses[i].body_index, fromWire(u.poses[i].X_WB)};
  for (std::size_t i = 0; i < u.added.size(); ++i)
    b.added[i] = {u.added[i].body_index, fromWire(u.added[i].X_WB)};
  for (std::size_t i = 0; i < u.removed.size(); ++i)
    b.removed[i] = u.removed[i];
  if (!loop_->sendEdits(b)) {
    *error = "the servo's edit queue is full (" + std::to_string(loop_->editCapacity()) +
             " updates waiting): send it again";
    return false;
  }
  return true;
}

void Daemon::fillStatus(proto::StatusReply& r) const {
  const ServoState st = loop_->state();
  r.uptime_ns = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now() - started_at_)
          .count());
  r.ticks = st.tick;
  r.tick_misses = st.overruns;
  r.tick_rate_hz = servo_rate_hz_;
  const double loop_s = st.t_s + 1.0 / servo_rate_hz_;
  r.measured_tick_hz = st.tick > 0 && loop_s > 0.0 ? static_cast<double>(st.tick) / loop_s : 0.0;
  const auto& cmp = loop_->compute();
  r.tick_p50_ns = clampU32(cmp.quantileNs(0.5));
  r.tick_p99_ns = clampU32(cmp.quantileNs(0.99));
  r.tick_max_ns = clampU32(cmp.maxNs());
  r.fault_bits = wireFaultBits(st.faults);
  r.state_flags = wireStateFlags(st);
  r.commands_accepted = st.commands_accepted;
  r.commands_dropped = st.commands_dropped;
  r.edit_batches_applied = st.edit_batches_applied;  // protocol minor 1
  r.edit_batches_dropped = st.edit_batches_dropped;
  r.edits_applied = st.edits_applied;
  r.edits_refused = st.edits_refused;
  r.shm_commands = st.shm_commands;
  if (shm_) {
    r.shm_name = shm_->name().substr(0, proto::kMaxShmNameBytes);
    r.shm_flags = proto::kShmServing;
    if (shm_->clientAttached())
      r.shm_flags |= proto::kShmClientAttached;
    if (shm_->clientAlive(proto::monotonicNs(), kShmAliveTimeoutNs))
      r.shm_flags |= proto::kShmClientAlive;
    r.shm_commands_refused = shm_->commandsRefused();
  }
  std::lock_guard<std::mutex> lock(info_mutex_);
  r.device = info_device_.substr(0, proto::kMaxDeviceBytes);
  r.scene = info_scene_.substr(0, proto::kMaxSceneNameBytes);
  r.plan = info_plan_.substr(0, proto::kMaxPlanBytes);
}

void Daemon::startShm() {
  const std::string& name = config_.network.shm;
  if (name.empty()) {
    shm_error_ = "off ([network] shm = \"\")";
    return;
  }
  if (const std::uint64_t pid = liveShmOwner(name); pid != 0) {
    shm_error_ =
        "segment " + name + " is served by another hapticd (pid " + std::to_string(pid) + ")";
    logWarning("[network] shm \"" + name + "\": " + shm_error_ + "; running without shared memory");
    return;
  }
  auto created = proto::ShmServer::create(name);
  if (!created) {
    shm_error_ = created.error().message;
    logWarning("[network] shm \"" + name + "\": " + shm_error_ + "; running without shared memory");
    return;
  }
  shm_ = std::make_unique<proto::ShmServer>(std::move(created.value()));
  loop_->attachShm(shm_.get());
  logInfo("shared memory: segment " + name + " (clients on this host: proto::ShmClient)");
}

Result<bool> Daemon::startNetwork() {
  auto settings = serverConfigOf(config_);
  if (!settings)
    return settings.error();
  proto::ServerConfig cfg = std::move(settings.value());
  servo_rate_hz_ = config_.servo.rate_hz;
  proto::ServerHandlers h;
  h.on_command = [this](const proto::CommandEvent& e) { return onCommand(e); };
  h.on_scene = [this](proto::SceneUploadDone&& up) {
    std::lock_guard<std::mutex> lock(upload_mutex_);
    uploads_.push_back(std::move(up));
  };
  edit_ = std::make_unique<EditBatch>();
  h.on_scene_update = [this](std::uint64_t, const proto::SceneUpdate& u, std::string* error) {
    return onSceneUpdate(u, error);
  };
  h.fill_state = [this](proto::State& st) { return fillState(st); };
  h.fill_status = [this](proto::StatusReply& r) { fillStatus(r); };
  auto created = proto::Server::create(cfg, std::move(h));
  if (!created)
    return Error{"[network] udp " + config_.network.udp + ": " + created.error().message};
  server_ = std::move(created.value());
  logInfo("network: protocol on udp " + server_->localAddress().toString() +
          (cfg.key ? ", pre-shared key" : ", no key"));
  auto started = net_thread_.start("hapticd-net", 1 << 20, [this] { server_->run(net_stop_); });
  if (!started) {
    server_.reset();
    return started.error();
  }
  return true;
}

void Daemon::stopNetwork() {
  net_stop_ = true;
  net_thread_.join();
}

void Daemon::drainEvents() {
  ServoEvent e;
  while (loop_->popEvent(e)) {
    const bool bad =
        e.kind == ServoEventKind::kMissFault || e.kind == ServoEventKind::kNonFiniteForce ||
        e.kind == ServoEventKind::kDeviceLost || e.kind == ServoEventKind::kRecordDropped ||
        e.kind == ServoEventKind::kDeviceWriteFailed || e.kind == ServoEventKind::kEditRefused ||
        e.kind == ServoEventKind::kEditBatchDropped;
    logLine(bad ? LogLevel::kWarning : LogLevel::kInfo, describe(e));
  }
}

void Daemon::writeStatus(const char* phase) {
  if (cli_.status_file.empty())
    return;
  const ServoState st = loop_->state();
  nlohmann::json j;
  j["phase"] = phase;
  j["tick"] = st.tick;
  j["t_s"] = st.t_s;
  j["period_index"] = st.period_index;
  j["rate_hz"] = config_.servo.rate_hz;
  j["clock"] = toString(config_.servo.clock);
  j["device"] = {{"name", device_->info().name},
                 {"connected", st.device_connected},
                 {"lost_count", st.device_lost_count}};
  j["scene"] = {{"name", scene_name_},
                {"generation", st.scene_generation},
                {"offered_generation", generation_}};
  j["armed"] = st.armed;
  j["stopping"] = st.stopping;
  j["running"] = st.running;
  j["faults"] = {{"bits", st.faults},
                 {"misses", (st.faults & kFaultMisses) != 0},
                 {"non_finite", (st.faults & kFaultNonFinite) != 0}};
  j["overruns"] = st.overruns;
  j["skipped_periods"] = st.skipped_periods;
  j["consecutive_misses"] = st.consecutive_misses;
  j["force_n"] = {st.force_W_n.x, st.force_W_n.y, st.force_W_n.z};
  j["torque_nm"] = {st.torque_W_nm.x, st.torque_W_nm.y, st.torque_W_nm.z};
  j["contacts"] = st.contacts;
  j["max_penetration_m"] = st.max_penetration_m;
  j["pairs_tested"] = st.pairs_tested;
  j["pairs_skipped"] = st.pairs_skipped;
  j["last_tick_ns"] = st.last_tick_ns;
  j["peak_force_n"] = st.peak_force_n;
  j["output_gain"] = st.output_gain;
  j["last_command_sequence"] = st.last_command_sequence;
  j["records_dropped"] = st.records_dropped;
  const auto& lat = loop_->lateness();
  const auto& cmp = loop_->compute();
  j["lateness_ns"] = {{"p50", lat.quantileNs(0.5)},
                      {"p99", lat.quantileNs(0.99)},
                      {"p999", lat.quantileNs(0.999)},
                      {"max", lat.maxNs()}};
  j["compute_ns"] = {{"p50", cmp.quantileNs(0.5)},
                     {"p99", cmp.quantileNs(0.99)},
                     {"p999", cmp.quantileNs(0.999)},
                     {"max", cmp.maxNs()}};
  j["realtime"] = {{"policy", toString(config_.servo.realtime)},
                   {"memory_locked", process_rt_.memory_locked},
                   {"fifo", setup_.report.fifo},
                   {"pinned", setup_.report.pinned},
                   {"servo_scheduling", setup_.scheduling}};
  j["last_reload"] = last_reload_;
  j["edits"] = {{"batches_applied", st.edit_batches_applied},
                {"batches_dropped", st.edit_batches_dropped},
                {"entries_applied", st.edits_applied},
                {"entries_refused", st.edits_refused},
                {"pending", loop_->editsPending()}};
  {
    nlohmann::json shm = {{"name", config_.network.shm}, {"serving", shm_ != nullptr}};
    if (shm_) {
      const std::uint64_t now = proto::monotonicNs();
      shm["client_attached"] = shm_->clientAttached();
      shm["client_alive"] = shm_->clientAlive(now, kShmAliveTimeoutNs);
      shm["commands"] = st.shm_commands;
      shm["commands_refused"] = shm_->commandsRefused();
    } else {
      shm["why_not"] = shm_error_;
    }
    j["shm"] = shm;
  }
  if (server_) {
    const auto& c = server_->counters();
    j["network"] = {{"udp", server_->localAddress().toString()},
                    {"sessions", c.sessions.load()},
                    {"received", c.received.load()},
                    {"states_sent", c.states_sent.load()},
                    {"commands_forwarded", c.commands_forwarded.load()},
                    {"commands_queue_full", c.commands_queue_full.load()}};
  }
  j["pid"] = static_cast<long>(getpid());
  const std::string tmp = cli_.status_file + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << j.dump(2) << "\n";
    if (!out)
      return;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, cli_.status_file, ec);
}

void Daemon::logStatusLine() {
  const ServoState st = loop_->state();
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "status: tick %" PRIu64 ", faults %u, overruns %" PRIu64
                ", device %s, force %.3f N",
                st.tick, st.faults, st.overruns, st.device_connected ? "connected" : "LOST",
                glm::length(st.force_W_n));
  logInfo(std::string(buf) + "; lateness " + loop_->lateness().summary() + "; compute " +
          loop_->compute().summary());
}

std::string Daemon::summary(ServoExit exit) const {
  const ServoState st = loop_->state();
  const char* why = exit == ServoExit::kEndOfStream ? "end of stream"
                    : exit == ServoExit::kMaxTicks  ? "tick limit"
                                                    : "stopped";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "hapticd: %s: %" PRIu64
                " ticks, %.3f s %s time, scene '%s', peak force %.6g N, "
                "peak penetration %.6g m, contact ticks %" PRIu64 ", overruns %" PRIu64
                ", faults %u, records %" PRIu64 " (dropped %" PRIu64
                "), tick p50 %.1f us p99 %.1f us "
                "max %.1f us",
                why, st.tick, st.tick > 0 ? st.t_s + 1.0 / config_.servo.rate_hz : 0.0,
                config_.servo.clock == ClockKind::kVirtual ? "simulated" : "loop",
                scene_name_.c_str(), st.peak_force_n, st.peak_penetration_m, st.contact_ticks,
                st.overruns, st.faults, writer_ ? writer_->rowsWritten() : 0, st.records_dropped,
                static_cast<double>(loop_->compute().quantileNs(0.5)) / 1e3,
                static_cast<double>(loop_->compute().quantileNs(0.99)) / 1e3,
                static_cast<double>(loop_->compute().maxNs()) / 1e3);
  return buf;
}

int Daemon::checkConfig() {
  const RealtimeOptions rt = realtimeOptions();
  auto prt = setupProcessRealtime(rt, backends_.realtime);
  if (!prt) {
    logError(prt.error().message);
    return kExitFailure;
  }
  for (const auto& w : prt.value().warnings)
    logWarning(w);
  auto scene = buildScene(config_, 1);
  if (!scene) {
    logError("cannot load the scene: " + scene.error().message);
    return kExitFailure;
  }
  auto spec = device::parseDeviceSpec(config_.device.spec);
  if (!spec) {
    logError("device: " + spec.error().message);
    return kExitFailure;
  }
  if (spec.value().openIsHarmless()) {
    auto device = backends_.make_device(config_.device.spec, deviceOptions(scene.value()));
    if (!device) {
      logError("device: " + device.error().message);
      return kExitFailure;
    }
  }
  if (auto net = serverConfigOf(config_); !net) {
    logError(net.error().message);
    return kExitFailure;
  }
  // the servo thread's setup, on a thread that ends at once
  Result<RealtimeReport> servo_rt = Error{"the servo thread did not start"};
  Thread servo;
  if (auto started =
          servo.start("hapticd-servo", 1 << 20,
                      [&] { servo_rt = setupServoThreadRealtime(rt, backends_.realtime); });
      !started) {
    logError(started.error().message);
    return kExitFailure;
  }
  servo.join();
  if (!servo_rt) {
    logError(servo_rt.error().message);
    return kExitFailure;
  }
  for (const auto& w : servo_rt.value().warnings)
    logWarning(w);
  std::printf("configuration ok%s: scene '%s', device '%s'\n",
              cli_.config_path ? (": " + *cli_.config_path).c_str() : " (built-in defaults)",
              scene.value().name.c_str(), config_.device.spec.c_str());
  return kExitOk;
}

int Daemon::run() {
  // 1. configuration
  auto config = buildConfig(cli_);
  if (!config) {
    logError(config.error().message);
    return kExitBadConfig;
  }
  config_ = config.value().config;
  setLogLevel(config_.log.level);
  for (const auto& w : config.value().warnings)
    logWarning(w);
  if (cli_.print_config) {
    std::fputs(toToml(config_).c_str(), stdout);
    return kExitOk;
  }
  if (cli_.check_config)
    return checkConfig();
  const bool virtual_clock = config_.servo.clock == ClockKind::kVirtual;

  // 2. signals: blocked here so that every thread started below inherits the mask; the main
  // thread takes them with sigtimedwait()
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // 3. process real-time setup (memory locking), before any thread starts
  const RealtimeOptions rt = realtimeOptions();
  if (virtual_clock && config_.servo.realtime != RealtimePolicy::kOff)
    logInfo("virtual clock: real-time scheduling and memory locking skipped");
  auto prt = setupProcessRealtime(rt, backends_.realtime);
  if (!prt) {
    logError(prt.error().message);
    return kExitFailure;
  }
  process_rt_ = prt.value();
  for (const auto& w : process_rt_.warnings)
    logWarning(w);

  // 4. the scene and its simulation (handed to the loop below, before it starts); first, so that
  // the sim hand can start where the held body starts
  auto scene = buildScene(config_, 1);
  if (!scene) {
    logError("cannot load the scene: " + scene.error().message);
    return kExitFailure;
  }

  // 4b. device
  const device::DeviceOptions device_options = deviceOptions(scene.value());
  auto device = backends_.make_device(config_.device.spec, device_options);
  if (!device) {
    logError("device: " + device.error().message);
    return kExitFailure;
  }
  device_ = std::move(device.value());
  logInfo("device: " + device_->info().name);
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    info_device_ = device_->info().name;
  }

  // 5. clock and servo loop (rings allocated here, before the loop starts)
  if (virtual_clock)
    clock_ = std::make_unique<VirtualClock>();
  else
    clock_ = std::make_unique<MonotonicClock>();
  ServoOptions servo = toServoOptions(config_, device_->info());
  servo.record = !cli_.record.empty();
  servo.record_bodies = !cli_.record_bodies.empty();
  servo.wait_for_record_space = virtual_clock;
  servo.max_ticks = cli_.ticks;
  loop_ = std::make_unique<ServoLoop>(servo, *clock_, *device_, nullptr);

  // 6. record writer (files opened now: a bad path fails start-up)
  if (servo.record || servo.record_bodies) {
    auto w = RecordWriter::open(*loop_, cli_.record, cli_.record_bodies);
    if (!w) {
      logError(w.error().message);
      return kExitFailure;
    }
    writer_ = std::move(w.value());
  }

  // 7. the scene built in step 4, handed over before the loop starts
  install(std::move(scene.value()));
  logInfo("scene: '" + scene_name_ + "'");

  // 7a. shared memory: created before the servo thread runs (its publish and command ring are
  // the servo thread's from then on)
  startShm();

  // 7b. the network thread (an ordinary thread): the protocol server; commands go to the servo
  // through the loop's command ring, whose only producer it is
  if (auto net = startNetwork(); !net) {
    logError(net.error().message);
    return kExitFailure;
  }

  if (writer_) {
    if (auto started = writer_->start(); !started) {
      logError(started.error().message);
      return kExitFailure;
    }
  }

  // 8. the servo thread: its own real-time setup, then (on the main thread's word) the loop
  std::promise<ServoSetup> setup_promise;
  auto setup_future = setup_promise.get_future();
  std::atomic<int> go{0};  // 1: run the loop, 2: end without running it
  Thread servo_thread;
  auto started = servo_thread.start("hapticd-servo", 1 << 20, [&] {
    ServoSetup s;
    auto r = setupServoThreadRealtime(rt, backends_.realtime);
    s.ok = r.ok();
    if (r)
      s.report = r.value();
    else
      s.error = r.error().message;
    s.scheduling = describeThreadScheduling();
    loop_->prepareServoThread();  // the scene's per-thread scratch, before the loop starts
    setup_promise.set_value(std::move(s));
    while (go.load(std::memory_order_acquire) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (go.load() == 1) {
      exit_reason_ = static_cast<int>(loop_->run());
      // whatever ended the loop, the device is left at zero force
      device_->write(geom::Vec3(0.0), geom::Vec3(0.0));
    }
    servo_done_ = true;
  });
  if (!started) {
    logError(started.error().message);
    return kExitFailure;
  }
  setup_ = setup_future.get();
  if (!setup_.ok) {
    go = 2;
    servo_thread.join();
    logError(setup_.error);
    if (writer_)
      (void)writer_->finish();
    return kExitFailure;
  }
  for (const auto& w : setup_.report.warnings)
    logWarning(w);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g Hz", config_.servo.rate_hz);
  logInfo("servo thread: " + setup_.scheduling + ", " + rate + ", clock " +
          toString(config_.servo.clock) +
          (process_rt_.memory_locked ? ", memory locked" : ", memory not locked"));
  go = 1;
  notifyReady("running: scene '" + scene_name_ + "', device " + device_->info().name);

  // 9. the main thread's service loop
  const auto watchdog = watchdogInterval();
  auto last_service = SteadyClock::now();
  auto last_watchdog = SteadyClock::now();
  auto last_status_file = SteadyClock::now();
  auto last_status_line = SteadyClock::now();
  std::uint64_t watchdog_tick = 0;
  bool stopping = false;
  writeStatus("running");
  while (!servo_done_.load()) {
    timespec timeout{0, 20'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if ((sig == SIGTERM || sig == SIGINT) && !stopping) {
      stopping = true;
      logInfo(std::string(sig == SIGTERM ? "SIGTERM" : "SIGINT") + ": ramping the force to zero");
      notifyStopping();
      loop_->requestStop();
    } else if (sig == SIGHUP && !stopping) {
      startReload();
    }
    finishReload();
    startUpload();
    drainEvents();
    loop_->reclaimScenes();
    if (secondsSince(last_service) >= config_.device.service_interval_s) {
      device_->service();
      last_service = SteadyClock::now();
    }
    // the watchdog is fed only while the loop is healthy: it ticked since the last feed and is
    // not in a run of overruns as long as the one that latches the miss fault (a latched fault
    // after the loop recovered is a safe state, force zero until re-armed: the daemon stays up)
    if (watchdog.count() > 0 &&
        SteadyClock::now() - last_watchdog >=
            std::chrono::duration_cast<SteadyClock::duration>(watchdog / 4)) {
      const ServoState st = loop_->state();
      if (st.tick > watchdog_tick && st.consecutive_misses < config_.servo.miss_fault_count)
        notifyWatchdog();
      watchdog_tick = st.tick;
      last_watchdog = SteadyClock::now();
    }
    if (secondsSince(last_status_file) >= 0.5) {
      writeStatus(stopping ? "stopping" : "running");
      last_status_file = SteadyClock::now();
    }
    if (config_.log.status_interval_s > 0.0 &&
        secondsSince(last_status_line) >= config_.log.status_interval_s) {
      logStatusLine();
      last_status_line = SteadyClock::now();
    }
  }

  // 10. reverse teardown: network, reload builder, servo thread, writer, scenes, device
  stopNetwork();
  reload_thread_.join();
  reload_result_.reset();
  servo_thread.join();
  drainEvents();
  loop_->reclaimScenes();
  int code = kExitOk;
  if (writer_) {
    if (auto done = writer_->finish(); !done) {
      logError(done.error().message);
      code = kExitFailure;
    }
  }
  const auto exit = static_cast<ServoExit>(exit_reason_.load());
  writeStatus("stopped");
  shm_.reset();  // unlinks the segment (the servo thread that used it has ended)
  std::printf("%s\n", summary(exit).c_str());
  std::fflush(stdout);
  writer_.reset();
  loop_.reset();
  device_.reset();
  return code;
}

}  // namespace

int runDaemon(const CommandLine& cli, const Backends& backends) {
  Daemon daemon(cli, backends);
  return daemon.run();
}

}  // namespace hapticd::daemon
