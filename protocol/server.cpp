#include "protocol/server.h"

#include <time.h>

#include <algorithm>

namespace hapticd::proto {

std::uint64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ull +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

namespace {

// kSubscribeEachTick: a session looks for a new tick every min(period / 4, this), and may send
// up to kEachTickBurst states in a row when ticks came close together (on average rate_hz).
constexpr std::uint64_t kEachTickLookNs = 250'000;
constexpr double kEachTickBurst = 4.0;

bool privileged(std::uint16_t type) {
  switch (static_cast<MsgType>(type)) {
    case MsgType::kSceneBegin:
    case MsgType::kSceneChunk:
    case MsgType::kSceneCommit:
    case MsgType::kSceneUpdate:
    case MsgType::kPoseCommand:
    case MsgType::kArm:
    case MsgType::kDisarm:
      return true;
    default:
      return false;
  }
}

std::string peerKey(const SocketAddress& a) {
  return std::string(reinterpret_cast<const char*>(&a.storage), a.length);
}

template <class... F>
struct Overload : F... {
  using F::operator()...;
};
template <class... F>
Overload(F...) -> Overload<F...>;

}  // namespace

Result<std::unique_ptr<Server>> Server::create(ServerConfig config, ServerHandlers handlers) {
  auto addr = parseAddress(config.bind_address);
  if (!addr)
    return Error{"protocol.bind: " + addr.error().message};
  if (!addr.value().isLoopback() && !config.key && !config.allow_remote_without_key)
    return Error{"protocol.bind: " + addr.value().toString() +
                 " is not a loopback address and no key is set: set protocol.key (64 hex "
                 "digits) or protocol.allow_remote_without_key = true"};
  if (config.max_datagram_bytes < 512 || config.max_datagram_bytes > kMaxDatagramLimit)
    return Error{"protocol.max_datagram_bytes: " + std::to_string(config.max_datagram_bytes) +
                 " is outside 512.." + std::to_string(kMaxDatagramLimit)};
  if (config.upload.max_chunk_bytes > kMaxChunkBytes ||
      config.upload.max_chunk_bytes + kHeaderSize + SceneChunk::kFixedSize + kMacSize >
          config.max_datagram_bytes)
    return Error{
        "protocol.upload.max_chunk_bytes: " + std::to_string(config.upload.max_chunk_bytes) +
        " does not fit a datagram of max_datagram_bytes with header and tag"};
  config.max_state_contacts = std::min(config.max_state_contacts, kMaxStateContacts);
  config.max_state_bodies = std::min(config.max_state_bodies, kMaxStateBodies);
  config.max_state_rate_hz = std::min(config.max_state_rate_hz, kMaxStateRateHz);
  auto sock = UdpSocket::bind(addr.value(), config.receive_buffer_bytes);
  if (!sock)
    return Error{"protocol.bind: " + sock.error().message};
  if (!config.clock)
    config.clock = monotonicNs;
  return std::unique_ptr<Server>(
      new Server(std::move(config), std::move(handlers), std::move(sock).value()));
}

Server::Server(ServerConfig config, ServerHandlers handlers, UdpSocket socket)
    : config_(std::move(config)), handlers_(std::move(handlers)), socket_(std::move(socket)) {
  rx_.resize(config_.max_datagram_bytes);
  tx_.resize(kMaxDatagramLimit);
  start_ns_ = now();
  last_expire_ns_ = start_ns_;
}

Server::~Server() = default;

std::uint64_t Server::now() const {
  return config_.clock();
}

void Server::run(const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed))
    poll(5);
}

