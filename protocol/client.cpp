#include "protocol/client.h"

#include <algorithm>
#include <map>

#include "protocol/server.h"  // monotonicNs
#include "protocol/upload.h"

namespace hapticd::proto {
namespace {
constexpr std::uint64_t kMs = 1'000'000;

std::string refusalText(const ErrorMsg& e) {
  return std::string(errcName(e.code)) + ": " + e.text;
}
}  // namespace

Client::Client(ClientConfig config, UdpSocket socket, SocketAddress server)
    : config_(std::move(config)), socket_(std::move(socket)), server_(server) {
  rx_.resize(kMaxDatagramLimit);
  tx_.resize(kMaxDatagramLimit);
}

Client::~Client() = default;

namespace {

// What a hello sent without a tag from a fresh socket gets: nullopt when nothing answers, else
// the Welcome (its tag is not checked: this only tells whether a daemon runs there and has a
// key). The probe's session is closed again with Bye.
std::optional<Welcome> probeUntagged(const SocketAddress& server, int timeout_ms, int resend_ms) {
  auto sock = UdpSocket::connectedTo(server);
  if (!sock)
    return std::nullopt;
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  Header h;
  h.sequence = 1;
  h.timestamp_ns = monotonicNs();
  const std::size_t n = encode(h, Hello{kCapUdp, "hapticctl-probe"}, buf);
  const std::vector<std::uint8_t> hello(buf.begin(), buf.begin() + static_cast<long>(n));
  const std::uint64_t end = monotonicNs() + static_cast<std::uint64_t>(timeout_ms) * kMs;
  while (n != 0 && monotonicNs() < end) {
    sock.value().sendTo(server, hello);
    if (!sock.value().waitReadable(resend_ms))
      continue;
    SocketAddress from;
    const Received r = sock.value().receive(buf, from);
    if (r.refused)
      return std::nullopt;
    Header rh;
    Message m;
    if (!r.got || decode(std::span(buf.data(), r.size), rh, m).code != Errc::kOk ||
        !std::holds_alternative<Welcome>(m))
      continue;
    Header bye;
    bye.session_id = std::get<Welcome>(m).session_id;
    bye.sequence = 2;
    if (const std::size_t k = encode(bye, Bye{}, buf))
      sock.value().sendTo(server, std::span(buf.data(), k));
    return std::get<Welcome>(m);
  }
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<Client>> Client::connect(ClientConfig config) {
  auto addr = parseAddress(config.server, kDefaultPort, true);
  if (!addr)
    return addr.error();
  auto sock = UdpSocket::connectedTo(addr.value(), 4 << 20);
  if (!sock)
    return sock.error();
  std::unique_ptr<Client> c(new Client(std::move(config), std::move(sock).value(), addr.value()));

  // the same hello datagram is resent, so a server that got it twice answers with one session
  Hello hello;
  hello.client_name = c->config_.name.substr(0, kMaxNameBytes);
  Header h;
  h.session_id = 0;
  h.sequence = ++c->sequence_;
  h.timestamp_ns = monotonicNs();
  Errc e = Errc::kOk;
  const Key* key = c->config_.key ? &*c->config_.key : nullptr;
  const std::size_t n = encodeDatagram(h, hello, key, c->tx_, &e);
  if (n == 0)
    return Error{std::string("hello: cannot encode: ") + errcName(e)};
  const std::vector<std::uint8_t> datagram(c->tx_.begin(), c->tx_.begin() + static_cast<long>(n));

  const Want want = [&](const Header& rh, const Message& m) {
    if (std::holds_alternative<Welcome>(m))
      return rh.session_id == std::get<Welcome>(m).session_id;
    if (const auto* err = std::get_if<ErrorMsg>(&m))
      return err->ref_sequence == h.sequence || err->code == Errc::kBadMajor;
    return false;
  };
  auto m = c->exchange([&] { c->sendBytes(datagram); }, want);
  if (!m)
    return c->silence();
  if (const auto* err = std::get_if<ErrorMsg>(&*m))
    return Error{"server " + c->server_.toString() + " refused hello: " + refusalText(*err)};
  c->welcome_ = std::get<Welcome>(*m);
  c->session_id_ = c->welcome_.session_id;
  // a server with a key and a client without: a watch-only session (status, subscribe);
  // scene and command messages will be refused with kNoMac
  return c;
}

Error Client::silence() const {
  const std::string at = server_.toString();
  if (unreachable_)
    return Error{"no daemon at " + at + ": the port is unreachable, no answer from " + at +
                 " (nothing listens there: is hapticd running, and is this its --udp address?)"};
  const std::string waited = "no daemon at " + at + ": no answer from " + at + " within " +
                             std::to_string(config_.timeout_ms) + " ms";
  if (!config_.key)
    return Error{waited + " (is hapticd running?)"};
  // a keyed daemon drops a hello whose tag does not verify without a word (no oracle); one
  // that answers a hello without a tag runs and has a key, and so refused ours: a wrong key
  const auto probe = probeUntagged(server_, std::min(config_.timeout_ms, 1000), config_.resend_ms);
  if (probe && (probe->flags & kWelcomeKeyRequired) != 0)
    return Error{"wrong key: hapticd at " + at +
                 " answers, but drops every datagram tagged with this key (the key file does "
                 "not hold the daemon's key)"};
  return Error{waited +
               " (is hapticd running? A daemon with another key drops datagrams tagged with this "
               "one without a word: the key may also be wrong)"};
}

std::optional<Message> Client::exchange(const std::function<void()>& send_once, const Want& want) {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(config_.timeout_ms) * kMs;
  while (monotonicNs() < deadline && !unreachable_) {
    send_once();
    if (auto m = processIncoming(config_.resend_ms, &want))
      return m;
  }
  return std::nullopt;
}

bool Client::sendBytes(std::span<const std::uint8_t> d) {
  ++counters_.sent;
  last_send_ns_ = monotonicNs();
  bool refused = false;
  const bool sent = socket_.sendTo(server_, d, &refused);
  unreachable_ = unreachable_ || refused;
  return sent;
}

std::uint64_t Client::send(const Message& m) {
  Header h;
  h.session_id = session_id_;
  h.sequence = ++sequence_;
  h.timestamp_ns = monotonicNs();
  const std::size_t n = encodeDatagram(h, m, config_.key ? &*config_.key : nullptr, tx_);
  if (n == 0)
    return 0;
  sendBytes(std::span<const std::uint8_t>(tx_.data(), n));
  return h.sequence;
}

std::optional<Message> Client::processIncoming(int timeout_ms, const Want* want) {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * kMs;
  const std::uint64_t beat_ns = static_cast<std::uint64_t>(std::max(config_.heartbeat_ms, 0)) * kMs;
  for (;;) {
    SocketAddress from;
    Received r = socket_.receive(rx_, from);
    if (r.refused)
      unreachable_ = true;
    if (unreachable_)
      return std::nullopt;  // nobody there to wait for
    if (!r.got) {
      std::uint64_t t = monotonicNs();
      if (beat_ns > 0 && session_id_ != 0 && t - last_send_ns_ >= beat_ns) {
        send(Heartbeat{0});
        t = monotonicNs();
      }
      if (t >= deadline)
        return std::nullopt;
      std::uint64_t left = deadline - t;
      if (beat_ns > 0 && session_id_ != 0)
        left = std::min(left, last_send_ns_ + beat_ns - t);
      if (!socket_.waitReadableNs(left) && monotonicNs() >= deadline)
        return std::nullopt;
      continue;
    }
    ++counters_.received;
    if (!(from == server_) || r.truncated) {
      ++counters_.bad;
      continue;
    }
    const auto d = std::span<const std::uint8_t>(rx_.data(), r.size);
    Header h;
    Message m;
    DecodeError e = decode(d, h, m);
    if (e.code == Errc::kOk && config_.key && (h.flags & kFlagMac) && !verifyTag(d, *config_.key))
      e.code = Errc::kBadMac;
    // a keyed client takes only tagged datagrams, except an Error while connecting: a server
    // without a key answers a tagged hello with an untagged "no key set", worth showing
    if (e.code == Errc::kOk && config_.key && !(h.flags & kFlagMac) &&
        !(session_id_ == 0 && std::holds_alternative<ErrorMsg>(m)))
      e.code = Errc::kNoMac;
    if (e.code != Errc::kOk) {
      ++counters_.bad;
      continue;
    }
    if (session_id_ != 0 && h.session_id != session_id_) {
      ++counters_.bad;
      continue;
    }
    if (auto* err = std::get_if<ErrorMsg>(&m)) {
      ++counters_.errors;
      counters_.last_error = *err;
    }
    if (want && (*want)(h, m))
      return m;
    if (auto* st = std::get_if<State>(&m)) {
      if (states_.size() >= config_.state_queue) {
        states_.pop_front();
        ++counters_.states_dropped;
      }
      states_.push_back(std::move(*st));
    }
  }
}

Result<Message> Client::call(const Message& m, const char* what, const Answers& answers) {
  std::vector<std::uint64_t> sent;
  const Want want = [&](const Header&, const Message& r) {
    if (const auto* e = std::get_if<ErrorMsg>(&r))
      return std::find(sent.begin(), sent.end(), e->ref_sequence) != sent.end();
    return answers(r, sent);
  };
  auto r = exchange([&] { sent.push_back(send(m)); }, want);
  if (!r && unreachable_)
    return Error{std::string(what) + ": no answer from " + server_.toString() +
                 ": the port is unreachable (did hapticd stop?)"};
  if (!r)
    return Error{std::string(what) + ": no answer from " + server_.toString() + " within " +
                 std::to_string(config_.timeout_ms) + " ms"};
  if (const auto* e = std::get_if<ErrorMsg>(&*r))
    return Error{std::string(what) + " refused: " + refusalText(*e)};
  return std::move(*r);
}

Result<Done> Client::request(const Message& m) {
  const auto type = static_cast<std::uint16_t>(typeOf(m));
  auto r = call(m, msgTypeName(type), [&](const Message& answer, const auto& sent) {
    const auto* a = std::get_if<Ack>(&answer);
    return a != nullptr && a->ref_type == type &&
           std::find(sent.begin(), sent.end(), a->ref_sequence) != sent.end();
  });
  if (!r)
    return r.error();
  return Done{};
}

Result<std::uint64_t> Client::sendPose(const PoseCommand& cmd) {
  const std::uint64_t seq = send(cmd);
  if (seq == 0)
    return Error{"pose: cannot encode (NaN/Inf or bad value)"};
  return seq;
}

Result<Done> Client::subscribe(std::uint32_t rate_hz, std::uint32_t flags) {
  if (rate_hz > kMaxStateRateHz)
    return Error{"subscribe: rate " + std::to_string(rate_hz) + " Hz over the maximum " +
                 std::to_string(kMaxStateRateHz) + " Hz"};
  return request(Subscribe{rate_hz, flags});
}

std::optional<State> Client::receiveState(int timeout_ms) {
  if (states_.empty()) {
    const Want want = [](const Header&, const Message& m) {
      return std::holds_alternative<State>(m);
    };
    auto m = processIncoming(timeout_ms, &want);
    if (m)
      return std::get<State>(std::move(*m));
    if (states_.empty())
      return std::nullopt;
  }
  State s = std::move(states_.front());
  states_.pop_front();
  return s;
}

Result<Done> Client::arm() {
  return request(Arm{});
}
Result<Done> Client::disarm() {
  return request(Disarm{});
}
Result<Done> Client::sceneUpdate(const SceneUpdate& update) {
  return request(update);
}

Result<StatusReply> Client::status() {
  auto r = call(StatusRequest{}, "status", [](const Message& answer, const auto&) {
    return std::holds_alternative<StatusReply>(answer);
  });
  if (!r)
    return r.error();
  return std::get<StatusReply>(std::move(r).value());
}

Result<std::uint64_t> Client::ping() {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(config_.timeout_ms) * kMs;
  while (monotonicNs() < deadline) {
    const std::uint64_t t0 = monotonicNs();
    const std::uint64_t seq = send(Heartbeat{0});
    (void)seq;
    const Want want = [&](const Header&, const Message& r) {
      const auto* hb = std::get_if<Heartbeat>(&r);
      return hb && hb->echo_timestamp_ns >= t0;
    };
    if (processIncoming(config_.resend_ms, &want))
      return monotonicNs() - t0;
  }
  return Error{"ping: no answer from " + server_.toString()};
}

void Client::bye() {
  send(Bye{});
}

// One scene upload in flight: which chunks are acknowledged, when each was last sent, and the
// server's verdict once it comes. take() is the upload's answer filter.
struct Client::Upload {
  std::span<const std::uint8_t> bytes;
  std::uint32_t chunk = 1;
  std::uint32_t id = 0;
  const std::function<void(std::uint64_t, std::uint64_t)>* progress = nullptr;
  std::size_t chunks = 0;
  std::vector<char> acked;
  std::vector<std::uint64_t> sent_ns;
  std::size_t acked_count = 0;
  std::uint64_t acked_bytes = 0;
  std::optional<SceneStatus> verdict;

  std::uint64_t bytesOf(std::size_t i) const {
    return std::min<std::uint64_t>(chunk, bytes.size() - i * std::uint64_t{chunk});
  }
  // true for a verdict (SceneStatus of this upload, or an Error about its messages); chunk
  // acknowledgements are noted on the way
  bool take(const Message& m) {
    if (const auto* a = std::get_if<SceneChunkAck>(&m)) {
      const std::size_t i = static_cast<std::size_t>(a->offset / chunk);
      if (a->upload_id == id && a->offset % chunk == 0 && i < chunks && !acked[i]) {
        acked[i] = 1;
        ++acked_count;
        acked_bytes += bytesOf(i);
        if (progress && *progress)
          (*progress)(acked_bytes, bytes.size());
      }
      return false;
    }
    if (const auto* s = std::get_if<SceneStatus>(&m); s && s->upload_id == id) {
      verdict = *s;
      return true;
    }
    if (const auto* e = std::get_if<ErrorMsg>(&m)) {
      const auto t = static_cast<MsgType>(e->ref_type);
      if (t == MsgType::kSceneBegin || t == MsgType::kSceneChunk || t == MsgType::kSceneCommit) {
        SceneStatus refused;
        refused.upload_id = id;
        refused.status = SceneStatusCode::kRefused;
        refused.text = refusalText(*e);
        verdict = refused;
        return true;
      }
    }
    return false;
  }
  // chunks in the ranges the server misses are sent again
  void forget(const std::vector<SceneStatus::Range>& missing) {
    for (const auto& g : missing) {
      const std::size_t first = static_cast<std::size_t>(g.offset / chunk);
      const std::size_t last = static_cast<std::size_t>((g.offset + g.length - 1) / chunk);
      for (std::size_t i = first; i <= last && i < chunks; ++i) {
        if (acked[i]) {
          acked[i] = 0;
          --acked_count;
          acked_bytes -= bytesOf(i);
        }
        sent_ns[i] = 0;
      }
    }
  }
};

namespace {
// accepted, refused or lost: the end of an upload; incomplete or validating: not yet
std::optional<Result<Done>> finalOf(const SceneStatus& s) {
  switch (s.status) {
    case SceneStatusCode::kAccepted:
      return Result<Done>(Done{});
    case SceneStatusCode::kRefused:
      return Result<Done>(Error{"scene refused: " + s.text});
    case SceneStatusCode::kUnknownUpload:
      return Result<Done>(Error{"load: the server lost the upload (" + s.text + ")"});
    default:
      return std::nullopt;
  }
}
}  // namespace

Result<Done> Client::load(std::span<const std::uint8_t> bytes,
                          const std::string& name,
                          const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  if (bytes.empty())
    return Error{"load: the scene file is empty"};
  if (welcome_.max_scene_bytes && bytes.size() > welcome_.max_scene_bytes)
    return Error{"load: scene of " + std::to_string(bytes.size()) + " bytes is over the server's " +
                 std::to_string(welcome_.max_scene_bytes) + " byte limit"};
  Upload up;
  up.bytes = bytes;
  up.chunk = config_.chunk_bytes;
  if (welcome_.max_chunk_bytes)
    up.chunk = std::min(up.chunk, welcome_.max_chunk_bytes);
  up.chunk = std::max<std::uint32_t>(up.chunk, 1);
  up.id = next_upload_id_++;
  up.progress = &progress;
  up.chunks = (bytes.size() + up.chunk - 1) / up.chunk;
  up.acked.assign(up.chunks, 0);
  up.sent_ns.assign(up.chunks, 0);
  const std::uint64_t t_end =
      monotonicNs() + static_cast<std::uint64_t>(config_.load_timeout_ms) * kMs;

  SceneBegin begin;
  begin.upload_id = up.id;
  begin.chunk_bytes = up.chunk;
  begin.total_bytes = bytes.size();
  begin.sha256 = sha256(bytes);
  begin.name = name.substr(0, kMaxSceneNameBytes);
  // 1. begin, until the server answers for this upload
  if (auto f = untilVerdict(up, t_end, [&] { send(begin); }))
    return std::move(*f);
  // 2. chunks in a window; 3. commit; missing ranges send us back to 2
  for (;;) {
    if (auto f = sendChunks(up, t_end))
      return std::move(*f);
    if (auto f = commit(up, t_end))
      return std::move(*f);
  }
}

Client::Phase Client::untilVerdict(Upload& up,
                                   std::uint64_t t_end,
                                   const std::function<void()>& send_once) {
  const Want want = [&](const Header&, const Message& m) { return up.take(m); };
  for (;;) {
    if (monotonicNs() > t_end)
      return uploadTimedOut();
    up.verdict.reset();
    send_once();
    processIncoming(config_.resend_ms, &want);
    if (up.verdict)
      return finalOf(*up.verdict);  // nullopt for incomplete or validating
  }
}

Client::Phase Client::sendChunks(Upload& up, std::uint64_t t_end) {
  const Want want = [&](const Header&, const Message& m) { return up.take(m); };
  const auto resend_ns = static_cast<std::uint64_t>(config_.chunk_resend_ms) * kMs;
  while (up.acked_count < up.chunks) {
    if (monotonicNs() > t_end)
      return uploadTimedOut();
    const std::uint64_t t = monotonicNs();
    std::size_t in_flight = 0;
    for (std::size_t i = 0; i < up.chunks && in_flight < config_.window; ++i) {
      if (up.acked[i])
        continue;
      ++in_flight;
      if (up.sent_ns[i] != 0 && t - up.sent_ns[i] < resend_ns)
        continue;
      if (up.sent_ns[i] != 0)
        ++counters_.chunks_resent;
      SceneChunk c;
      c.upload_id = up.id;
      c.offset = static_cast<std::uint64_t>(i) * up.chunk;
      c.data = up.bytes.subspan(static_cast<std::size_t>(c.offset), up.bytesOf(i));
      send(c);
      ++counters_.chunks_sent;
      up.sent_ns[i] = t;
    }
    up.verdict.reset();
    processIncoming(1, &want);
    if (up.verdict) {
      if (auto f = finalOf(*up.verdict))
        return f;
    }
  }
  return std::nullopt;
}

Client::Phase Client::commit(Upload& up, std::uint64_t t_end) {
  // commit until a verdict; Incomplete names what to send again (back to the chunks);
  // Validating: keep committing (each answer is idempotent) until the verdict
  for (;;) {
    if (auto f = untilVerdict(up, t_end, [&] { send(SceneCommit{up.id}); }))
      return f;
    if (up.verdict->status == SceneStatusCode::kIncomplete && !up.verdict->missing.empty()) {
      up.forget(up.verdict->missing);
      return std::nullopt;
    }
    // an Incomplete without ranges is the answer to a late begin
  }
}

Client::Phase Client::uploadTimedOut() const {
  return Result<Done>(Error{"load: upload not finished within " +
                            std::to_string(config_.load_timeout_ms) + " ms (" + server_.toString() +
                            ")"});
}

}  // namespace hapticd::proto
