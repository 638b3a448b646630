#pragma once
/// \file
/// The daemon's UDP endpoint. One ordinary (non-servo) daemon thread owns a Server and calls
/// poll() in a loop (or run()). Per datagram, in this order: size bound, per-peer rate limit,
/// header, tag and replay window (when a key is set), session, payload decode, then the message:
/// hello/welcome, scene upload reassembly, pose commands and arm/disarm handed to the daemon,
/// subscriptions served at their rate, status. Every refused datagram is counted by reason
/// (Errc) and, where answering cannot be abused for reflection, answered with an Error.
///
/// The daemon wires it like this (see protocol/README.md, "Wiring the server"):
/// \code
///   proto::ServerConfig cfg;                       // bind 127.0.0.1:47100, no key
///   proto::ServerHandlers h;
///   h.on_command = [&](const proto::CommandEvent& e) { return servo_queue.push(e); };
///   h.on_scene = [&](proto::SceneUploadDone&& s) { loader.enqueue(std::move(s)); };
///   h.fill_state = [&](proto::State& st) { return state_block.read(st); };
///   h.fill_status = [&](proto::StatusReply& r) { r.device = device_name; ... };
///   auto server = proto::Server::create(cfg, h);   // Result: a clear error if bind fails
///   std::thread net([&] { server.value()->run(stop); });
///   // loader thread, when a scene is validated and swapped in (or refused):
///   server.value()->finishScene(ticket, accepted, first_error_text);
/// \endcode
/// The servo thread never touches the Server: it drains the queue that on_command fills
/// (proto::SpscRing<CommandEvent>) into a proto::CommandGate every tick.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "core/common/result.h"
#include "protocol/auth.h"
#include "protocol/messages.h"
#include "protocol/udp.h"
#include "protocol/upload.h"

