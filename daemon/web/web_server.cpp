#include "daemon/web/web_server.h"

#include <sodium.h>
#include <sys/socket.h>

#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "protocol/udp.h"

namespace hapticd::web {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::ordered_json;
using Text = std::shared_ptr<const std::string>;

namespace {

constexpr std::size_t kMaxHttpRequestBytes = 64u << 10;
constexpr std::size_t kNonceBytes = 32;

std::string hexOf(const std::uint8_t* data, std::size_t n) {
  std::string out(n * 2 + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), data, n);
  out.pop_back();
  return out;
}

std::string base64Of(const std::vector<std::uint8_t>& bytes) {
  const std::size_t n = sodium_base64_encoded_len(bytes.size(), sodium_base64_VARIANT_ORIGINAL);
  std::string out(n, '\0');
  sodium_bin2base64(out.data(), n, bytes.data(), bytes.size(), sodium_base64_VARIANT_ORIGINAL);
  out.resize(n - 1);  // the terminating NUL
  return out;
}

// false when `text` is not base64 (or decodes to more than `max` bytes)
bool bytesOfBase64(const std::string& text, std::size_t max, std::vector<std::uint8_t>& out) {
  out.resize(std::min(max + 1, text.size() / 4 * 3 + 3));
  std::size_t n = 0;
  if (sodium_base642bin(out.data(), out.size(), text.data(), text.size(), " \n\r", &n, nullptr,
                        sodium_base64_VARIANT_ORIGINAL) != 0)
    return false;
  out.resize(n);
  return n <= max;
}

const char* contentType(const std::string& path) {
  static const std::pair<const char*, const char*> kTypes[] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".glb", "model/gltf-binary"},
      {".wasm", "application/wasm"}};
  for (const auto& [ext, type] : kTypes)
    if (path.size() >= std::strlen(ext) &&
        path.compare(path.size() - std::strlen(ext), std::string::npos, ext) == 0)
      return type;
  return "application/octet-stream";
}

Text textOf(const json& j) {
  return std::make_shared<const std::string>(
      j.dump(-1, ' ', false, json::error_handler_t::replace));
}

Text errorText(const std::string& ref, const std::string& what) {
  return textOf({{"type", "error"}, {"ref", ref}, {"error", what}});
}

}  // namespace

class WsSession;

/// The server's state; everything but finishScene() and the counters runs on the web thread.
class WebServerImpl {
 public:
  WebServerImpl(WebServerConfig config, WebHandlers handlers)
      : config_(std::move(config)), handlers_(std::move(handlers)), acceptor_(ioc_), timer_(ioc_) {}

  Result<bool> open();
  void run(const std::atomic<bool>& stop);
  void finishScene(std::uint64_t ticket, bool accepted, std::string text);

  void accept();
  void onTimer(const std::atomic<bool>& stop);
  void sendStates();
  void add(const std::shared_ptr<WsSession>& s) { sessions_.insert(s); }
  void remove(const std::shared_ptr<WsSession>& s);
  std::uint64_t nowNs() const { return proto::monotonicNs(); }

  WebServerConfig config_;
  WebHandlers handlers_;
  WebCounters counters_;
  asio::io_context ioc_;
  tcp::acceptor acceptor_;
  asio::steady_timer timer_;
  std::string local_;
  std::set<std::shared_ptr<WsSession>> sessions_;
  std::map<std::uint64_t, std::weak_ptr<WsSession>> loads_;  // ticket → its session
  std::uint64_t next_ticket_ = 1;
  std::uint64_t period_ns_ = 1'000'000;
};

