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

Result<std::unique_ptr<Client>> Client::connect(ClientConfig config) {
  auto addr = parseAddress(config.server, kDefaultPort, true);
  if (!addr)
    return addr.error();
  auto sock = UdpSocket::forPeer(addr.value(), 4 << 20);
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
  const std::size_t n =
      encodeDatagram(h, hello, c->config_.key ? &*c->config_.key : nullptr, c->tx_, &e);
  if (n == 0)
    return Error{std::string("hello: cannot encode: ") + errcName(e)};
  const std::vector<std::uint8_t> datagram(c->tx_.begin(), c->tx_.begin() + static_cast<long>(n));

  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(c->config_.timeout_ms) * kMs;
  std::function<bool(const Header&, const Message&)> want = [&](const Header& rh,
                                                                const Message& m) {
    if (std::holds_alternative<Welcome>(m))
      return rh.session_id == std::get<Welcome>(m).session_id;
    if (const auto* err = std::get_if<ErrorMsg>(&m))
      return err->ref_sequence == h.sequence || err->code == Errc::kBadMajor;
    return false;
  };
  while (monotonicNs() < deadline) {
    c->sendBytes(datagram);
    auto m = c->processIncoming(c->config_.resend_ms, &want);
    if (!m)
      continue;
    if (const auto* err = std::get_if<ErrorMsg>(&*m))
      return Error{"server " + c->server_.toString() + " refused hello: " + refusalText(*err)};
    c->welcome_ = std::get<Welcome>(*m);
    c->session_id_ = c->welcome_.session_id;
    // a server with a key and a client without: a watch-only session (status, subscribe);
    // scene and command messages will be refused with kNoMac
    return c;
  }
  return Error{"no answer from " + c->server_.toString() + " within " +
               std::to_string(c->config_.timeout_ms) + " ms (is hapticd running?)"};
}