void Server::poll(int timeout_ms) {
  drainFinished();
  std::uint64_t t = now();
  // wake for the first state due
  std::uint64_t due = UINT64_MAX;
  for (const auto& [id, s] : sessions_)
    if (s.rate_hz > 0)
      due = std::min(due, s.next_state_ns);
  std::uint64_t wait_ns =
      static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * std::uint64_t{1'000'000};
  if (due != UINT64_MAX)
    wait_ns = std::min(wait_ns, due > t ? due - t : 0);
  if (socket_.waitReadableNs(wait_ns)) {
    // bounded per round, so states go out under a flood
    for (int i = 0; i < 4096; ++i) {
      SocketAddress from;
      const Received r = socket_.receive(rx_, from);
      if (!r.got)
        break;
      t = now();
      if (r.truncated) {
        counters_.received.fetch_add(1, std::memory_order_relaxed);
        refuse(Errc::kTooLong, from, nullptr, nullptr, false, "");
        continue;
      }
      handleDatagram(std::span<const std::uint8_t>(rx_.data(), r.size), from, t);
      counters_.sessions.store(sessions_.size(), std::memory_order_relaxed);
    }
  }
  t = now();
  sendStates(t);
  if (t - last_expire_ns_ > 100'000'000) {
    expire(t);
    last_expire_ns_ = t;
    counters_.sessions.store(sessions_.size(), std::memory_order_relaxed);
  }
  drainFinished();
}

Server::Peer& Server::peer(const SocketAddress& a, std::uint64_t t) {
  const std::string k = peerKey(a);
  auto it = peers_.find(k);
  if (it == peers_.end()) {
    if (peers_.size() >= config_.max_peers) {
      auto oldest = peers_.begin();
      for (auto j = peers_.begin(); j != peers_.end(); ++j)
        if (j->second.last_ns < oldest->second.last_ns)
          oldest = j;
      peers_.erase(oldest);
    }
    it = peers_.emplace(k, Peer{TokenBucket(config_.rate_limit, t), t}).first;
  }
  it->second.last_ns = t;
  return it->second;
}

void Server::refuse(Errc why,
                    const SocketAddress& from,
                    const Header* h,
                    Session* s,
                    bool answer,
                    const std::string& text) {
  counters_.refused[static_cast<std::size_t>(why)].fetch_add(1, std::memory_order_relaxed);
  if (!answer)
    return;
  ErrorMsg e;
  e.ref_sequence = h ? h->sequence : 0;
  e.ref_type = h ? h->type : 0;
  e.code = why;
  e.text = text.substr(0, kMaxTextBytes);
  if (s)
    sendTo(*s, e);
  else
    sendRaw(from, h ? h->session_id : 0, ++anon_sequence_, e);
}

void Server::handleDatagram(std::span<const std::uint8_t> d,
                            const SocketAddress& from,
                            std::uint64_t t) {
  counters_.received.fetch_add(1, std::memory_order_relaxed);
  if (d.size() > config_.max_datagram_bytes)
    return refuse(Errc::kTooLong, from, nullptr, nullptr, false, "");
  if (!peer(from, t).bucket.take(t))
    return refuse(Errc::kRateLimited, from, nullptr, nullptr, false, "");

  Header h;
  if (DecodeError e = decodeHeader(d, h); e.code != Errc::kOk) {
    // answer only a datagram that is ours but of another major version: a clear error helps,
    // and anything else may be noise or a reflection attempt
    return refuse(e.code, from, nullptr, nullptr, e.code == Errc::kBadMajor, describe(e));
  }
  const bool tagged = (h.flags & kFlagMac) != 0;
  if (tagged) {
    if (!config_.key)
      return refuse(Errc::kBadMac, from, &h, nullptr, true,
                    "this server has no key set: send without a tag");
    if (!verifyTag(d, *config_.key))
      return refuse(Errc::kBadMac, from, &h, nullptr, false, "");
  }
  const auto payload = d.subspan(kHeaderSize, h.payload_length);

  if (h.type == static_cast<std::uint16_t>(MsgType::kHello)) {
    Message m;
    if (DecodeError e = decodePayload(h.type, h.minor, payload, m); e.code != Errc::kOk)
      return refuse(e.code, from, &h, nullptr, true, describe(e));
    return handleHello(h, std::get<Hello>(m), tagged, from, t);
  }
  Session* s = admit(h, tagged, from);
  if (s == nullptr)
    return;
  Message m;
  if (DecodeError e = decodePayload(h.type, h.minor, payload, m); e.code != Errc::kOk)
    return refuse(e.code, from, &h, s, true, describe(e));
  s->last_rx_ns = t;
  s->last_peer_timestamp_ns = h.timestamp_ns;
  dispatch(*s, h, tagged, m, t);
}