/// One WebSocket client.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(WebServerImpl& server, tcp::socket socket)
      : server_(server),
        ws_(std::move(socket)),
        bucket_(server.config_.rate_limit, server.nowNs()) {
    randombytes_buf(nonce_.data(), nonce_.size());
    do {
      id_ = proto::randomU64();
    } while (id_ == 0);
  }

  void start(const http::request<http::string_body>& request) {
    ws_.read_message_max(server_.config_.max_message_bytes);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec)
        return self->close();
      self->server_.add(self);
      ++self->server_.counters_.clients;
      self->greet();
      self->read();
    });
  }

  // a state due now for this subscriber, or none
  bool stateDue(std::uint64_t now) const { return rate_hz_ > 0 && now >= next_state_ns_; }
  const std::string& fields() const { return fields_key_; }
  const std::vector<std::string>& fieldList() const { return fields_; }
  std::uint64_t lastTick() const { return last_tick_; }
  std::uint64_t id() const { return id_; }

  // the state `text` of tick `tick`: at most one waits; a newer one replaces it
  void offerState(const Text& text, std::uint64_t tick, std::uint64_t now) {
    next_state_ns_ += 1'000'000'000ull / rate_hz_;
    if (next_state_ns_ < now)
      next_state_ns_ = now;
    last_tick_ = tick;
    if (state_)
      ++server_.counters_.states_replaced;
    state_ = text;
    flush();
  }

  void send(const Text& text) {
    if (closed_)
      return;
    if (queued_bytes_ + text->size() > server_.config_.max_queued_bytes) {
      ++server_.counters_.closed_slow;
      return close();
    }
    queued_bytes_ += text->size();
    out_.push_back(text);
    flush();
  }

  void loaded(bool ok, const std::string& text) {
    loading_ = false;
    json j = {{"type", "loaded"}, {"ok", ok}};
    if (!ok)
      j["error"] = text;
    send(textOf(j));
  }

  void close() {
    if (closed_)
      return;
    closed_ = true;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).close();
    server_.remove(shared_from_this());
  }

 private:
  void greet();
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec)
        return self->close();  // closed, broken, or a message over read_message_max (1009)
      self->onMessage();
      self->in_.consume(self->in_.size());
      if (!self->closed_)
        self->read();
    });
  }
  void flush() {
    if (writing_ || closed_)
      return;
    Text next;
    bool is_state = false;
    if (!out_.empty()) {
      next = out_.front();
      out_.pop_front();
      queued_bytes_ -= next->size();
    } else if (state_) {
      next = std::move(state_);
      state_.reset();
      is_state = true;
    } else {
      return;
    }
    writing_ = true;
    ws_.text(true);
    ws_.async_write(asio::buffer(*next),
                    [self = shared_from_this(), next, is_state](beast::error_code ec, std::size_t) {
                      self->writing_ = false;
                      if (ec)
                        return self->close();
                      if (is_state)
                        ++self->server_.counters_.states_sent;
                      self->flush();
                    });
  }
  void onMessage();
  void dispatch(const std::string& type, const json& m);
  bool mayCommand(const std::string& type);
  void onHello(const json& m);
  void onSubscribe(const json& m);
  void onPose(const json& m);
  void onArm(const std::string& type);
  // fills the session's fields of `e` and hands it to the servo; false (refused) when its queue
  // is full
  bool forward(const std::string& type, proto::CommandEvent& e);
  void onLoad(const json& m);
  void onScene();
  void onEdit(const std::string& type, const json& m);
  void onStatus();
  void refuse(const std::string& ref, const std::string& what) {
    ++server_.counters_.refused;
    send(errorText(ref, what));
  }

  WebServerImpl& server_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer in_;
  std::deque<Text> out_;
  std::size_t queued_bytes_ = 0;
  Text state_;
  bool writing_ = false;
  bool closed_ = false;
  proto::TokenBucket bucket_;
  bool limited_ = false;  // in a run of rate-limited messages (one error per run)
  std::array<std::uint8_t, kNonceBytes> nonce_{};
  std::uint64_t id_ = 0;
  bool hello_ = false;
  bool authenticated_ = false;
  std::string name_;
  std::uint64_t sequence_ = 0;
  std::uint32_t rate_hz_ = 0;
  std::uint64_t next_state_ns_ = 0;
  std::uint64_t last_tick_ = 0;
  std::vector<std::string> fields_;  // empty: every field
  std::string fields_key_;
  bool loading_ = false;
};

