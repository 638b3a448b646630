#include "tests/daemon/device/fake_haply.h"

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

namespace hapticd::testing {

namespace beast = boost::beast;
namespace net = boost::asio;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using nlohmann::json;

namespace {

json vec3(const std::array<double, 3>& v) {
  return {{"x", v[0]}, {"y", v[1]}, {"z", v[2]}};
}

}  // namespace

struct FakeHaply::Impl {
  Options options;
  net::io_context ioc;
  tcp::acceptor acceptor{ioc};
  std::thread thread;

  mutable std::mutex mutex;  // the script and the records
  std::array<double, 3> position{0.0, -0.12, 0.15};
  std::array<double, 3> velocity{};
  std::array<double, 4> orientation{0.0, 0.0, 0.0, 1.0};
  bool buttons[3] = {false, false, false};
  bool error = false;
  bool silent = false;
  bool dropped = false;
  bool down = false;
  std::vector<std::array<double, 3>> forces;
  std::uint64_t other = 0;
  std::uint64_t connections = 0;

  struct Session;
  std::weak_ptr<Session> current;  // the server thread's

  // the device list (with config) or a state message; under the mutex
  std::string message(bool with_config) const {
    json inverse3 = {{"device_id", options.id},
                     {"state",
                      {{"cursor_position", vec3(position)},
                       {"cursor_velocity", vec3(velocity)},
                       {"mode", "idle"}}},
                     {"status", {{"calibrated", true}, {"ready", !error}, {"started", true}}}};
    if (error)
      inverse3["status"]["error"] = "fake: a safety error";
    if (with_config)
      inverse3["config"] = {{"type", options.type}, {"handedness", options.handedness}};
    json out = {{"session_id", 1}, {"inverse3", dropped ? json::array() : json::array({inverse3})}};
    if (options.grip) {
      const json q = {{"x", orientation[0]},
                      {"y", orientation[1]},
                      {"z", orientation[2]},
                      {"w", orientation[3]}};
      json grip = {{"device_id", "61548"}, {"status", json::object()}};
      if (options.wireless)
        grip["state"] = {{"orientation", q},
                         {"buttons", {{"a", buttons[0]}, {"b", buttons[1]}, {"c", buttons[2]}}}};
      else
        grip["state"] = {{"orientation", q}, {"button", buttons[0]}, {"hall", 0}};
      out[options.wireless ? "wireless_verse_grip" : "verse_grip"] = json::array({grip});
    }
    return out.dump();
  }

  // a received message: a force recorded; true when it should be answered
  bool receive(const std::string& text) {
    std::lock_guard lock(mutex);
    const json m = json::parse(text, nullptr, false);
    const json* f = nullptr;
    if (m.is_object() && m.contains("inverse3") && m["inverse3"].is_array() &&
        !m["inverse3"].empty()) {
      const json& d = m["inverse3"][0];
      if (d.value("device_id", "") == options.id && d.contains("commands") &&
          d["commands"].contains("set_cursor_force"))
        f = &d["commands"]["set_cursor_force"]["vector"];
    }
    if (f != nullptr && f->is_object())
      forces.push_back({f->value("x", 0.0), f->value("y", 0.0), f->value("z", 0.0)});
    else
      ++other;
    return !silent;
  }

  struct Session : std::enable_shared_from_this<Session> {
    Impl& impl;
    websocket::stream<beast::tcp_stream> ws;
    beast::flat_buffer buffer;
    std::string out;
    Session(Impl& i, tcp::socket socket) : impl(i), ws(std::move(socket)) {}

    void start() {
      ws.async_accept([self = shared_from_this()](beast::error_code ec) {
        if (ec)
          return;
        {
          std::lock_guard lock(self->impl.mutex);
          ++self->impl.connections;
          self->out = self->impl.message(true);
        }
        self->send();
      });
    }
    void send() {
      ws.text(true);
      ws.async_write(net::buffer(out),
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       if (!ec)
                         self->read();
                     });
    }
    void read() {
      buffer.clear();
      ws.async_read(buffer, [self = shared_from_this()](beast::error_code ec, std::size_t) {
        if (ec)
          return;
        if (!self->impl.receive(beast::buffers_to_string(self->buffer.data()))) {
          self->read();  // silent: received, not answered
          return;
        }
        {
          std::lock_guard lock(self->impl.mutex);
          self->out = self->impl.message(false);
        }
        self->send();
      });
    }
    void close() {
      beast::error_code ec;
      beast::get_lowest_layer(ws).socket().shutdown(tcp::socket::shutdown_both, ec);
      beast::get_lowest_layer(ws).socket().close(ec);
    }
  };

  void accept() {
    acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec)
        return;
      bool refuse = false;
      {
        std::lock_guard lock(mutex);
        refuse = down;
      }
      if (refuse) {
        socket.close(ec);
      } else {
        auto s = std::make_shared<Session>(*this, std::move(socket));
        current = s;
        s->start();
      }
      accept();
    });
  }
};

FakeHaply::FakeHaply() : FakeHaply(Options{}) {}

FakeHaply::FakeHaply(const Options& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  const tcp::endpoint at(net::ip::make_address("127.0.0.1"), 0);
  impl_->acceptor.open(at.protocol());
  impl_->acceptor.set_option(tcp::acceptor::reuse_address(true));
  impl_->acceptor.bind(at);
  impl_->acceptor.listen();
  impl_->accept();
  impl_->thread = std::thread([this] { impl_->ioc.run(); });
}

FakeHaply::~FakeHaply() {
  net::post(impl_->ioc, [this] {
    beast::error_code ec;
    impl_->acceptor.close(ec);
    if (auto s = impl_->current.lock())
      s->close();
    impl_->ioc.stop();
  });
  impl_->thread.join();
}

std::uint16_t FakeHaply::port() const {
  return impl_->acceptor.local_endpoint().port();
}

std::string FakeHaply::url() const {
  return "ws://127.0.0.1:" + std::to_string(port());
}

void FakeHaply::move(const std::array<double, 3>& position_m,
                     const std::array<double, 3>& velocity) {
  std::lock_guard lock(impl_->mutex);
  impl_->position = position_m;
  impl_->velocity = velocity;
}

void FakeHaply::turn(const std::array<double, 4>& xyzw) {
  std::lock_guard lock(impl_->mutex);
  impl_->orientation = xyzw;
}

void FakeHaply::press(bool a, bool b, bool c) {
  std::lock_guard lock(impl_->mutex);
  impl_->buttons[0] = a;
  impl_->buttons[1] = b;
  impl_->buttons[2] = c;
}

void FakeHaply::reportError(bool on) {
  std::lock_guard lock(impl_->mutex);
  impl_->error = on;
}

void FakeHaply::silent(bool on) {
  std::lock_guard lock(impl_->mutex);
  impl_->silent = on;
}

void FakeHaply::dropInverse3(bool on) {
  std::lock_guard lock(impl_->mutex);
  impl_->dropped = on;
}

void FakeHaply::disconnect() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->down = true;
  }
  net::post(impl_->ioc, [this] {
    if (auto s = impl_->current.lock())
      s->close();
  });
}

void FakeHaply::comeBack() {
  std::lock_guard lock(impl_->mutex);
  impl_->down = false;
}

std::vector<std::array<double, 3>> FakeHaply::forces() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->forces;
}

std::uint64_t FakeHaply::forceCount() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->forces.size();
}

std::uint64_t FakeHaply::otherMessages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->other;
}

std::uint64_t FakeHaply::connections() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections;
}

}  // namespace hapticd::testing