Server::Session* Server::admit(const Header& h, bool tagged, const SocketAddress& from) {
  auto it = sessions_.find(h.session_id);
  if (it == sessions_.end()) {
    refuse(Errc::kUnknownSession, from, &h, nullptr, !tagged || config_.key.has_value(),
           "unknown session " + std::to_string(h.session_id) + ": send hello first");
    return nullptr;
  }
  Session& s = it->second;
  if (!(s.peer == from)) {
    refuse(Errc::kWrongPeer, from, &h, nullptr, true,
           "session " + std::to_string(h.session_id) + " belongs to another address");
    return nullptr;
  }
  if (s.authenticated && !tagged) {
    refuse(Errc::kNoMac, from, &h, nullptr, true,
           "this session is authenticated: every datagram needs a tag");
    return nullptr;
  }
  if (config_.key && privileged(h.type) && !tagged) {
    refuse(Errc::kNoMac, from, &h, &s, true,
           std::string("a key is set: ") + msgTypeName(h.type) +
               " needs a tag (give the client the key)");
    return nullptr;
  }
  if (tagged) {
    if (!s.replay.check(h.sequence)) {
      refuse(Errc::kReplay, from, &h, nullptr, false, "");
      return nullptr;
    }
    s.replay.accept(h.sequence);
  }
  return &s;
}

bool Server::forward(const Session& s,
                     const Header& h,
                     bool tagged,
                     CommandEvent::Kind kind,
                     const PoseCommand* pose,
                     std::uint64_t t) {
  CommandEvent ev;
  ev.kind = kind;
  ev.authenticated = tagged;
  ev.session_id = s.id;
  ev.sequence = h.sequence;
  ev.sender_timestamp_ns = h.timestamp_ns;
  ev.received_ns = t;
  if (pose)
    ev.pose = *pose;
  const bool queued = !handlers_.on_command || handlers_.on_command(ev);
  if (queued)
    counters_.commands_forwarded.fetch_add(1, std::memory_order_relaxed);
  else
    counters_.commands_queue_full.fetch_add(1, std::memory_order_relaxed);
  return queued;
}

void Server::dispatch(Session& s, const Header& h, bool tagged, const Message& m, std::uint64_t t) {
  const SocketAddress from = s.peer;
  // arm and disarm are answered: Ack when queued for the servo thread, else "queue full"
  auto control = [&](CommandEvent::Kind kind, const char* full) {
    if (forward(s, h, tagged, kind, nullptr, t))
      sendTo(s, Ack{h.sequence, h.type});
    else
      refuse(Errc::kServerFull, from, &h, &s, true, full);
  };
  std::visit(
      Overload{
          [&](const SceneBegin& x) { handleBegin(s, h, x, t); },
          [&](const SceneChunk& x) { handleChunk(s, h, x, t); },
          [&](const SceneCommit& x) { handleCommit(s, h, x, t); },
          [&](const SceneUpdate& x) {
            std::string error;
            if (handlers_.on_scene_update && !handlers_.on_scene_update(s.id, x, &error))
              return refuse(Errc::kBadValue, from, &h, &s, true,
                            error.empty() ? std::string("scene update refused") : error);
            sendTo(s, Ack{h.sequence, h.type});
          },
          [&](const PoseCommand& x) { forward(s, h, tagged, CommandEvent::Kind::kPose, &x, t); },
          [&](const Arm&) { control(CommandEvent::Kind::kArm, "command queue full: arm again"); },
          [&](const Disarm&) {
            control(CommandEvent::Kind::kDisarm, "command queue full: disarm again");
          },
          [&](const Subscribe& x) {
            s.rate_hz = std::min(x.rate_hz, config_.max_state_rate_hz);
            s.sub_flags = x.flags;
            s.next_state_ns = t;
            s.sent_state = false;
            s.state_credit = 1.0;
            s.credit_ns = t;
            sendTo(s, Ack{h.sequence, h.type});
          },
          [&](const Heartbeat&) { sendTo(s, Heartbeat{h.timestamp_ns}); },
          [&](const StatusRequest&) { sendTo(s, statusReply(t)); },
          [&](const Bye&) { sessions_.erase(s.id); },
          [&](const Hello&) {},
          [&](const auto&) { refuse(Errc::kNotExpected, from, &h, nullptr, false, ""); },
      },
      m);
}