void WsSession::greet() {
  send(textOf({{"type", "hello"},
               {"server", "hapticd"},
               {"api", 1},
               {"nonce", hexOf(nonce_.data(), nonce_.size())},
               {"key_required", server_.config_.key.has_value()},
               {"tick_rate_hz", server_.config_.tick_rate_hz},
               {"max_state_rate_hz",
                std::min(server_.config_.max_state_rate_hz, server_.config_.tick_rate_hz)},
               {"max_message_bytes", server_.config_.max_message_bytes}}));
}

void WsSession::onMessage() {
  ++server_.counters_.messages;
  if (!bucket_.take(server_.nowNs())) {
    ++server_.counters_.rate_limited;
    if (!limited_)
      send(errorText("", "rate limited: messages over the per-connection limit are dropped"));
    limited_ = true;
    return;
  }
  limited_ = false;
  if (!ws_.got_text())
    return refuse("", "binary message: send one JSON object per text message");
  const std::string text = beast::buffers_to_string(in_.data());
  json m;
  try {
    m = json::parse(text);
  } catch (const json::exception& e) {
    return refuse("", std::string("not JSON: ") + e.what());
  }
  if (!m.is_object() || !m.contains("type") || !m["type"].is_string())
    return refuse("", "a message is a JSON object with a string \"type\"");
  const std::string type = m["type"].get<std::string>();
  try {
    dispatch(type, m);
  } catch (const json::exception& e) {  // a field of the wrong JSON type
    refuse(type, std::string("bad field: ") + e.what());
  }
}

void WsSession::dispatch(const std::string& type, const json& m) {
  if (type == "hello")
    return onHello(m);
  if (!hello_)
    return refuse(type, "send hello first");
  if (type == "subscribe")
    return onSubscribe(m);
  if (type == "status")
    return onStatus();
  if (type == "scene")
    return onScene();
  if (type == "pose" || type == "arm" || type == "disarm" || type == "load" || type == "move" ||
      type == "add" || type == "remove") {
    if (!mayCommand(type))
      return;
    if (type == "pose")
      return onPose(m);
    if (type == "arm" || type == "disarm")
      return onArm(type);
    if (type == "load")
      return onLoad(m);
    return onEdit(type, m);
  }
  refuse(type,
         "unknown type (hello, subscribe, pose, arm, disarm, status, load, scene, move, add, "
         "remove)");
}

bool WsSession::mayCommand(const std::string& type) {
  if (!server_.config_.key || authenticated_)
    return true;
  refuse(type, "this session watches only: the server has a key, and " + type +
                   " needs a hello with the key's tag (protocol/websocket.md)");
  return false;
}

void WsSession::onHello(const json& m) {
  if (m.contains("name") && !m["name"].is_string())
    return refuse("hello", "name must be a string");
  name_ = m.value("name", std::string()).substr(0, 64);
  hello_ = true;
  if (server_.config_.key && m.contains("tag")) {
    const std::string tag = m["tag"].is_string() ? m["tag"].get<std::string>() : "";
    std::array<std::uint8_t, crypto_auth_BYTES> bin{};
    std::size_t n = 0;
    if (sodium_hex2bin(bin.data(), bin.size(), tag.data(), tag.size(), nullptr, &n, nullptr) != 0 ||
        n != bin.size() ||
        crypto_auth_verify(bin.data(), nonce_.data(), nonce_.size(), server_.config_.key->data()) !=
            0) {
      authenticated_ = false;
      return refuse("hello",
                    "wrong key: the tag is not HMAC-SHA512-256 of the nonce under the server's "
                    "key; this session watches only");
    }
    authenticated_ = true;
  }
  send(textOf({{"type", "welcome"},
               {"name", name_},
               {"session", std::to_string(id_)},
               {"authenticated", authenticated_},
               {"may_command", !server_.config_.key || authenticated_}}));
}