namespace hapticd::proto {

/// CLOCK_MONOTONIC in ns. Any thread.
std::uint64_t monotonicNs();

/// Server settings. Every field has its default here (the daemon's config keys mirror them).
struct ServerConfig {
  std::string bind_address = std::string(kDefaultBindAddress);  ///< "IP:PORT" or "[IPv6]:PORT"
  std::optional<Key> key;  ///< pre-shared key; set: scene and command messages need a valid tag
  /// Refuse to start on a non-loopback address without a key unless this is true.
  bool allow_remote_without_key = false;
  std::size_t max_datagram_bytes = 16384;  ///< larger datagrams are refused (kTooLong)
  RateLimitConfig rate_limit;              ///< per peer address
  UploadLimits upload;                     ///< per upload
  std::size_t max_concurrent_uploads = 2;  ///< sessions uploading at once
  std::size_t max_sessions = 64;
  std::uint64_t session_timeout_ns = 10'000'000'000;   ///< silent this long: session dropped (10 s)
  std::uint32_t max_state_rate_hz = kMaxStateRateHz;   ///< subscribe rates are clamped to this
  std::uint32_t tick_rate_hz = 1000;                   ///< told to clients in Welcome
  std::size_t max_state_contacts = kMaxStateContacts;  ///< contacts listed per State
  std::size_t max_state_bodies = kMaxStateBodies;      ///< bodies listed per State
  std::size_t max_peers = 1024;        ///< rate-limit buckets kept (oldest forgotten first)
  int receive_buffer_bytes = 4 << 20;  ///< SO_RCVBUF
  /// Monotonic time in ns; tests give a simulated clock. Default: monotonicNs.
  std::function<std::uint64_t()> clock;
};

/// A pose command, arm or disarm for the servo thread. Trivially copyable (fits an SPSC ring).
struct CommandEvent {
  enum class Kind : std::uint8_t { kPose, kArm, kDisarm };
  Kind kind = Kind::kPose;
  bool authenticated = false;  ///< its tag verified (always false without a key)
  std::uint64_t session_id = 0;
  std::uint64_t sequence = 0;             ///< header sequence: the CommandGate orders by it
  std::uint64_t sender_timestamp_ns = 0;  ///< sender's clock, for latency figures only
  std::uint64_t received_ns = 0;          ///< server clock when received
  PoseCommand pose;                       ///< kPose only
};

static_assert(std::is_trivially_copyable_v<CommandEvent>, "CommandEvent travels in an SpscRing");

/// A scene upload that is complete and whose SHA-256 matched, for the daemon to validate, build
/// and swap in off the servo thread. Answer with Server::finishScene(ticket, ...).
struct SceneUploadDone {
  std::uint64_t ticket = 0;
  std::uint64_t session_id = 0;
  std::string name;
  std::array<std::uint8_t, 32> sha256{};
  std::vector<std::uint8_t> bytes;  ///< the whole .glb
};

/// The daemon's side. Every callback runs on the server thread (the one in poll()) and must not
/// block for long (push to a queue, read a seqlock). Any may be empty.
struct ServerHandlers {
  /// A pose command, arm or disarm. Return false when the queue to the servo is full (counted
  /// in StatusReply::commands_dropped; an arm or disarm is then answered with Error kServerFull).
  std::function<bool(const CommandEvent&)> on_command;
  /// A complete, hashed scene. Empty: every upload is accepted at once (tests).
  std::function<void(SceneUploadDone&&)> on_scene;
  /// A scene update. Return false with *error set to refuse it (answered with Error kBadValue).
  std::function<bool(std::uint64_t session_id, const SceneUpdate&, std::string* error)>
      on_scene_update;
  /// Fills the newest state (the server then trims lists to each subscriber's flags and the
  /// configured bounds). Return false when there is none yet (nothing is sent).
  std::function<bool(State&)> fill_state;
  /// Fills the daemon's part of a status reply (device, scene, plan, tick figures, faults,
  /// commands accepted). The server then sets sessions, subscribers, state_rate_hz, packets and
  /// the refused counters.
  std::function<void(StatusReply&)> fill_status;
};

/// Counters, readable from any thread.
struct ServerCounters {
  std::array<std::atomic<std::uint64_t>, kErrcCount> refused{};  ///< by Errc
  std::atomic<std::uint64_t> received{0};
  std::atomic<std::uint64_t> sent{0};
  std::atomic<std::uint64_t> send_failed{0};
  std::atomic<std::uint64_t> commands_forwarded{0};
  std::atomic<std::uint64_t> commands_queue_full{0};
  std::atomic<std::uint64_t> states_sent{0};
  std::atomic<std::uint64_t> scenes_completed{0};
  std::atomic<std::uint64_t> sessions{0};  ///< open now
};

/// See the file comment. Create on any thread; poll()/run() on one thread only; finishScene(),
/// counters() and stop() from any thread.
class Server {
 public:
  /// Binds the socket. Errors: bad address, bind failure, a non-loopback address without a key
  /// (unless allow_remote_without_key), a max_datagram_bytes out of 512..kMaxDatagramLimit.
  static Result<std::unique_ptr<Server>> create(ServerConfig config, ServerHandlers handlers);
  ~Server();

  /// Waits up to timeout_ms (less when a state is due) for datagrams, handles all waiting ones,
  /// sends the states that are due, answers finished scenes, expires silent sessions and stale
  /// uploads. Server thread.
  void poll(int timeout_ms);
  /// poll(5) until `stop` is true. Server thread.
  void run(const std::atomic<bool>& stop);

  /// The daemon's verdict on upload `ticket`: accepted (swapped in), or refused with the first
  /// error text (the old scene stays). Any thread; answered on the next poll().
  void finishScene(std::uint64_t ticket, bool accepted, std::string text);

  const ServerCounters& counters() const { return counters_; }
  SocketAddress localAddress() const { return socket_.localAddress(); }
  const ServerConfig& config() const { return config_; }
  /// Sessions open now (as of the server thread's last change). Any thread.
  std::size_t sessionCount() const { return static_cast<std::size_t>(counters_.sessions.load()); }