StatusReply Server::statusReply(std::uint64_t t) {
  StatusReply r;
  if (handlers_.fill_status)
    handlers_.fill_status(r);
  r.uptime_ns = r.uptime_ns ? r.uptime_ns : t - start_ns_;
  r.sessions = static_cast<std::uint32_t>(sessions_.size());
  r.subscribers = 0;
  r.state_rate_hz = 0;
  for (const auto& [id, o] : sessions_) {
    if (o.rate_hz > 0)
      ++r.subscribers;
    r.state_rate_hz += o.rate_hz;
  }
  r.packets_received = counters_.received.load();
  r.packets_sent = counters_.sent.load();
  r.commands_dropped += counters_.commands_queue_full.load();
  r.refused.resize(kErrcCount);
  for (std::size_t i = 0; i < kErrcCount; ++i)
    r.refused[i] = counters_.refused[i].load();
  if (r.device.size() > kMaxDeviceBytes)
    r.device.resize(kMaxDeviceBytes);
  if (r.scene.size() > kMaxSceneNameBytes)
    r.scene.resize(kMaxSceneNameBytes);
  if (r.plan.size() > kMaxPlanBytes)
    r.plan.resize(kMaxPlanBytes);
  return r;
}

void Server::handleHello(const Header& h,
                         const Hello& m,
                         bool tagged,
                         const SocketAddress& from,
                         std::uint64_t t) {
  auto welcome = [&](Session& s) {
    Welcome w;
    w.session_id = s.id;
    w.capabilities = kCapUdp | (config_.key ? kCapMac : 0u);
    w.flags =
        (config_.key ? kWelcomeKeyRequired : 0u) | (s.authenticated ? kWelcomeAuthenticated : 0u);
    w.max_datagram_bytes = static_cast<std::uint32_t>(config_.max_datagram_bytes);
    w.max_chunk_bytes = config_.upload.max_chunk_bytes;
    w.max_scene_bytes = config_.upload.max_scene_bytes;
    w.max_state_rate_hz = config_.max_state_rate_hz;
    w.tick_rate_hz = config_.tick_rate_hz;
    w.max_state_contacts = static_cast<std::uint16_t>(config_.max_state_contacts);
    w.max_state_bodies = static_cast<std::uint16_t>(config_.max_state_bodies);
    w.max_update_entries = static_cast<std::uint16_t>(kMaxUpdateEntries);
    w.session_timeout_ns = config_.session_timeout_ns;
    sendTo(s, w);
  };
  // one session per peer address: a new hello replaces it; the same hello again (the client
  // resends the identical datagram when the welcome was lost, or a replay) gets the same welcome
  for (auto it = sessions_.begin(); it != sessions_.end(); ++it) {
    if (!(it->second.peer == from))
      continue;
    if (it->second.hello_sequence == h.sequence &&
        it->second.hello_timestamp_ns == h.timestamp_ns && it->second.authenticated == tagged) {
      it->second.last_rx_ns = t;
      return welcome(it->second);
    }
    if (it->second.authenticated && !tagged)
      return refuse(Errc::kNoMac, from, &h, nullptr, true,
                    "an authenticated session is open from this address: hello needs a tag");
    sessions_.erase(it);
    break;
  }
  if (sessions_.size() >= config_.max_sessions)
    return refuse(Errc::kServerFull, from, &h, nullptr, true,
                  "server full: " + std::to_string(config_.max_sessions) + " sessions");
  std::uint64_t id = randomU64();
  while (sessions_.count(id))
    id = randomU64();
  Session& s = sessions_[id];
  s.id = id;
  s.peer = from;
  s.authenticated = tagged;
  s.name = m.client_name;
  s.last_rx_ns = t;
  s.last_peer_timestamp_ns = h.timestamp_ns;
  s.hello_sequence = h.sequence;
  s.hello_timestamp_ns = h.timestamp_ns;
  s.upload = Reassembly(config_.upload);
  // an authenticated session's window starts above the hello, so a replayed hello's number
  // cannot be used again inside this session
  if (tagged)
    s.replay.accept(h.sequence);
  welcome(s);
}