void WsSession::onSubscribe(const json& m) {
  static const std::set<std::string> kFields = {
      "device",        "proxy",    "force",       "torque",          "force_scale",
      "contact_count", "contacts", "bodies",      "max_penetration", "pairs_tested",
      "pairs_skipped", "tick_ns",  "tick_p50_ns", "tick_p99_ns",     "tick_max_ns",
      "tick_misses",   "faults",   "armed",       "streaming",       "ramping",
      "last_sequence"};
  const auto& rate = m.contains("rate_hz") ? m["rate_hz"] : json(0);
  if (!rate.is_number() || !std::isfinite(rate.get<double>()) || rate.get<double>() < 0.0)
    return refuse("subscribe", "rate_hz must be a number >= 0 (0 stops)");
  std::vector<std::string> fields;
  if (m.contains("fields")) {
    if (!m["fields"].is_array())
      return refuse("subscribe", "fields must be an array of state field names");
    for (const auto& f : m["fields"]) {
      if (!f.is_string() || kFields.count(f.get<std::string>()) == 0)
        return refuse("subscribe", "unknown field " + f.dump() + " (protocol/websocket.md, state)");
      fields.push_back(f.get<std::string>());
    }
  }
  const double limit = std::min(server_.config_.max_state_rate_hz, server_.config_.tick_rate_hz);
  rate_hz_ = static_cast<std::uint32_t>(std::ceil(std::min(rate.get<double>(), limit)));
  std::sort(fields.begin(), fields.end());
  fields_ = fields;
  fields_key_.clear();
  for (const auto& f : fields_)
    fields_key_ += f + ",";
  next_state_ns_ = server_.nowNs();
  send(textOf({{"type", "ack"}, {"ref", "subscribe"}, {"rate_hz", rate_hz_}}));
}

void WsSession::onPose(const json& m) {
  std::string error;
  proto::CommandEvent e;
  e.kind = proto::CommandEvent::Kind::kPose;
  auto X = poseOf(m, &error);
  auto v = X ? vec3Of(m, "v", &error) : std::nullopt;
  auto w = v ? vec3Of(m, "w", &error) : std::nullopt;
  if (!w)
    return refuse("pose", error);
  const auto& buttons = m.contains("buttons") ? m["buttons"] : json(0);
  if (!buttons.is_number_integer() || buttons.get<std::int64_t>() < 0 ||
      buttons.get<std::int64_t>() > 0xffffffffLL)
    return refuse("pose", "buttons must be an integer 0..2^32-1 (a bit mask)");
  e.pose.X_WT = *X;
  e.pose.v_W = *v;
  e.pose.w_W = *w;
  e.pose.buttons = buttons.get<std::uint32_t>();
  forward("pose", e);
}

bool WsSession::forward(const std::string& type, proto::CommandEvent& e) {
  e.authenticated = authenticated_;
  e.session_id = id_;
  e.sequence = ++sequence_;
  e.received_ns = server_.nowNs();
  if (!server_.handlers_.on_command || !server_.handlers_.on_command(e)) {
    ++server_.counters_.commands_queue_full;
    refuse(type, "server_full: the servo's command queue is full: send it again");
    return false;
  }
  ++server_.counters_.commands_forwarded;
  return true;
}

void WsSession::onArm(const std::string& type) {
  proto::CommandEvent e;
  e.kind = type == "arm" ? proto::CommandEvent::Kind::kArm : proto::CommandEvent::Kind::kDisarm;
  if (forward(type, e))
    send(textOf({{"type", "ack"}, {"ref", type}}));
}

