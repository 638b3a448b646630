#include "daemon/device/haply_device.h"

#include <pthread.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <string>

namespace hapticd::device {

namespace beast = boost::beast;
namespace net = boost::asio;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

namespace {

// the longest the I/O thread goes without a command: the service answers only commands, and its
// per-tick commands lapse when they stop coming
constexpr auto kKeepalive = std::chrono::milliseconds(10);
// how often the I/O thread looks for a new force from the servo thread
constexpr auto kPoll = std::chrono::microseconds(100);

std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(s));
}

std::string modelOf(const haply::Inventory& inv) {
  std::string model = inv.type == "inverse3x" ? "Inverse3x"
                      : inv.type == "minverse"
                          ? "Minverse"
                          : (inv.type.empty() || inv.type == "inverse3" ? "Inverse3" : inv.type);
  if (!inv.handedness.empty())
    model += " (" + inv.handedness + "-handed)";
  if (!inv.grip_id.empty())
    model += inv.grip_array == "wireless_verse_grip" ? " + Wireless VerseGrip" : " + VerseGrip";
  return model;
}

}  // namespace

/// A WebSocket client whose every step has a deadline: each call runs the asynchronous
/// operations on its own io_context until they end or the deadline closes the socket. One thread
/// at a time (the opener, then the I/O thread).
class HaplyWsClient {
 public:
  /// TCP connection, handshake and the first message, within `timeout`.
  bool connect(const WsUrl& url,
               std::chrono::steady_clock::duration timeout,
               std::string& first,
               std::string& error) {
    tcp::resolver resolver(ioc_);
    beast::error_code ec;
    const auto endpoints = resolver.resolve(url.host, std::to_string(url.port), ec);
    if (ec) {
      error = "cannot resolve '" + url.host + "': " + ec.message();
      return false;
    }
    auto& lowest = beast::get_lowest_layer(ws_);
    lowest.expires_after(timeout);
    const std::string host = url.host + ":" + std::to_string(url.port);
    const char* step = "connect";
    lowest.async_connect(endpoints, [&](beast::error_code e, const tcp::endpoint&) {
      if ((ec = e))
        return;
      step = "WebSocket handshake";
      ws_.async_handshake(host, url.path, [&](beast::error_code h) {
        if ((ec = h))
          return;
        step = "first message";
        ws_.async_read(buffer_, [&](beast::error_code r, std::size_t) { ec = r; });
      });
    });
    run();
    if (ec) {
      error = std::string(step) + ": " + ec.message();
      return false;
    }
    first = beast::buffers_to_string(buffer_.data());
    return true;
  }

  /// Sends `out`, then reads one message into `in`, within `timeout`.
  bool exchange(const std::string& out,
                std::string& in,
                std::chrono::steady_clock::duration timeout,
                std::string& error) {
    beast::get_lowest_layer(ws_).expires_after(timeout);
    beast::error_code ec;
    ws_.text(true);
    ws_.async_write(net::buffer(out), [&](beast::error_code w, std::size_t) {
      if ((ec = w))
        return;
      buffer_.clear();
      ws_.async_read(buffer_, [&](beast::error_code r, std::size_t) { ec = r; });
    });
    run();
    if (ec) {
      error = ec.message();
      return false;
    }
    in = beast::buffers_to_string(buffer_.data());
    return true;
  }