std::size_t Server::uploadsActive() const {
  std::size_t n = 0;
  for (const auto& [id, s] : sessions_)
    if (s.upload_state == UploadState::kReceiving || s.upload_state == UploadState::kValidating)
      ++n;
  return n;
}

void Server::sendSceneStatus(Session& s,
                             std::uint32_t upload_id,
                             SceneStatusCode code,
                             const std::string& text,
                             bool with_missing) {
  SceneStatus st;
  st.upload_id = upload_id;
  st.status = code;
  st.received_bytes = s.upload.active() ? s.upload.receivedBytes() : 0;
  st.total_bytes = s.upload.active() ? s.upload.totalBytes() : s.upload_total;
  if (code == SceneStatusCode::kAccepted || code == SceneStatusCode::kValidating)
    st.received_bytes = st.total_bytes;
  if (with_missing)
    st.missing = s.upload.missing(kMaxMissingRanges);
  st.text = text.substr(0, kMaxTextBytes);
  sendTo(s, st);
}

void Server::handleBegin(Session& s, const Header&, const SceneBegin& m, std::uint64_t t) {
  if (s.upload_state == UploadState::kValidating) {
    if (m.upload_id == s.upload_id)
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kValidating, "", false);
    return sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused,
                           "the previous scene is still being validated: try again", false);
  }
  if ((s.upload_state == UploadState::kAccepted || s.upload_state == UploadState::kRefused) &&
      m.upload_id == s.upload_id) {
    // a begin resent after the upload finished: repeat the verdict
    return sendSceneStatus(s, m.upload_id,
                           s.upload_state == UploadState::kAccepted ? SceneStatusCode::kAccepted
                                                                    : SceneStatusCode::kRefused,
                           s.upload_text, false);
  }
  const bool same = s.upload_state == UploadState::kReceiving && s.upload.uploadId() == m.upload_id;
  if (!same && s.upload_state != UploadState::kReceiving &&
      uploadsActive() >= config_.max_concurrent_uploads) {
    counters_.refused[static_cast<std::size_t>(Errc::kServerFull)]++;
    return sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused,
                           "server busy: " + std::to_string(config_.max_concurrent_uploads) +
                               " uploads in progress, try again",
                           false);
  }
  std::string error;
  s.upload_id = m.upload_id;
  s.upload_total = m.total_bytes;
  if (!s.upload.begin(m, t, &error)) {
    counters_.refused[static_cast<std::size_t>(Errc::kUploadError)]++;
    s.upload_state = UploadState::kRefused;
    s.upload_text = error;
    return sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused, error, false);
  }
  s.upload_state = UploadState::kReceiving;
  s.upload_text.clear();
  sendSceneStatus(s, m.upload_id, SceneStatusCode::kIncomplete, "", false);
}

