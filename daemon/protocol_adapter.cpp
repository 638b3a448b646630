#include "daemon/protocol_adapter.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <utility>

#include "daemon/log.h"

namespace hapticd::daemon {
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

// The pid of a live hapticd other than this process serving segment `existing` (a hapticd
// segment), or 0 (a stale one, or this process's own). Stale: its server process is gone, or its
// heartbeat (each tick) stopped more than 5 s ago, so that a dead daemon's pid reused by another
// process does not keep the segment forever (a heartbeat of 0: the server has not ticked yet, it
// counts as live).
std::uint64_t liveShmOwner(const proto::ShmExisting& existing) {
  const std::uint64_t pid = existing.server_pid;
  const std::uint64_t beat = existing.server_heartbeat_ns;
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

std::uint32_t clampU32(std::int64_t ns) {
  return static_cast<std::uint32_t>(std::clamp<std::int64_t>(ns, 0, 0xffffffffLL));
}

// what State and StatusReply both carry: misses, compute percentiles, faults, flags
template <class Message>
void putTickFigures(const ServoState& st, const DurationHistogram& compute, Message& m) {
  m.tick_misses = st.overruns;
  m.tick_p50_ns = clampU32(compute.quantileNs(0.5));
  m.tick_p99_ns = clampU32(compute.quantileNs(0.99));
  m.tick_max_ns = clampU32(compute.maxNs());
  m.fault_bits = st.faults;
  m.state_flags = wireStateFlags(st);
}

// The address `text` of the config key `key` parses; one other hosts can reach needs the key file.
Result<bool> checkListenAddress(const char* key, const std::string& text, bool has_key_file) {
  auto address = proto::parseAddress(text);
  if (!address)
    return Error{std::string(key) + ": " + address.error().message};
  if (!address.value().isLoopback() && !has_key_file)
    return Error{std::string(key) + ": " + address.value().toString() +
                 " is not a loopback address and [network] key_file is not set: set key_file "
                 "(64 hex digits) to serve other hosts"};
  return true;
}

}  // namespace

Result<proto::ServerConfig> serverConfigOf(const Config& c) {
  proto::ServerConfig cfg;
  if (c.network.udp.empty())
    return cfg;  // UDP off: nothing to check
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
  if (auto listen = checkListenAddress("[network] udp", c.network.udp, cfg.key.has_value());
      !listen)
    return listen.error();
  return cfg;
}

Result<web::WebServerConfig> webConfigOf(const Config& c) {
  auto udp = serverConfigOf(c);  // the key file, read and parsed
  if (!udp)
    return udp.error();
  web::WebServerConfig w;
  w.listen = c.web.listen;
  w.key = udp.value().key;
  w.max_message_bytes = static_cast<std::size_t>(c.web.max_message_bytes);
  w.rate_limit = udp.value().rate_limit;
  w.max_state_rate_hz = udp.value().max_state_rate_hz;
  w.tick_rate_hz = udp.value().tick_rate_hz;
  w.max_scene_bytes = proto::UploadLimits{}.max_scene_bytes;
  if (auto listen = checkListenAddress("[web] listen", c.web.listen, w.key.has_value()); !listen)
    return listen.error();
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!c.web.root.empty()) {
    w.root = c.web.root;
  } else {
    const fs::path installed =
        fs::read_symlink("/proc/self/exe", ec).parent_path().parent_path() / "share/hapticd/web";
    w.root = !ec && fs::is_directory(installed, ec) ? installed.string()
                                                    : std::string(HAPTICD_WEB_SOURCE_ROOT);
  }
  if (!fs::is_directory(w.root, ec))
    return Error{"[web] root: '" + w.root + "' is not a folder"};
  return w;
}

ProtocolAdapter::ProtocolAdapter(ServoLoop& loop) : loop_(loop) {}

ProtocolAdapter::~ProtocolAdapter() {
  stopNetwork();
}

void ProtocolAdapter::closeShm() {
  shm_.reset();  // unlinks the segment (the servo thread that used it has ended)
}

void ProtocolAdapter::setDevice(const std::string& name) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  info_device_ = name;
}

void ProtocolAdapter::setScene(const std::string& name,
                               const std::string& plan,
                               std::shared_ptr<const scene::SceneModel> model,
                               std::uint64_t generation) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  info_scene_ = name;
  info_plan_ = plan;
  edit_model_ = std::move(model);
  edit_generation_ = generation;
}

std::optional<proto::SceneUploadDone> ProtocolAdapter::takeUpload() {
  std::lock_guard<std::mutex> lock(upload_mutex_);
  if (uploads_.empty())
    return std::nullopt;
  proto::SceneUploadDone up = std::move(uploads_.front());
  uploads_.pop_front();
  return up;
}