 private:
  enum class UploadState : std::uint8_t { kNone, kReceiving, kValidating, kAccepted, kRefused };
  struct Session {
    std::uint64_t id = 0;
    SocketAddress peer;
    bool authenticated = false;  // hello verified: every later datagram must be tagged
    std::string name;
    std::uint64_t last_rx_ns = 0;
    std::uint64_t tx_sequence = 0;
    std::uint64_t last_peer_timestamp_ns = 0;
    std::uint64_t hello_sequence = 0;  // the hello that opened the session
    std::uint64_t hello_timestamp_ns = 0;
    ReplayWindow replay;
    std::uint32_t rate_hz = 0;
    std::uint32_t sub_flags = 0;
    std::uint64_t next_state_ns = 0;  // next state slot; kSubscribeEachTick: next look
    bool sent_state = false;
    std::uint64_t last_state_tick = 0;  // tick of the last state sent
    double state_credit = 0.0;          // kSubscribeEachTick: states that may be sent now
    std::uint64_t credit_ns = 0;        // when state_credit was last refilled
    Reassembly upload;
    UploadState upload_state = UploadState::kNone;
    std::uint32_t upload_id = 0;  // of the current or last finished upload
    std::uint64_t upload_total = 0;
    std::uint64_t ticket = 0;
    std::string upload_text;  // the refusal text of the last upload
  };
  struct Peer {
    TokenBucket bucket;
    std::uint64_t last_ns = 0;
  };
  Server(ServerConfig config, ServerHandlers handlers, UdpSocket socket);

  void handleDatagram(std::span<const std::uint8_t> d,
                      const SocketAddress& from,
                      std::uint64_t now);
  void refuse(Errc why,
              const SocketAddress& from,
              const Header* h,
              Session* s,
              bool answer,
              const std::string& text);
  /// The session a non-hello datagram belongs to, after the session, peer, tag and replay
  /// checks; nullptr when refused (counted, answered where the rules say).
  Session* admit(const Header& h, bool tagged, const SocketAddress& from);
  /// Handles a decoded message of session `s`.
  void dispatch(Session& s, const Header& h, bool tagged, const Message& m, std::uint64_t now);
  /// Hands a pose, arm or disarm to on_command; false when its queue was full (counted).
  bool forward(const Session& s,
               const Header& h,
               bool tagged,
               CommandEvent::Kind kind,
               const PoseCommand* pose,
               std::uint64_t now);
  /// The daemon's status (fill_status) with the server's own figures.
  StatusReply statusReply(std::uint64_t now);
  void handleHello(const Header& h,
                   const Hello& m,
                   bool tagged,
                   const SocketAddress& from,
                   std::uint64_t now);
  void handleBegin(Session& s, const Header& h, const SceneBegin& m, std::uint64_t now);
  void handleChunk(Session& s, const Header& h, const SceneChunk& m, std::uint64_t now);
  void handleCommit(Session& s, const Header& h, const SceneCommit& m, std::uint64_t now);
  void sendSceneStatus(Session& s,
                       std::uint32_t upload_id,
                       SceneStatusCode code,
                       const std::string& text,
                       bool with_missing);
  void sendStates(std::uint64_t now);
  void sendTo(Session& s, const Message& m);
  void sendRaw(const SocketAddress& to,
               std::uint64_t session_id,
               std::uint64_t sequence,
               const Message& m);
  void expire(std::uint64_t now);
  void drainFinished();
  std::uint64_t now() const;
  std::size_t uploadsActive() const;
  Peer& peer(const SocketAddress& a, std::uint64_t now);

  ServerConfig config_;
  ServerHandlers handlers_;
  UdpSocket socket_;
  std::unordered_map<std::uint64_t, Session> sessions_;
  std::unordered_map<std::string, Peer> peers_;
  std::vector<std::uint8_t> rx_;
  std::vector<std::uint8_t> tx_;
  std::uint64_t next_ticket_ = 1;
  std::uint64_t last_expire_ns_ = 0;
  std::uint64_t start_ns_ = 0;
  std::uint64_t anon_sequence_ = 0;  // for answers outside a session
  ServerCounters counters_;
  std::mutex finished_mutex_;
  struct Finished {
    std::uint64_t ticket;
    bool accepted;
    std::string text;
  };
  std::vector<Finished> finished_;  // guarded by finished_mutex_
};

}  // namespace hapticd::proto