  /// A closing handshake (bounded), then the socket closed.
  void close() {
    if (!ws_.is_open())
      return;
    beast::get_lowest_layer(ws_).expires_after(std::chrono::milliseconds(200));
    ws_.async_close(websocket::close_code::normal, [](beast::error_code) {});
    run();
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  void run() {
    ioc_.restart();
    ioc_.run();
  }

  net::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_{ioc_};
  beast::flat_buffer buffer_;
};

HaplyDevice::HaplyDevice(const WsUrl& url, const DeviceOptions& options)
    : url_(url), options_(options) {}

HaplyDevice::~HaplyDevice() {
  stop_.store(true);
  if (io_.joinable())
    io_.join();
}

Result<std::unique_ptr<HaplyDevice>> HaplyDevice::open(std::string_view url,
                                                       const DeviceOptions& options) {
  const std::string what = "device 'haply:" + std::string(url) + "': ";
  auto parsed = parseWsUrl(url);
  if (!parsed)
    return Error{what + parsed.error().message};
  for (const auto& [name, value] :
       {std::pair{"haply_silence_lost_s", options.haply_silence_lost_s},
        std::pair{"haply_connect_timeout_s", options.haply_connect_timeout_s}})
    if (!std::isfinite(value) || value <= 0.0 || value > 60.0)
      return Error{what + name + " must be a number > 0 and <= 60, got " + std::to_string(value)};
  std::unique_ptr<HaplyDevice> dev(new HaplyDevice(parsed.value(), options));
  dev->url_text_ = std::string(url);
  dev->link_.markClosed();
  std::string error;
  if (!dev->connect(error))
    return Error{what + error};
  const haply::Inventory& inv = dev->inventory_;
  DeviceInfo& info = dev->info_;
  const bool grip = !inv.grip_id.empty();
  info.model = modelOf(inv);
  info.serial = inv.inverse3_id;
  info.name = "haply:" + dev->url_text_ + " " + info.model;
  info.sensing_dof = grip ? 6 : 3;
  info.force_dof = 3;
  info.capabilities = kCapPosition | kCapForce |
                      (grip ? static_cast<std::uint32_t>(kCapOrientation | kCapButtons) : 0u);
  info.limits = options.limits;
  info.limits.max_torque_nm = 0.0;  // force only
  dev->last_ = inv.state;
  return dev;
}

bool HaplyDevice::connect(std::string& error) {
  auto client = std::make_unique<HaplyWsClient>();
  std::string first;
  if (!client->connect(url_, seconds(options_.haply_connect_timeout_s), first, error)) {
    error = "cannot reach the Haply Inverse Service at " + url_text_ + " (" + error +
            "); install the Haply Inverse Service (with the Haply Hub, "
            "https://docs.haply.co/inverseSDK/), start it and plug in the Inverse3, or give its "
            "address as haply:ws://HOST:PORT";
    return false;
  }
  auto inventory = haply::parseInventory(first);
  if (!inventory) {
    error = "the Haply Inverse Service at " + url_text_ + ": " + inventory.error().message;
    client->close();
    return false;
  }
  inventory_ = std::move(inventory).value();
  state_.write(inventory_.state);
  const std::uint64_t forces_before = force_.writes();
  session_done_.store(false);
  link_.markConnected();
  io_ = std::thread([this, c = std::move(client), forces_before] {
    pthread_setname_np(pthread_self(), "hapticd-haply");
    session(*c, forces_before);
  });
  return true;
}

void HaplyDevice::session(HaplyWsClient& client, std::uint64_t forces_before) {
  const auto silence = seconds(options_.haply_silence_lost_s);
  std::uint64_t sent = forces_before;
  auto last_send = std::chrono::steady_clock::now();
  haply::State state = inventory_.state;
  std::string in, error;
  bool lost = false;
  while (!stop_.load(std::memory_order_relaxed)) {
    const std::uint64_t writes = force_.writes();
    if (writes == sent && std::chrono::steady_clock::now() - last_send < kKeepalive) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    // nothing written since this connection began: zero (never a force from before a loss)
    const Force f = writes == forces_before ? Force{} : force_.read();
    sent = writes;
    last_send = std::chrono::steady_clock::now();
    if (!client.exchange(haply::forceCommand(inventory_.inverse3_id, f.force_n), in, silence,
                         error)) {
      lost = true;
      break;
    }
    exchanges_.fetch_add(1, std::memory_order_relaxed);
    answered_.store(writes, std::memory_order_release);
    const haply::Parsed p = haply::parseState(in, inventory_, state);
    if (p == haply::Parsed::kMissing) {
      lost = true;
      break;
    }
    if (p == haply::Parsed::kBad)
      bad_messages_.fetch_add(1, std::memory_order_relaxed);
    else
      state_.write(state);
  }
  if (lost) {
    link_.markLost();
  } else {  // stopped: a last zero force, then close
    const double zero[3] = {0.0, 0.0, 0.0};
    (void)client.exchange(haply::forceCommand(inventory_.inverse3_id, zero), in, silence, error);
  }
  client.close();
  session_done_.store(true);
}

DeviceStatus HaplyDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  haply::State s;
  if (state_.tryRead(s, 100))
    last_ = s;
  const bool rearm = rearm_pending_.exchange(false, std::memory_order_acq_rel);
  if (rearm) {
    velocity_.reset();
    held_ = true;  // back after a loss: nothing is displayed until the loop is re-armed
  }
  const Pose X{haply::toDevice(last_.position_m),
               haply::orientationToDevice(last_.orientation_xyzw)};
  Vec3 difference(0.0);
  velocity_.update(t_s, X, difference, out.angular_velocity);
  out.X_WD = X;
  out.linear_velocity = haply::toDevice(last_.velocity_m_per_s);
  out.buttons = last_.buttons;
  out.gripper_rad = 0.0;
  if (rearm)
    return DeviceStatus::kFault;
  if (last_.fault != 0) {
    fault_ticks_.fetch_add(1, std::memory_order_relaxed);
    return DeviceStatus::kFault;
  }
  return DeviceStatus::kOk;
}

DeviceStatus HaplyDevice::write(const Vec3& force_n, const Vec3& torque_nm) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  if (torque_nm != Vec3(0.0))
    torque_dropped_.fetch_add(1, std::memory_order_relaxed);
  Force f;
  haply::forceToHaply(held_ ? Vec3(0.0) : force_n, f.force_n);
  force_.write(f);
  return DeviceStatus::kOk;
}

void HaplyDevice::setOutputHeld(bool held) noexcept {
  held_ = held;
  if (held && link_.connected())
    force_.write(Force{});
}

bool HaplyDevice::service() {
  if (link_.connected())
    return true;
  if (!session_done_.load())
    return false;  // the I/O thread is still ending
  if (io_.joinable())
    io_.join();
  std::string error;
  rearm_pending_.store(true, std::memory_order_release);
  if (connect(error))
    return true;
  rearm_pending_.store(false, std::memory_order_release);
  return false;
}

Result<std::unique_ptr<Device>> makeHaplyDevice(std::string_view url,
                                                const DeviceOptions& options) {
  auto d = HaplyDevice::open(url, options);
  if (!d)
    return d.error();
  return std::unique_ptr<Device>(std::move(d).value());
}

}  // namespace hapticd::device