void WsSession::onLoad(const json& m) {
  if (!m.contains("glb_base64") || !m["glb_base64"].is_string())
    return refuse("load", "glb_base64 must be a string (the .glb file, base64)");
  if (loading_)
    return refuse("load", "a load of this session is still being built: wait for \"loaded\"");
  if (server_.loads_.size() >= server_.config_.max_concurrent_loads)
    return refuse("load", "server_full: " + std::to_string(server_.loads_.size()) +
                              " loads are being built: send it again after a \"loaded\"");
  proto::SceneUploadDone up;
  if (!bytesOfBase64(m["glb_base64"].get_ref<const std::string&>(),
                     static_cast<std::size_t>(server_.config_.max_scene_bytes), up.bytes))
    return refuse("load", "glb_base64 is not base64, or decodes to more than " +
                              std::to_string(server_.config_.max_scene_bytes) + " bytes");
  if (up.bytes.empty())
    return refuse("load", "glb_base64 is empty");
  up.name = m.value("name", std::string("web.glb")).substr(0, proto::kMaxSceneNameBytes);
  up.session_id = id_;
  up.ticket = WebServer::kTicketBit | server_.next_ticket_++;
  crypto_hash_sha256(up.sha256.data(), up.bytes.data(), up.bytes.size());
  if (!server_.handlers_.on_scene)
    return loaded(false, "this server takes no scenes");
  loading_ = true;
  server_.loads_[up.ticket] = weak_from_this();
  server_.handlers_.on_scene(std::move(up));
}

void WsSession::onScene() {
  if (!server_.handlers_.scene)
    return refuse("scene", "this server has no scene to send");
  auto snap = server_.handlers_.scene();
  if (!snap)
    return refuse("scene", snap.error().message);
  const SceneSnapshot& s = snap.value();
  json bodies = json::array();
  for (const auto& b : s.bodies)
    bodies.push_back(
        {{"index", b.index}, {"name", b.name}, {"motion", b.motion}, {"probe", b.probe}});
  send(textOf({{"type", "scene"},
               {"name", s.name},
               {"probe_body", s.probe_body},
               {"length_scale", s.length_scale},
               {"bodies", std::move(bodies)},
               {"glb_base64", s.glb ? base64Of(*s.glb) : std::string()}}));
}

void WsSession::onEdit(const std::string& type, const json& m) {
  std::string error;
  const auto body = bodyOf(m, &error);
  if (!body)
    return refuse(type, error);
  proto::SceneUpdate u;
  if (type == "remove") {
    u.removed.push_back(*body);
  } else {
    const auto X = poseOf(m, &error);
    if (!X)
      return refuse(type, error);
    (type == "move" ? u.poses : u.added).push_back({*body, *X});
  }
  if (!server_.handlers_.on_scene_update)
    return refuse(type, "this server takes no scene edits");
  if (!server_.handlers_.on_scene_update(id_, u, &error))
    return refuse(type, error);
  send(textOf({{"type", "ack"}, {"ref", type}, {"body", *body}}));
}

void WsSession::onStatus() {
  proto::StatusReply r;
  if (server_.handlers_.fill_status)
    server_.handlers_.fill_status(r);
  json j = statusJson(r, server_.handlers_.fault_names);
  const WebCounters& c = server_.counters_;
  std::uint64_t subscribers = 0;
  for (const auto& s : server_.sessions_)
    subscribers += s->stateDue(UINT64_MAX) ? 1u : 0u;
  j["web"] = {{"listen", server_.local_},
              {"clients", c.clients.load()},
              {"subscribers", subscribers},
              {"messages", c.messages.load()},
              {"refused", c.refused.load()},
              {"rate_limited", c.rate_limited.load()},
              {"states_sent", c.states_sent.load()},
              {"states_replaced", c.states_replaced.load()},
              {"closed_slow", c.closed_slow.load()},
              {"commands_forwarded", c.commands_forwarded.load()},
              {"commands_queue_full", c.commands_queue_full.load()}};
  j["authenticated"] = authenticated_;
  send(textOf(j));
}