void ProtocolAdapter::finishUpload(std::uint64_t ticket, bool accepted, const std::string& text) {
  if ((ticket & web::WebServer::kTicketBit) != 0) {
    if (web_)
      web_->finishScene(ticket, accepted, text);
  } else if (server_) {
    server_->finishScene(ticket, accepted, text);
  }
}

void ProtocolAdapter::setLoading(std::string text) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  info_loading_ = std::move(text);
}

void ProtocolAdapter::setSceneBytes(SceneBytes bytes) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  scene_bytes_ = std::move(bytes);
}

Result<web::SceneSnapshot> ProtocolAdapter::sceneSnapshot() {
  std::shared_ptr<const scene::SceneModel> model;
  std::uint64_t generation = 0;
  SceneBytes bytes;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    model = edit_model_;
    generation = edit_generation_;
    bytes = scene_bytes_;
  }
  if (!model)
    return Error{"no scene is running"};
  if (!glb_ || glb_generation_ != generation) {
    if (!bytes)
      return Error{"the running scene's bytes are not available"};
    auto read = bytes();
    if (!read)
      return read.error();
    glb_ = std::make_shared<const std::vector<std::uint8_t>>(std::move(read.value()));
    glb_generation_ = generation;
  }
  web::SceneSnapshot s;
  s.name = model->name;
  s.glb = glb_;
  s.probe_body = model->probe_body;
  s.length_scale = model->length_scale;
  for (std::size_t i = 0; i < model->bodies.size(); ++i) {
    const scene::Body& b = model->bodies[i];
    s.bodies.push_back({static_cast<std::uint32_t>(i), b.name, motionName(b.motion),
                        static_cast<std::int32_t>(i) == model->probe_body || b.probe});
  }
  return s;
}

void ProtocolAdapter::addStatus(nlohmann::json& j, const ServoState& st) const {
  nlohmann::json shm = {{"name", shm_name_}, {"serving", shm_ != nullptr}};
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
  if (web_) {
    const auto& c = web_->counters();
    j["web"] = {
        {"listen", web_->localAddress()},      {"root", web_->root()},
        {"clients", c.clients.load()},         {"messages", c.messages.load()},
        {"states_sent", c.states_sent.load()}, {"states_replaced", c.states_replaced.load()},
        {"closed_slow", c.closed_slow.load()}, {"commands_forwarded", c.commands_forwarded.load()}};
  }
  if (!server_)
    j["network"] = {{"udp", ""}, {"why_not", "off ([network] udp = \"\")"}};
  if (server_) {
    const auto& c = server_->counters();
    j["network"] = {{"udp", server_->localAddress().toString()},
                    {"sessions", c.sessions.load()},
                    {"received", c.received.load()},
                    {"states_sent", c.states_sent.load()},
                    {"commands_forwarded", c.commands_forwarded.load()},
                    {"commands_queue_full", c.commands_queue_full.load()}};
  }
}

bool ProtocolAdapter::fillState(proto::State& out) const {
  const ServoState st = loop_.state();
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
  putTickFigures(st, loop_.compute(), out);
  out.contact_count = st.contacts;
  out.pairs_tested = st.pairs_tested;
  out.pairs_skipped = st.pairs_skipped;
  out.max_penetration_m =
      std::isfinite(st.max_penetration_m) ? std::max(0.0, st.max_penetration_m) : 0.0;
  out.tick_ns = clampU32(st.last_tick_ns);
  // the lists of the newest tick (published by the servo thread right after the state block: at
  // most a tick apart from the fields above)
  const ServoLists l = loop_.lists();
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

bool ProtocolAdapter::onSceneUpdate(const proto::SceneUpdate& u, std::string* error) {
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

  std::lock_guard<std::mutex> producer(producer_mutex_);
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
  if (!loop_.sendEdits(b)) {
    *error = "the servo's edit queue is full (" + std::to_string(loop_.editCapacity()) +
             " updates waiting): send it again";
    return false;
  }
  return true;
}

void ProtocolAdapter::fillStatus(proto::StatusReply& r) const {
  const ServoState st = loop_.state();
  r.uptime_ns = static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::steady_clock::now() - started_at_)
                                               .count());
  r.ticks = st.tick;
  r.tick_rate_hz = servo_rate_hz_;
  const double loop_s = st.t_s + 1.0 / servo_rate_hz_;
  r.measured_tick_hz = st.tick > 0 && loop_s > 0.0 ? static_cast<double>(st.tick) / loop_s : 0.0;
  putTickFigures(st, loop_.compute(), r);
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
  r.loading = info_loading_.substr(0, proto::kMaxTextBytes);  // protocol minor 2
}

