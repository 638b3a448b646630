#include "client/link.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <ostream>
#include <thread>

#include "protocol/server.h"  // monotonicNs
#include "protocol/shm.h"

namespace hapticd::client {
namespace {

using proto::monotonicNs;

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
  bool gone() const override { return c_->unreachable(); }
  void close() override { c_->bye(); }

 private:
  std::unique_ptr<proto::Client> c_;
};

class ShmLink final : public Link {
 public:
  ShmLink(proto::ShmClient c, std::uint64_t timeout_ns)
      : c_(std::move(c)), timeout_ns_(timeout_ns) {}
  bool arm(std::string* why) override {
    c_.beat(monotonicNs());
    if (!pushWaiting([&] { return c_.pushArm(monotonicNs()); })) {
      *why = "the command ring stayed full (is the daemon consuming it?)";
      return false;
    }
    return true;
  }
  bool sendPose(const proto::PoseCommand& cmd, std::string* why) override {
    c_.beat(monotonicNs());
    if (!pushWaiting([&] { return c_.pushPose(cmd, monotonicNs()); })) {
      *why = "the command ring stayed full (is the daemon consuming it?)";
      return false;
    }
    return true;
  }
  bool subscribe(std::uint32_t, std::uint32_t, std::string*) override { return true; }
  std::optional<proto::State> receiveState(int timeout_ms) override {
    const std::uint64_t end =
        monotonicNs() + static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * 1'000'000;
    proto::ShmState s{};
    for (;;) {
      c_.beat(monotonicNs());
      if (c_.readState(s) && (!seen_ || s.tick != last_tick_)) {
        seen_ = true;
        last_tick_ = s.tick;
        noteRate(s);
        proto::State out;
        proto::toState(s, out);
        return out;
      }
      if (monotonicNs() >= end)
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
  void pump() override { c_.beat(monotonicNs()); }
  void close() override {}
  bool gone() const override { return !c_.serverAlive(monotonicNs(), timeout_ns_); }

 private:
  template <class F>
  bool pushWaiting(F push) {
    // the daemon drains the ring every tick: a full ring empties within a few ticks
    const std::uint64_t end = monotonicNs() + 500'000'000;
    while (!push()) {
      if (monotonicNs() >= end)
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
  std::uint64_t timeout_ns_;
  bool seen_ = false;
  std::uint64_t last_tick_ = 0;
  bool have_ref_ = false;
  std::uint64_t ref_tick_ = 0;
  std::uint64_t ref_ns_ = 0;
  std::uint32_t rate_hz_ = 0;
};

// Shared memory when t.shm_name is set, else UDP. nullptr after saying why on `err`.
std::unique_ptr<Link> openTransport(const DaemonTarget& t, const char* command, std::ostream& err) {
  if (t.shm_name.empty()) {
    auto c = connectUdp(t, err);
    if (!c)
      return nullptr;
    return std::make_unique<UdpLink>(std::move(c));
  }
  auto c = proto::ShmClient::attach(t.shm_name);
  if (!c) {
    err << "hapticctl " << command << ": --shm " << t.shm_name << ": " << c.error().message << "\n";
    return nullptr;
  }
  // the daemon beats every tick; wait a little for a first beat, as UDP waits for Welcome
  const std::uint64_t timeout_ns =
      static_cast<std::uint64_t>(std::max(t.timeout_ms, 1)) * 1'000'000;
  auto link = std::make_unique<ShmLink>(std::move(c).value(), timeout_ns);
  const std::uint64_t end = monotonicNs() + timeout_ns;
  while (link->gone()) {
    if (monotonicNs() >= end) {
      err << "hapticctl " << command << ": --shm " << t.shm_name << ": the daemon's heartbeat is "
          << "older than " << t.timeout_ms << " ms (is hapticd running?)\n";
      return nullptr;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return link;
}

}  // namespace

std::string address(const DaemonTarget& t) {
  const bool v6 = t.host.find(':') != std::string::npos;
  return (v6 ? "[" + t.host + "]" : t.host) + ":" + std::to_string(t.port);
}

std::unique_ptr<proto::Client> connectUdp(const DaemonTarget& t, std::ostream& err) {
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
    err << "hapticctl: " << client.error().message << "\n";
    return nullptr;
  }
  return std::move(client.value());
}

std::unique_ptr<Link> openLink(const DaemonTarget& t,
                               const char* command,
                               bool arm,
                               std::ostream& err) {
  std::unique_ptr<Link> link = openTransport(t, command, err);
  std::string why;
  if (link && arm && !link->arm(&why)) {
    err << "hapticctl " << command << ": arm: " << why << "\n";
    return nullptr;
  }
  return link;
}

}  // namespace hapticd::client