/// One HTTP connection: files from the root, or the upgrade to a WebSocket on /ws.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(WebServerImpl& server, tcp::socket socket)
      : server_(server), stream_(std::move(socket)) {}

  void read() {
    parser_.emplace();
    parser_->body_limit(kMaxHttpRequestBytes);
    parser_->header_limit(static_cast<std::uint32_t>(kMaxHttpRequestBytes));
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       if (ec)
                         return self->shut();
                       self->onRequest(self->parser_->release());
                     });
  }

 private:
  void onRequest(const http::request<http::string_body>& req);
  void respond(http::response<http::string_body> res) {
    auto r = std::make_shared<http::response<http::string_body>>(std::move(res));
    r->prepare_payload();
    http::async_write(stream_, *r,
                      [self = shared_from_this(), r](beast::error_code ec, std::size_t) {
                        if (ec || r->need_eof())
                          return self->shut();
                        self->read();
                      });
  }
  http::response<http::string_body> simple(const http::request<http::string_body>& req,
                                           http::status status,
                                           const std::string& text) {
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.keep_alive(req.keep_alive());
    res.body() = text + "\n";
    return res;
  }
  void shut() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
  }

  WebServerImpl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

void HttpSession::onRequest(const http::request<http::string_body>& req) {
  ++server_.counters_.http_requests;
  std::string target(req.target());
  target = target.substr(0, target.find_first_of("?#"));
  if (websocket::is_upgrade(req)) {
    if (target != "/ws")
      return respond(simple(req, http::status::not_found, "the WebSocket is on /ws"));
    if (server_.sessions_.size() >= server_.config_.max_clients)
      return respond(simple(
          req, http::status::service_unavailable,
          "server full: " + std::to_string(server_.config_.max_clients) + " WebSocket clients"));
    stream_.expires_never();
    auto s = std::make_shared<WsSession>(server_, stream_.release_socket());
    return s->start(req);
  }
  if (req.method() != http::verb::get && req.method() != http::verb::head)
    return respond(simple(req, http::status::method_not_allowed, "GET only"));
  if (target.empty() || target[0] != '/' || target.find("..") != std::string::npos ||
      target.find('\\') != std::string::npos || target.find('%') != std::string::npos)
    return respond(simple(req, http::status::bad_request, "bad path"));
  if (target.back() == '/')
    target += "index.html";
  const std::string path = server_.config_.root + target;
  std::error_code fec;
  if (!std::filesystem::is_regular_file(path, fec))
    return respond(simple(req, http::status::not_found, "not found: " + target));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream body;
  body << in.rdbuf();
  http::response<http::string_body> res{http::status::ok, req.version()};
  res.set(http::field::content_type, contentType(path));
  res.set(http::field::cache_control, "no-cache");
  res.keep_alive(req.keep_alive());
  if (req.method() == http::verb::get)
    res.body() = body.str();
  else
    res.content_length(body.str().size());
  respond(std::move(res));
}

Result<bool> WebServerImpl::open() {
  auto address = proto::parseAddress(config_.listen);
  if (!address)
    return Error{address.error().message};
  const auto& ss = address.value().storage;
  tcp::endpoint ep;
  const std::size_t len = ss.ss_family == AF_INET6 ? sizeof(sockaddr_in6) : sizeof(sockaddr_in);
  std::memcpy(ep.data(), &ss, len);
  ep.resize(len);
  std::error_code fec;
  if (!std::filesystem::is_directory(config_.root, fec))
    return Error{"root '" + config_.root + "' is not a folder"};
  beast::error_code ec;
  acceptor_.open(ep.protocol(), ec);
  if (!ec)
    acceptor_.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec)
    acceptor_.bind(ep, ec);
  if (!ec)
    acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    return Error{"cannot listen on " + config_.listen + ": " + ec.message()};
  const tcp::endpoint bound = acceptor_.local_endpoint();
  local_ = (bound.address().is_v6() ? "[" + bound.address().to_string() + "]"
                                    : bound.address().to_string()) +
           ":" + std::to_string(bound.port());
  const std::uint32_t rate =
      std::max<std::uint32_t>(1, std::min(config_.max_state_rate_hz, config_.tick_rate_hz));
  period_ns_ = std::max<std::uint64_t>(250'000, 1'000'000'000ull / rate / 2);
  return true;
}