bool Client::sendBytes(std::span<const std::uint8_t> d) {
  ++counters_.sent;
  last_send_ns_ = monotonicNs();
  return socket_.sendTo(server_, d);
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

std::optional<Message> Client::processIncoming(
    int timeout_ms,
    const std::function<bool(const Header&, const Message&)>* want) {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * kMs;
  const std::uint64_t beat_ns = static_cast<std::uint64_t>(std::max(config_.heartbeat_ms, 0)) * kMs;
  for (;;) {
    SocketAddress from;
    Received r = socket_.receive(rx_, from);
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

Result<Done> Client::request(const Message& m) {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(config_.timeout_ms) * kMs;
  const auto type = static_cast<std::uint16_t>(typeOf(m));
  std::vector<std::uint64_t> sent;
  std::function<bool(const Header&, const Message&)> want = [&](const Header&, const Message& r) {
    if (const auto* a = std::get_if<Ack>(&r))
      return a->ref_type == type &&
             std::find(sent.begin(), sent.end(), a->ref_sequence) != sent.end();
    if (const auto* e = std::get_if<ErrorMsg>(&r))
      return std::find(sent.begin(), sent.end(), e->ref_sequence) != sent.end();
    return false;
  };
  while (monotonicNs() < deadline) {
    sent.push_back(send(m));
    auto r = processIncoming(config_.resend_ms, &want);
    if (!r)
      continue;
    if (const auto* e = std::get_if<ErrorMsg>(&*r))
      return Error{std::string(msgTypeName(type)) + " refused: " + refusalText(*e)};
    return Done{};
  }
  return Error{std::string(msgTypeName(type)) + ": no answer from " + server_.toString() +
               " within " + std::to_string(config_.timeout_ms) + " ms"};
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
    std::function<bool(const Header&, const Message&)> want = [](const Header&, const Message& m) {
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
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(config_.timeout_ms) * kMs;
  std::vector<std::uint64_t> sent;
  std::function<bool(const Header&, const Message&)> want = [&](const Header&, const Message& r) {
    if (std::holds_alternative<StatusReply>(r))
      return true;
    if (const auto* e = std::get_if<ErrorMsg>(&r))
      return std::find(sent.begin(), sent.end(), e->ref_sequence) != sent.end();
    return false;
  };
  while (monotonicNs() < deadline) {
    sent.push_back(send(StatusRequest{}));
    auto r = processIncoming(config_.resend_ms, &want);
    if (!r)
      continue;
    if (const auto* e = std::get_if<ErrorMsg>(&*r))
      return Error{"status refused: " + refusalText(*e)};
    return std::get<StatusReply>(std::move(*r));
  }
  return Error{"status: no answer from " + server_.toString()};
}

Result<std::uint64_t> Client::ping() {
  const std::uint64_t deadline =
      monotonicNs() + static_cast<std::uint64_t>(config_.timeout_ms) * kMs;
  while (monotonicNs() < deadline) {
    const std::uint64_t t0 = monotonicNs();
    const std::uint64_t seq = send(Heartbeat{0});
    (void)seq;
    std::function<bool(const Header&, const Message&)> want = [&](const Header&, const Message& r) {
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

Result<Done> Client::load(std::span<const std::uint8_t> bytes,
                          const std::string& name,
                          const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  if (bytes.empty())
    return Error{"load: the scene file is empty"};
  if (welcome_.max_scene_bytes && bytes.size() > welcome_.max_scene_bytes)
    return Error{"load: scene of " + std::to_string(bytes.size()) + " bytes is over the server's " +
                 std::to_string(welcome_.max_scene_bytes) + " byte limit"};
  std::uint32_t chunk = config_.chunk_bytes;
  if (welcome_.max_chunk_bytes)
    chunk = std::min(chunk, welcome_.max_chunk_bytes);
  chunk = std::max<std::uint32_t>(chunk, 1);
  const std::uint64_t t_end =
      monotonicNs() + static_cast<std::uint64_t>(config_.load_timeout_ms) * kMs;
  const std::uint32_t id = next_upload_id_++;
  auto timedOut = [&] {
    return Error{"load: upload not finished within " + std::to_string(config_.load_timeout_ms) +
                 " ms (" + server_.toString() + ")"};
  };

  SceneBegin begin;
  begin.upload_id = id;
  begin.chunk_bytes = chunk;
  begin.total_bytes = bytes.size();
  begin.sha256 = sha256(bytes);
  begin.name = name.substr(0, kMaxSceneNameBytes);

  std::optional<SceneStatus> verdict;
  // one handler for everything about this upload
  std::vector<char> acked;
  const std::size_t nchunks = (bytes.size() + chunk - 1) / chunk;
  acked.assign(nchunks, 0);
  std::vector<std::uint64_t> sent_ns(nchunks, 0);
  std::size_t acked_count = 0;
  std::uint64_t acked_bytes = 0;
  std::function<bool(const Header&, const Message&)> want = [&](const Header&, const Message& m) {
    if (const auto* a = std::get_if<SceneChunkAck>(&m)) {
      if (a->upload_id != id || a->offset % chunk != 0)
        return false;
      const std::size_t i = static_cast<std::size_t>(a->offset / chunk);
      if (i < nchunks && !acked[i]) {
        acked[i] = 1;
        ++acked_count;
        acked_bytes += std::min<std::uint64_t>(chunk, bytes.size() - a->offset);
        if (progress)
          progress(acked_bytes, bytes.size());
      }
      return false;
    }
    if (const auto* s = std::get_if<SceneStatus>(&m)) {
      if (s->upload_id == id) {
        verdict = *s;
        return true;
      }
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
  };
  auto finalOrError = [&](const SceneStatus& s) -> std::optional<Result<Done>> {
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
  };

  // 1. begin, until the server answers for this upload
  for (;;) {
    if (monotonicNs() > t_end)
      return timedOut();
    verdict.reset();
    send(begin);
    processIncoming(config_.resend_ms, &want);
    if (!verdict)
      continue;
    if (auto f = finalOrError(*verdict))
      return std::move(*f);
    break;
  }

  // 2. chunks in a window; 3. commit; missing ranges send us back to 2
  for (;;) {
    std::size_t next = 0;
    while (acked_count < nchunks) {
      if (monotonicNs() > t_end)
        return timedOut();
      const std::uint64_t t = monotonicNs();
      std::size_t in_flight = 0;
      for (std::size_t i = 0; i < nchunks && in_flight < config_.window; ++i) {
        if (acked[i])
          continue;
        if (sent_ns[i] != 0 &&
            t - sent_ns[i] < static_cast<std::uint64_t>(config_.chunk_resend_ms) * kMs) {
          ++in_flight;
          continue;
        }
        if (sent_ns[i] != 0)
          ++counters_.chunks_resent;
        SceneChunk c;
        c.upload_id = id;
        c.offset = static_cast<std::uint64_t>(i) * chunk;
        c.data = bytes.subspan(
            static_cast<std::size_t>(c.offset),
            std::min<std::size_t>(chunk, bytes.size() - static_cast<std::size_t>(c.offset)));
        send(c);
        ++counters_.chunks_sent;
        sent_ns[i] = t;
        ++in_flight;
      }
      (void)next;
      verdict.reset();
      processIncoming(1, &want);
      if (verdict) {
        if (auto f = finalOrError(*verdict))
          return std::move(*f);
      }
    }
    // commit until a verdict; Incomplete names what to send again
    bool resend = false;
    while (!resend) {
      if (monotonicNs() > t_end)
        return timedOut();
      verdict.reset();
      send(SceneCommit{id});
      processIncoming(config_.resend_ms, &want);
      if (!verdict)
        continue;
      if (auto f = finalOrError(*verdict))
        return std::move(*f);
      if (verdict->status == SceneStatusCode::kIncomplete) {
        if (verdict->missing.empty())
          continue;  // the answer to a late begin
        for (const auto& g : verdict->missing) {
          const std::size_t first = static_cast<std::size_t>(g.offset / chunk);
          const std::size_t last = static_cast<std::size_t>((g.offset + g.length - 1) / chunk);
          for (std::size_t i = first; i <= last && i < nchunks; ++i) {
            if (acked[i]) {
              acked[i] = 0;
              --acked_count;
              acked_bytes -=
                  std::min<std::uint64_t>(chunk, bytes.size() - i * std::uint64_t{chunk});
            }
            sent_ns[i] = 0;
          }
        }
        resend = true;
      }
      // kValidating: keep committing (each answer is idempotent) until the verdict
    }
  }
}

}  // namespace hapticd::proto