void Server::handleChunk(Session& s, const Header&, const SceneChunk& m, std::uint64_t t) {
  if (m.upload_id != s.upload_id || s.upload_state == UploadState::kNone) {
    counters_.refused[static_cast<std::size_t>(Errc::kUploadError)]++;
    return sendSceneStatus(s, m.upload_id, SceneStatusCode::kUnknownUpload,
                           "no upload " + std::to_string(m.upload_id) + " in progress", false);
  }
  if (s.upload_state != UploadState::kReceiving) {
    // a late copy after the upload completed: acknowledge so the client stops resending
    SceneChunkAck a{m.upload_id, static_cast<std::uint32_t>(m.data.size()), m.offset,
                    s.upload_total, s.upload_total};
    return sendTo(s, a);
  }
  const ChunkOutcome o = s.upload.add(m.offset, m.data, t);
  if (o == ChunkOutcome::kStored || o == ChunkOutcome::kDuplicate) {
    SceneChunkAck a{m.upload_id, static_cast<std::uint32_t>(m.data.size()), m.offset,
                    s.upload.receivedBytes(), s.upload.totalBytes()};
    return sendTo(s, a);
  }
  counters_.refused[static_cast<std::size_t>(Errc::kUploadError)]++;
  s.upload_text = std::string("chunk at offset ") + std::to_string(m.offset) + " of " +
                  std::to_string(m.data.size()) + " bytes: " + chunkOutcomeText(o);
  s.upload.reset();
  s.upload_state = UploadState::kRefused;
  sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused, s.upload_text, false);
}

void Server::handleCommit(Session& s, const Header&, const SceneCommit& m, std::uint64_t t) {
  if (m.upload_id != s.upload_id || s.upload_state == UploadState::kNone)
    return sendSceneStatus(
        s, m.upload_id, SceneStatusCode::kUnknownUpload,
        "no upload " + std::to_string(m.upload_id) + " (never begun, timed out, or replaced)",
        false);
  switch (s.upload_state) {
    case UploadState::kValidating:
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kValidating, "", false);
    case UploadState::kAccepted:
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kAccepted, "", false);
    case UploadState::kRefused:
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused, s.upload_text, false);
    case UploadState::kNone:
    case UploadState::kReceiving:
      break;
  }
  switch (s.upload.commit(t)) {
    case CommitOutcome::kIncomplete:
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kIncomplete, "", true);
    case CommitOutcome::kHashMismatch:
    case CommitOutcome::kNotBegun:
      counters_.refused[static_cast<std::size_t>(Errc::kUploadError)]++;
      s.upload_state = UploadState::kRefused;
      s.upload_text = "the SHA-256 of the " + std::to_string(s.upload_total) +
                      " bytes received differs from the one announced in scene_begin: upload again";
      return sendSceneStatus(s, m.upload_id, SceneStatusCode::kRefused, s.upload_text, false);
    case CommitOutcome::kComplete:
      break;
  }
  SceneUploadDone done;
  done.ticket = next_ticket_++;
  done.session_id = s.id;
  done.name = s.upload.announced().name;
  done.sha256 = s.upload.announced().sha256;
  done.bytes = s.upload.take();
  s.ticket = done.ticket;
  counters_.scenes_completed.fetch_add(1, std::memory_order_relaxed);
  if (!handlers_.on_scene) {
    s.upload_state = UploadState::kAccepted;
    return sendSceneStatus(s, m.upload_id, SceneStatusCode::kAccepted, "", false);
  }
  s.upload_state = UploadState::kValidating;
  handlers_.on_scene(std::move(done));
  drainFinished();  // a handler that answers at once is answered now
  if (s.upload_state == UploadState::kValidating)
    sendSceneStatus(s, m.upload_id, SceneStatusCode::kValidating, "", false);
}

void Server::finishScene(std::uint64_t ticket, bool accepted, std::string text) {
  std::lock_guard<std::mutex> lock(finished_mutex_);
  finished_.push_back({ticket, accepted, std::move(text)});
}

void Server::drainFinished() {
  std::vector<Finished> done;
  {
    std::lock_guard<std::mutex> lock(finished_mutex_);
    done.swap(finished_);
  }
  for (auto& f : done) {
    for (auto& [id, s] : sessions_) {
      if (s.ticket != f.ticket || s.upload_state != UploadState::kValidating)
        continue;
      s.upload_state = f.accepted ? UploadState::kAccepted : UploadState::kRefused;
      s.upload_text = f.accepted ? "" : f.text;
      sendSceneStatus(s, s.upload_id,
                      f.accepted ? SceneStatusCode::kAccepted : SceneStatusCode::kRefused,
                      s.upload_text, false);
    }
  }
}