void ProtocolAdapter::startShm(const std::string& name) {
  shm_name_ = name;
  if (name.empty()) {
    shm_error_ = "off ([network] shm = \"\")";
    logInfo("shared memory: off ([network] shm = \"\")");
    return;
  }
  // a file at the name that hapticd did not make is never removed (ShmServer::create refuses
  // it, naming it and what was found); a stale hapticd segment is replaced, a live one left alone
  const proto::ShmExisting existing = proto::inspectShm(name);
  if (existing.kind == proto::ShmExisting::Kind::kHapticd) {
    if (const std::uint64_t pid = liveShmOwner(existing); pid != 0) {
      shm_error_ =
          "segment " + name + " is served by another hapticd (pid " + std::to_string(pid) + ")";
      logWarning("[network] shm \"" + name + "\": " + shm_error_ +
                 "; running without shared memory");
      return;
    }
    logInfo("shared memory: replacing the stale segment " + existing.path + " (server pid " +
            std::to_string(existing.server_pid) + ", gone or silent)");
  }
  auto created = proto::ShmServer::create(name);
  if (!created) {
    shm_error_ = created.error().message;
    logWarning("[network] shm \"" + name + "\": " + shm_error_ + "; running without shared memory");
    return;
  }
  shm_ = std::make_unique<proto::ShmServer>(std::move(created.value()));
  loop_.attachShm(shm_.get());
  logInfo("shared memory: segment " + name + " (clients on this host: proto::ShmClient)");
}

Result<bool> ProtocolAdapter::startNetwork(const Config& config) {
  if (config.network.udp.empty()) {
    logInfo(std::string("network: UDP off ([network] udp = \"\"") +
            (config.servo.clock == ClockKind::kVirtual ? ", the virtual clock's default: --udp "
                                                         "serves it)"
                                                       : ")"));
    return true;
  }
  auto settings = serverConfigOf(config);
  if (!settings)
    return settings.error();
  proto::ServerConfig cfg = std::move(settings.value());
  servo_rate_hz_ = config.servo.rate_hz;
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
  if (!created) {
    // the server names its own setting (protocol.bind); the user's key is [network] udp
    std::string text = created.error().message;
    constexpr std::string_view kBind = "protocol.bind: ";
    if (text.rfind(kBind, 0) == 0)
      text.erase(0, kBind.size());
    return Error{"[network] udp " + config.network.udp + ": " + text};
  }
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

Result<bool> ProtocolAdapter::startWeb(const Config& config) {
  if (config.web.listen.empty()) {
    logInfo("web: off ([web] listen = \"\")");
    return true;
  }
  auto settings = webConfigOf(config);
  if (!settings)
    return settings.error();
  const bool keyed = settings.value().key.has_value();
  web::WebHandlers h;
  h.on_command = [this](const proto::CommandEvent& e) { return onCommand(e); };
  h.on_scene = [this](proto::SceneUploadDone&& up) {
    std::lock_guard<std::mutex> lock(upload_mutex_);
    uploads_.push_back(std::move(up));
  };
  if (!edit_)
    edit_ = std::make_unique<EditBatch>();
  h.on_scene_update = [this](std::uint64_t, const proto::SceneUpdate& u, std::string* error) {
    return onSceneUpdate(u, error);
  };
  h.fill_state = [this](proto::State& st) { return fillState(st); };
  h.fill_status = [this](proto::StatusReply& r) { fillStatus(r); };
  h.scene = [this] { return sceneSnapshot(); };
  h.fault_names = [](std::uint32_t bits) { return faultNames(bits); };
  auto created = web::WebServer::create(std::move(settings.value()), std::move(h));
  if (!created) {
    // like shared memory: the viewer is an extra, a daemon whose port is taken runs without it
    logWarning("[web] listen " + config.web.listen + ": " + created.error().message +
               "; running without the web endpoint");
    return true;
  }
  web_ = std::move(created.value());
  logInfo("web: viewer on http://" + web_->localAddress() + "/ (files from " + web_->root() +
          "), WebSocket API on ws://" + web_->localAddress() + "/ws" +
          (keyed ? ", pre-shared key" : ", no key"));
  auto started = web_thread_.start("hapticd-web", 1 << 20, [this] { web_->run(net_stop_); });
  if (!started) {
    web_.reset();
    return started.error();
  }
  return true;
}

void ProtocolAdapter::stopNetwork() {
  net_stop_ = true;
  net_thread_.join();
  web_thread_.join();
}

bool ProtocolAdapter::onCommand(const proto::CommandEvent& e) {
  const CommandKind kind = e.kind == proto::CommandEvent::Kind::kArm      ? CommandKind::kArm
                           : e.kind == proto::CommandEvent::Kind::kDisarm ? CommandKind::kDisarm
                                                                          : CommandKind::kPose;
  std::lock_guard<std::mutex> producer(producer_mutex_);
  return loop_.sendCommand(gatedCommand(kind, e.session_id, e.sequence, e.pose));
}

}  // namespace hapticd::daemon