void WebServerImpl::accept() {
  acceptor_.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec)
      return;  // the acceptor closed
    ++counters_.connections;
    std::make_shared<HttpSession>(*this, std::move(socket))->read();
    accept();
  });
}

void WebServerImpl::remove(const std::shared_ptr<WsSession>& s) {
  if (sessions_.erase(s) != 0)
    --counters_.clients;
}

void WebServerImpl::sendStates() {
  const std::uint64_t now = nowNs();
  bool any = false;
  for (const auto& s : sessions_)
    any = any || s->stateDue(now);
  if (!any || !handlers_.fill_state)
    return;
  proto::State st;
  if (!handlers_.fill_state(st))
    return;
  const json full = stateJson(st, handlers_.fault_names);
  std::map<std::string, Text> texts;  // by fields
  // copy: offerState may close a session, which removes it from sessions_
  const std::vector<std::shared_ptr<WsSession>> due(sessions_.begin(), sessions_.end());
  for (const auto& s : due) {
    if (!s->stateDue(now) || s->lastTick() == st.tick)
      continue;
    Text& text = texts[s->fields()];
    if (!text) {
      if (s->fieldList().empty()) {
        text = textOf(full);
      } else {
        json j = {{"type", "state"}, {"tick", full["tick"]}, {"t", full["t"]}};
        for (const auto& f : s->fieldList())
          j[f] = full[f];
        text = textOf(j);
      }
    }
    s->offerState(text, st.tick, now);
  }
}

void WebServerImpl::onTimer(const std::atomic<bool>& stop) {
  if (stop.load()) {
    beast::error_code ec;
    acceptor_.close(ec);
    const std::vector<std::shared_ptr<WsSession>> all(sessions_.begin(), sessions_.end());
    for (const auto& s : all)
      s->close();
    ioc_.stop();
    return;
  }
  sendStates();
  timer_.expires_after(std::chrono::nanoseconds(period_ns_));
  timer_.async_wait([this, &stop](beast::error_code ec) {
    if (!ec)
      onTimer(stop);
  });
}

void WebServerImpl::run(const std::atomic<bool>& stop) {
  accept();
  onTimer(stop);
  ioc_.run();
}

void WebServerImpl::finishScene(std::uint64_t ticket, bool accepted, std::string text) {
  asio::post(ioc_, [this, ticket, accepted, text = std::move(text)] {
    const auto it = loads_.find(ticket);
    if (it == loads_.end())
      return;
    if (auto s = it->second.lock())
      s->loaded(accepted, text);
    loads_.erase(it);
  });
}

Result<std::unique_ptr<WebServer>> WebServer::create(WebServerConfig config, WebHandlers handlers) {
  if (sodium_init() < 0)
    return Error{"libsodium did not initialise"};
  auto impl = std::make_unique<WebServerImpl>(std::move(config), std::move(handlers));
  if (auto opened = impl->open(); !opened)
    return opened.error();
  return std::unique_ptr<WebServer>(new WebServer(std::move(impl)));
}

WebServer::WebServer(std::unique_ptr<WebServerImpl> impl) : impl_(std::move(impl)) {}
WebServer::~WebServer() = default;

void WebServer::run(const std::atomic<bool>& stop) {
  impl_->run(stop);
}
void WebServer::finishScene(std::uint64_t ticket, bool accepted, std::string text) {
  impl_->finishScene(ticket, accepted, std::move(text));
}
const WebCounters& WebServer::counters() const {
  return impl_->counters_;
}
std::string WebServer::localAddress() const {
  return impl_->local_;
}
const std::string& WebServer::root() const {
  return impl_->config_.root;
}

}  // namespace hapticd::web
