#pragma once
/// \file
/// The client side of the UDP protocol, for hapticctl and visualization clients: hello, chunked
/// scene upload with resend, pose commands, subscription and state, arm/disarm, status. Blocking
/// calls with timeouts, one thread (the caller's). Errors come back as Result with a sentence
/// that names what failed; nothing throws.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <variant>

#include "core/common/result.h"
#include "protocol/auth.h"
#include "protocol/messages.h"
#include "protocol/udp.h"

namespace hapticd::proto {

/// Success without a value.
using Done = std::monostate;

/// Client settings; every field has its default.
struct ClientConfig {
  std::string server = std::string(kDefaultBindAddress);  ///< "HOST:PORT", "[V6]:PORT"
  std::optional<Key> key;                                 ///< pre-shared key: tag every datagram
  std::string name = "hapticctl";                         ///< shown in the server's status
  int timeout_ms = 2000;                                  ///< per request (hello, arm, status, ...)
  int resend_ms = 100;               ///< a request unanswered this long is sent again
  std::uint32_t chunk_bytes = 1200;  ///< scene chunk size (≤ the server's max_chunk_bytes)
  std::size_t window = 64;           ///< scene chunks in flight
  int chunk_resend_ms = 50;          ///< an unacknowledged chunk is resent after this
  int load_timeout_ms = 120000;      ///< a whole upload, validation included
  std::size_t state_queue = 4096;    ///< states kept for receiveState (oldest dropped)
  /// A heartbeat is sent when nothing was sent for this long, from any call that waits (so a
  /// session that only watches states stays open); 0 disables. Keep it well under the server's
  /// session_timeout_ns (10 s by default).
  int heartbeat_ms = 1000;
};

/// What a client saw the server refuse (Error messages), counted by code.
struct ClientCounters {
  std::uint64_t received = 0;
  std::uint64_t sent = 0;
  std::uint64_t bad = 0;             ///< datagrams that failed to decode or verify
  std::uint64_t errors = 0;          ///< Error messages received
  std::uint64_t states_dropped = 0;  ///< states dropped because the queue was full
  std::uint64_t chunks_sent = 0;     ///< chunk datagrams including resends
  std::uint64_t chunks_resent = 0;
  ErrorMsg last_error;
};

/// See the file comment. Not thread-safe: one thread uses a Client.
class Client {
 public:
  /// Resolves the server, opens a socket connected to it and exchanges hello/welcome (hello
  /// resent every resend_ms until timeout_ms). Errors: a bad address; a refusal (its text); no
  /// answer: at once when the port is unreachable (nothing listens there; loopback says so at
  /// once), else after timeout_ms; with a key, "wrong key" when the daemon answers an untagged
  /// hello (it runs, has a key, and dropped ours), else that the key may also be wrong.
  static Result<std::unique_ptr<Client>> connect(ClientConfig config);
  ~Client();

  /// Uploads `bytes` as scene `name`: begin, chunks in a window with resend until each is
  /// acknowledged, commit until the server accepts or refuses. Ok when accepted; the error is the
  /// server's first error text when refused. `progress` (may be empty) gets bytes acknowledged.
  Result<Done> load(
      std::span<const std::uint8_t> bytes,
      const std::string& name,
      const std::function<void(std::uint64_t acked, std::uint64_t total)>& progress = {});
  /// Sends one pose command; returns its sequence number (no answer is awaited: the state's
  /// last_command_sequence shows it was taken).
  Result<std::uint64_t> sendPose(const PoseCommand& cmd);
  /// Subscribes to state at rate_hz (0 stops) with kSubscribe* flags; waits for the ack.
  Result<Done> subscribe(std::uint32_t rate_hz, std::uint32_t flags = 0);
  /// The oldest state received and not yet taken, waiting up to timeout_ms.
  std::optional<State> receiveState(int timeout_ms);
  /// Arms (clears a latched fault) / disarms; waits for the ack.
  Result<Done> arm();
  Result<Done> disarm();
  /// Sends a scene update; waits for the ack (or the refusal's text).
  Result<Done> sceneUpdate(const SceneUpdate& update);
  /// Asks for the server's status.
  Result<StatusReply> status();
  /// Round trip of a heartbeat in ns.
  Result<std::uint64_t> ping();
  /// Ends the session (no answer).
  void bye();
  /// Handles whatever is waiting (states, errors) without blocking; call it in idle loops.
  void pump() { processIncoming(0); }

  const Welcome& welcome() const { return welcome_; }
  /// The server's port was reported closed (ICMP port unreachable on the connected socket): no
  /// daemon listens there any more; every wait now ends at once.
  bool unreachable() const { return unreachable_; }
  const ClientCounters& counters() const { return counters_; }

 private:
  Client(ClientConfig config, UdpSocket socket, SocketAddress server);
  /// Whether an incoming message is the answer awaited.
  using Want = std::function<bool(const Header&, const Message&)>;
  /// Whether a reply answers a request, given the sequences of the copies sent so far.
  using Answers = std::function<bool(const Message&, const std::vector<std::uint64_t>& sent)>;

  /// The error for a hello nobody answered (see connect()).
  Error silence() const;
  std::uint64_t send(const Message& m);
  bool sendBytes(std::span<const std::uint8_t> datagram);
  /// Reads datagrams for up to timeout_ms; returns the first that `want` accepts (others are
  /// dispatched: states queued, errors counted). want == nullptr: just drain.
  std::optional<Message> processIncoming(int timeout_ms, const Want* want = nullptr);
  /// Calls `send_once` every resend_ms until `want` takes an answer (returned) or timeout_ms
  /// passes (nullopt).
  std::optional<Message> exchange(const std::function<void()>& send_once, const Want& want);
  /// Sends `m` (a new sequence each time) until `answers` takes a reply or an Error refers to a
  /// copy sent; the error says "<what> refused: ..." or "<what>: no answer ...".
  Result<Message> call(const Message& m, const char* what, const Answers& answers);
  /// call() for a request answered with Ack.
  Result<Done> request(const Message& m);

  // Scene upload phases (load()). Each returns the upload's result when it ended (accepted,
  // refused, lost, timed out), or nullopt to go on.
  struct Upload;
  using Phase = std::optional<Result<Done>>;
  /// Calls `send_once` every resend_ms until the server gives a verdict on the upload.
  Phase untilVerdict(Upload& up, std::uint64_t t_end, const std::function<void()>& send_once);
  /// Sends every chunk not acknowledged, a window at a time, resending the slow ones.
  Phase sendChunks(Upload& up, std::uint64_t t_end);
  /// Commits until a verdict or until the server names missing ranges (empty optional).
  Phase commit(Upload& up, std::uint64_t t_end);
  Phase uploadTimedOut() const;

  ClientConfig config_;
  UdpSocket socket_;
  SocketAddress server_;
  Welcome welcome_;
  std::uint64_t session_id_ = 0;
  std::uint64_t sequence_ = 0;
  std::uint32_t next_upload_id_ = 1;
  std::uint64_t last_send_ns_ = 0;
  bool unreachable_ = false;
  std::deque<State> states_;
  std::vector<std::uint8_t> rx_;
  std::vector<std::uint8_t> tx_;
  ClientCounters counters_;
};

}  // namespace hapticd::proto
