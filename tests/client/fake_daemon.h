#pragma once
// Fakes of hapticd for hapticctl's daemon commands: a proto::Server on a loopback port with
// scripted handlers (FakeDaemon), and a proto::ShmServer driven by a thread (FakeShmDaemon).
// Every value a fake sends is a function of the tick (stateFor), so a test can check a record
// row by row; every command and scene update a fake receives is kept, in order.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "client/daemon_commands.h"
#include "protocol/server.h"
#include "protocol/shm.h"

namespace hapticd::client::testing {

/// The state a fake publishes at `tick` (1-based, as the daemon's State::tick).
inline proto::State stateFor(std::uint64_t tick) {
  const double k = static_cast<double>(tick);
  proto::State s;
  s.tick = tick;
  s.sim_time_ns = tick * 2'000'000;
  s.X_WD.p = {k * 1e-3, 2.0, -3.0};
  const double a = 0.01 * k;  // a rotation about y
  s.X_WD.q = {0.0, std::sin(a), 0.0, std::cos(a)};
  s.X_WP.p = {k * 1e-3, 2.5, -3.5};
  s.X_WP.q = {std::sin(a), 0.0, 0.0, std::cos(a)};
  s.force_n = {k, -k, 0.5};
  s.torque_nm = {0.25, k * 1e-2, -k * 1e-3};
  s.force_scale = 1.0;
  s.tick_p50_ns = 11000;
  s.tick_p99_ns = 22000;
  s.tick_max_ns = 33000;
  s.state_flags = proto::kStateArmed;
  s.contact_count = static_cast<std::uint32_t>(tick % 5 + 3);
  for (std::uint32_t i = 0; i < 3; ++i)  // listed in an order that is not by depth
    s.contacts.push_back({{0.1 * i, 0.0, k}, {0.0, 1.0, 0.0}, 1e-4 * ((i + 1) % 3 + 1)});
  s.max_penetration_m = k * 1e-6;
  s.pairs_tested = static_cast<std::uint32_t>(2 * tick);
  s.pairs_skipped = static_cast<std::uint32_t>(tick % 3);
  s.tick_ns = static_cast<std::uint32_t>(1000 + tick);
  for (std::uint32_t b : {1u, 4u}) {  // two moving bodies, scene indices 1 and 4
    const double h = 0.005 * k * b;   // a rotation about z
    s.bodies.push_back({b, {{0.25 * b, k * 1e-4, -1.0}, {0.0, 0.0, std::sin(h), std::cos(h)}}});
  }
  return s;
}

/// A proto::Server on 127.0.0.1 (a free port) on its own thread, with recording handlers.
class FakeDaemon {
 public:
  /// tick_rate_hz: told in Welcome, and the fake's tick rate on the monotonic clock. skip_every:
  /// ticks that are multiples of it are never shown (0: none skipped). key: the daemon's key.
  explicit FakeDaemon(std::uint32_t tick_rate_hz = 1000,
                      std::uint64_t skip_every = 0,
                      std::optional<proto::Key> key = std::nullopt)
      : skip_every_(skip_every) {
    proto::ServerConfig cfg;
    cfg.bind_address = "127.0.0.1:0";
    cfg.tick_rate_hz = tick_rate_hz;
    cfg.key = key;
    proto::ServerHandlers h;
    h.on_command = [this](const proto::CommandEvent& e) {
      std::lock_guard<std::mutex> l(m_);
      commands_.push_back(e);
      return true;
    };
    h.on_scene_update = [this](std::uint64_t, const proto::SceneUpdate& u, std::string* error) {
      std::lock_guard<std::mutex> l(m_);
      updates_.push_back(u);
      if (!refusal_.empty()) {
        *error = refusal_;
        return false;
      }
      return true;
    };
    // a servo ticking at tick_rate_hz since construction: the newest tick now (a skipped tick
    // is never newest: its predecessor is shown until the next one)
    start_ns_ = proto::monotonicNs();
    h.fill_status = [](proto::StatusReply& r) {
      r.device = "fake";
      r.scene = "fake.glb";
    };
    h.fill_state = [this, tick_rate_hz](proto::State& s) {
      std::uint64_t tick = 1 + (proto::monotonicNs() - start_ns_) * tick_rate_hz / 1'000'000'000;
      if (skip_every_ != 0 && tick % skip_every_ == 0)
        --tick;
      s = stateFor(tick);
      return true;
    };
    auto s = proto::Server::create(cfg, h);
    if (s)
      server_ = std::move(s).value();
    else
      error_ = s.error().message;
    target_.host = "127.0.0.1";
    target_.port = server_ ? server_->localAddress().port() : 1;
    target_.timeout_ms = 3000;
    if (server_)
      thread_ = std::thread([this] { server_->run(stop_); });
  }
  ~FakeDaemon() { stop(); }
  /// The daemon goes away: its thread ends and its socket closes (the port then answers "port
  /// unreachable"). target() stays as it was.
  void stop() {
    stop_ = true;
    if (thread_.joinable())
      thread_.join();
    server_.reset();
  }
  const std::string& error() const { return error_; }
  DaemonTarget target() const { return target_; }
  /// Waits up to 3 s for a client's session; false when none came.
  bool waitForSession() const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (server_ && server_->sessionCount() == 0) {
      if (std::chrono::steady_clock::now() > end)
        return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
  void refuseUpdatesWith(std::string text) {
    std::lock_guard<std::mutex> l(m_);
    refusal_ = std::move(text);
  }
  std::vector<proto::CommandEvent> commands() const {
    std::lock_guard<std::mutex> l(m_);
    return commands_;
  }
  /// Pose commands, waiting up to 3 s for `n` of them (datagrams still in flight).
  std::vector<proto::CommandEvent> poses(std::size_t n) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    for (;;) {
      std::vector<proto::CommandEvent> out;
      for (const auto& e : commands())
        if (e.kind == proto::CommandEvent::Kind::kPose)
          out.push_back(e);
      if (out.size() >= n || std::chrono::steady_clock::now() > end)
        return out;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  std::vector<proto::SceneUpdate> updates() const {
    std::lock_guard<std::mutex> l(m_);
    return updates_;
  }

 private:
  std::uint64_t skip_every_;
  std::uint64_t start_ns_ = 0;
  std::unique_ptr<proto::Server> server_;
  DaemonTarget target_;
  std::string error_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex m_;
  std::vector<proto::CommandEvent> commands_;
  std::vector<proto::SceneUpdate> updates_;
  std::string refusal_;
};

/// A ShmServer whose thread ticks every `period`: beats, drains the ring (kept in order) and
/// publishes a state whose device pose is the newest commanded pose (else stateFor's).
class FakeShmDaemon {
 public:
  explicit FakeShmDaemon(const char* what,
                         std::chrono::microseconds period = std::chrono::microseconds(1000))
      : name_("/hapticctl-test-" + std::to_string(::getpid()) + "-" + what) {
    auto s = proto::ShmServer::create(name_);
    if (!s) {
      error_ = s.error().message;
      return;
    }
    server_ = std::make_unique<proto::ShmServer>(std::move(s).value());
    thread_ = std::thread([this, period] {
      std::uint64_t tick = 0;
      bool have_pose = false;
      proto::PoseCommand last;
      while (!stop_) {
        server_->beat(proto::monotonicNs());
        proto::ShmCommandEvent e;
        while (server_->popCommand(e)) {
          std::lock_guard<std::mutex> l(m_);
          events_.push_back(e);
          if (e.kind == proto::ShmCommandEvent::Kind::kPose) {
            last = e.pose;
            have_pose = true;
          }
        }
        ++tick;
        const proto::State st = stateFor(tick);
        proto::ShmState x{};
        x.tick = st.tick;
        x.sim_time_ns = st.sim_time_ns;
        x.publish_ns = proto::monotonicNs();
        const proto::WirePose& d = have_pose ? last.X_WT : st.X_WD;
        for (std::size_t i = 0; i < 3; ++i) {
          x.X_WD[i] = d.p[i];
          x.X_WP[i] = st.X_WP.p[i];
          x.force_n[i] = st.force_n[i];
          x.torque_nm[i] = st.torque_nm[i];
        }
        for (std::size_t i = 0; i < 4; ++i) {
          x.X_WD[3 + i] = d.q[i];
          x.X_WP[3 + i] = st.X_WP.q[i];
        }
        x.force_scale = st.force_scale;
        x.contact_count = st.contact_count;
        x.state_flags = st.state_flags;
        x.pairs_tested = st.pairs_tested;
        x.pairs_skipped = st.pairs_skipped;
        x.max_penetration_m = st.max_penetration_m;
        x.tick_ns = st.tick_ns;
        x.body_count = st.bodies.size();
        for (std::size_t b = 0; b < st.bodies.size(); ++b) {
          x.bodies[b].index = st.bodies[b].body_index;
          for (std::size_t i = 0; i < 3; ++i)
            x.bodies[b].X_WB[i] = st.bodies[b].X_WB.p[i];
          for (std::size_t i = 0; i < 4; ++i)
            x.bodies[b].X_WB[3 + i] = st.bodies[b].X_WB.q[i];
        }
        server_->publish(x);
        std::this_thread::sleep_for(period);
      }
    });
  }
  ~FakeShmDaemon() {
    stop_ = true;
    if (thread_.joinable())
      thread_.join();
  }
  const std::string& error() const { return error_; }
  const std::string& name() const { return name_; }
  DaemonTarget target() const {
    DaemonTarget t;
    t.shm_name = name_;
    t.port = 1;  // nothing there: a command that used UDP would fail
    t.timeout_ms = 3000;
    return t;
  }
  std::vector<proto::ShmCommandEvent> events() const {
    std::lock_guard<std::mutex> l(m_);
    return events_;
  }

 private:
  std::string name_;
  std::string error_;
  std::unique_ptr<proto::ShmServer> server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex m_;
  std::vector<proto::ShmCommandEvent> events_;
};

}  // namespace hapticd::client::testing