void Server::sendStates(std::uint64_t t) {
  bool any = false;
  for (const auto& [id, s] : sessions_)
    if (s.rate_hz > 0 && t >= s.next_state_ns)
      any = true;
  if (!any)
    return;
  State full;
  const bool have = handlers_.fill_state && handlers_.fill_state(full);
  for (auto& [id, s] : sessions_) {
    if (s.rate_hz == 0 || t < s.next_state_ns)
      continue;
    const std::uint64_t period = 1'000'000'000ull / s.rate_hz;
    if ((s.sub_flags & kSubscribeEachTick) != 0) {
      // each new tick once, as soon as it is seen, paced by a token bucket at rate_hz
      s.state_credit = std::min(
          kEachTickBurst, s.state_credit + static_cast<double>(t - s.credit_ns) * s.rate_hz * 1e-9);
      s.credit_ns = t;
      s.next_state_ns = t + std::min<std::uint64_t>(period / 4 + 1, kEachTickLookNs);
      if (!have || (s.sent_state && full.tick <= s.last_state_tick) || s.state_credit < 1.0)
        continue;
      s.state_credit -= 1.0;
    } else {
      s.next_state_ns += period;
      if (s.next_state_ns < t)
        s.next_state_ns = t + period;  // no burst after a stall
    }
    if (!have)
      continue;
    State st = full;
    if (!(s.sub_flags & kSubscribeContacts))
      st.contacts.clear();
    if (!(s.sub_flags & kSubscribeBodies))
      st.bodies.clear();
    if (st.contacts.size() > config_.max_state_contacts) {
      st.contacts.resize(config_.max_state_contacts);
      st.state_flags |= kStateContactsTruncated;
    }
    if (st.bodies.size() > config_.max_state_bodies) {
      st.bodies.resize(config_.max_state_bodies);
      st.state_flags |= kStateBodiesTruncated;
    }
    s.sent_state = true;
    s.last_state_tick = st.tick;
    sendTo(s, st);
    counters_.states_sent.fetch_add(1, std::memory_order_relaxed);
  }
}

void Server::sendTo(Session& s, const Message& m) {
  ++s.tx_sequence;
  sendRaw(s.peer, s.id, s.tx_sequence, m);
  (void)s;
}

void Server::sendRaw(const SocketAddress& to,
                     std::uint64_t session_id,
                     std::uint64_t sequence,
                     const Message& m) {
  Header h;
  h.session_id = session_id;
  h.sequence = sequence;
  h.timestamp_ns = now();
  // answers are tagged whenever a key is set (a client with the key verifies them; one without
  // ignores the tag after checking the length)
  Errc e = Errc::kOk;
  const std::size_t n = encodeDatagram(h, m, config_.key ? &*config_.key : nullptr, tx_, &e);
  if (n == 0) {
    counters_.send_failed.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (socket_.sendTo(to, std::span<const std::uint8_t>(tx_.data(), n)))
    counters_.sent.fetch_add(1, std::memory_order_relaxed);
  else
    counters_.send_failed.fetch_add(1, std::memory_order_relaxed);
}

void Server::expire(std::uint64_t t) {
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    Session& s = it->second;
    if (t - s.last_rx_ns > config_.session_timeout_ns) {
      it = sessions_.erase(it);
      continue;
    }
    if (s.upload_state == UploadState::kReceiving && s.upload.stale(t)) {
      s.upload.reset();
      s.upload_state = UploadState::kNone;
    }
    ++it;
  }
  if (peers_.size() > config_.max_peers / 2) {
    for (auto it = peers_.begin(); it != peers_.end();)
      it = (t - it->second.last_ns > 60'000'000'000ull) ? peers_.erase(it) : std::next(it);
  }
}

}  // namespace hapticd::proto
