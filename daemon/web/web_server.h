#pragma once
/// \file
/// The daemon's WebSocket JSON API and the viewer's files (protocol/websocket.md): HTTP on "/"
/// serves a folder, a WebSocket on "/ws" carries one JSON object per text message. One ordinary
/// (non-servo) thread, `hapticd-web`, owns the server and runs its event loop (Boost.Asio and
/// Boost.Beast); it reaches the servo loop only through the handlers, which the daemon binds to
/// the same paths as the UDP server's (daemon/protocol_adapter.h): the command ring, the edit
/// ring, the state seqlocks, the upload queue.
///
/// Per message, in this order: size bound (read_message_max: larger is closed with 1009), per
/// connection rate limit (as UDP's per peer), JSON, "type", hello first, the key's tag for
/// anything that commands (when a key is set), then the message. A state is offered to each
/// subscriber on its rate grid; a subscriber that does not read holds at most one state waiting
/// (newer ones replace it, counted), and one whose answers pile up past a bound is closed, so
/// that a slow reader costs the server a bounded amount of memory and the servo loop nothing.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "daemon/web/web_json.h"
#include "protocol/auth.h"
#include "protocol/server.h"

namespace hapticd::web {

/// Settings: [web] and the [network] keys the WebSocket API shares with UDP.
struct WebServerConfig {
  std::string listen = "127.0.0.1:47180";     ///< "IP:PORT" or "[IPv6]:PORT"; port 0: any free one
  std::string root;                           ///< folder served on "/"; must exist
  std::optional<proto::Key> key;              ///< [network] key_file: commands need its tag
  std::size_t max_message_bytes = 16u << 20;  ///< client messages over this are refused
  proto::RateLimitConfig rate_limit;          ///< messages per connection
  std::uint32_t max_state_rate_hz = proto::kMaxStateRateHz;  ///< subscribe rates clamp to this
  std::uint32_t tick_rate_hz = 1000;                         ///< and to this
  std::size_t max_clients = 64;  ///< WebSocket connections at once (more get HTTP 503)
  /// Answers waiting for a client that does not read, bytes (states excluded: at most one waits);
  /// over it the connection is closed.
  std::size_t max_queued_bytes = 64u << 20;
  std::uint64_t max_scene_bytes = 64ull << 20;  ///< largest scene a load may carry (decoded)
  std::size_t max_concurrent_loads = 2;         ///< loads being built at once, all clients
};

/// The running scene as the viewer asks for it.
struct SceneSnapshot {
  std::string name;
  std::shared_ptr<const std::vector<std::uint8_t>> glb;  ///< the .glb bytes the daemon runs
  struct Body {
    std::uint32_t index = 0;  ///< the index in state "bodies" and in move/add/remove
    std::string name;         ///< the glTF node's name
    std::string motion;       ///< "static", "kinematic", "dynamic"
    bool probe = false;       ///< the held body
  };
  std::vector<Body> bodies;
  std::int32_t probe_body = -1;  ///< index of the held body; -1: a probe sphere of the config
  double length_scale = 1.0;     ///< the scene's bounding-box diagonal, m
};

/// The daemon's side. Every callback runs on the web thread; as proto::ServerHandlers.
struct WebHandlers {
  /// A pose, arm or disarm for the servo (false: its queue is full).
  std::function<bool(const proto::CommandEvent&)> on_command;
  /// A decoded, hashed scene to build (answered with finishScene).
  std::function<void(proto::SceneUploadDone&&)> on_scene;
  /// One scene edit; false with *error to refuse it.
  std::function<bool(std::uint64_t session_id, const proto::SceneUpdate&, std::string* error)>
      on_scene_update;
  /// The newest state; false when there is none yet.
  std::function<bool(proto::State&)> fill_state;
  /// The daemon's status.
  std::function<void(proto::StatusReply&)> fill_status;
  /// The running scene; an error when its bytes cannot be had.
  std::function<Result<SceneSnapshot>()> scene;
  /// Fault names ("none" or "a,b").
  FaultNames fault_names;
};

/// Counters, readable from any thread.
struct WebCounters {
  std::atomic<std::uint64_t> clients{0};      ///< WebSocket connections open now
  std::atomic<std::uint64_t> connections{0};  ///< accepted since start (HTTP and WebSocket)
  std::atomic<std::uint64_t> http_requests{0};
  std::atomic<std::uint64_t> messages{0};  ///< client messages read
  std::atomic<std::uint64_t> refused{0};   ///< answered with an error
  std::atomic<std::uint64_t> rate_limited{0};
  std::atomic<std::uint64_t> states_sent{0};
  std::atomic<std::uint64_t> states_replaced{0};  ///< a waiting state replaced by a newer one
  std::atomic<std::uint64_t> closed_slow{0};      ///< closed: answers piled up unread
  std::atomic<std::uint64_t> commands_forwarded{0};
  std::atomic<std::uint64_t> commands_queue_full{0};
};

class WebServerImpl;

/// See the file comment. create() on any thread; run() on one thread; finishScene(), counters()
/// and localAddress() from any thread.
class WebServer {
 public:
  /// Binds and listens. Errors: a bad address, a bind failure, a root that is not a folder.
  static Result<std::unique_ptr<WebServer>> create(WebServerConfig config, WebHandlers handlers);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// Serves until `stop` is true (checked every few ms), then closes every connection.
  void run(const std::atomic<bool>& stop);
  /// The daemon's verdict on load `ticket`: "loaded" ok, or the first error. Any thread.
  void finishScene(std::uint64_t ticket, bool accepted, std::string text);
  const WebCounters& counters() const;
  /// "ADDRESS:PORT" bound (the port chosen when 0 was asked).
  std::string localAddress() const;
  /// The folder served.
  const std::string& root() const;

  /// Tickets of web loads have this bit set (the UDP server's never do).
  static constexpr std::uint64_t kTicketBit = 1ull << 63;

 private:
  explicit WebServer(std::unique_ptr<WebServerImpl> impl);
  std::unique_ptr<WebServerImpl> impl_;
};

}  // namespace hapticd::web
