#pragma once
/// \file
/// The daemon's face to clients: the protocol server (protocol/server.h) on the network thread
/// (`hapticd-net`) and the shared-memory segment (protocol/shm.h), and the conversions between
/// them and the servo loop: a client's command becomes a ServoCommand on the loop's command ring
/// (the network thread is its only producer; the wire pose is converted once, there); a scene
/// update is validated against the running scene and queued whole as an EditBatch; the loop's
/// state and lists become State and StatusReply; a finished upload waits for the main thread.
///
/// Threads: the public members on the main thread (the owner); the server's handlers run on the
/// network thread and read what the main thread sets under a mutex.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/scene/scene.h"
#include "daemon/config.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "daemon/web/web_server.h"
#include "protocol/server.h"
#include "protocol/shm.h"

namespace hapticd::daemon {

/// The protocol server's settings: [network], and [servo] rate_hz. The key file is read and
/// parsed, a non-loopback address without a key refused. Errors name the key. Any normal thread
/// (also --check-config's).
Result<proto::ServerConfig> serverConfigOf(const Config& config);

/// The web server's settings: [web], and the key, rate limit and state rate of [network] (the
/// same as UDP's). The root: [web] root, else BIN/../share/hapticd/web when it is a folder, else
/// the source tree's web/. Errors as serverConfigOf (a non-loopback listen needs a key).
Result<web::WebServerConfig> webConfigOf(const Config& config);

/// The .glb bytes of the running scene, read when a viewer asks (web thread).
using SceneBytes = std::function<Result<std::vector<std::uint8_t>>()>;
class ProtocolAdapter {
 public:
  /// `loop` outlives the adapter.
  explicit ProtocolAdapter(ServoLoop& loop);
  ~ProtocolAdapter();  ///< stops the network thread
  ProtocolAdapter(const ProtocolAdapter&) = delete;
  ProtocolAdapter& operator=(const ProtocolAdapter&) = delete;

  /// Before the servo thread starts: creates the segment [network] shm ("" : none) and attaches
  /// it to the loop. A segment that cannot be created, or one another live hapticd serves, is a
  /// warning (logged): the daemon runs without it.
  void startShm(const std::string& name);
  /// After the servo thread ended: removes the segment.
  void closeShm();
  /// The server on [network] udp and its thread. Error: what and which key (exit 1).
  Result<bool> startNetwork(const Config& config);
  /// The web server on [web] listen and its thread `hapticd-web` ("" : nothing). Its commands,
  /// edits, uploads, state and status take the same paths as the UDP server's (the rings' producer
  /// side is shared under a mutex). Error: a bad [web] setting or key (exit 1); an address that
  /// cannot be bound is a warning (logged) and the daemon runs without it, like shared memory.
  Result<bool> startWeb(const Config& config);
  /// Stops and joins the network and web threads (again: nothing).
  void stopNetwork();

  /// What status replies name: the device.
  void setDevice(const std::string& name);
  /// The scene just offered to the loop: its name and plan, the model scene updates are
  /// validated against, and its generation.
  void setScene(const std::string& name,
                const std::string& plan,
                std::shared_ptr<const scene::SceneModel> model,
                std::uint64_t generation);

  /// What a scene build is doing ("" when none runs), for status replies (main thread).
  void setLoading(std::string text);

  /// Where the running scene's bytes come from (set with each scene: the configured file or demo,
  /// or the upload's bytes).
  void setSceneBytes(SceneBytes bytes);

  /// The next complete upload waiting to be built, if any.
  std::optional<proto::SceneUploadDone> takeUpload();
  /// The verdict on an upload: accepted (handed to the loop) or refused with the error's text.
  void finishUpload(std::uint64_t ticket, bool accepted, const std::string& text);

  /// The status file's "shm" and "network" objects, into `j`.
  void addStatus(nlohmann::json& j, const ServoState& st) const;

 private:
  bool onCommand(const proto::CommandEvent& e);  // network thread: the command ring's producer
  // network thread: the edit ring's producer. Validates `u` against the running scene model;
  // false with *error naming the first bad entry (nothing queued), or the ring full.
  bool onSceneUpdate(const proto::SceneUpdate& u, std::string* error);
  bool fillState(proto::State& out) const;         // network thread
  void fillStatus(proto::StatusReply& out) const;  // network thread
  Result<web::SceneSnapshot> sceneSnapshot();      // web thread

  ServoLoop& loop_;
  std::unique_ptr<proto::ShmServer> shm_;  // outlives the servo thread's run (closeShm after it)
  std::string shm_name_;
  std::string shm_error_;  // why [network] shm is not served ("" when it is)
  std::unique_ptr<proto::Server> server_;
  Thread net_thread_;
  std::atomic<bool> net_stop_{false};
  std::unique_ptr<web::WebServer> web_;
  Thread web_thread_;
  // the producer side of the command and edit rings (and edit_, edit_batches_): the network and
  // web threads take turns under it; the servo thread, the consumer, never takes it
  std::mutex producer_mutex_;
  std::chrono::steady_clock::time_point started_at_ = std::chrono::steady_clock::now();
  double servo_rate_hz_ = 1000.0;  // [servo] rate_hz (restart-only), set before the network runs
  mutable std::mutex info_mutex_;  // guards the fields below (the network thread reads them)
  std::string info_device_;
  std::string info_scene_;
  std::string info_plan_;
  std::string info_loading_;  // a scene build's progress, "" when none runs
  // the scene updates are validated against: set after the scene is offered, so that a batch
  // validated against it meets it at the servo
  std::shared_ptr<const scene::SceneModel> edit_model_;
  std::uint64_t edit_generation_ = 0;
  SceneBytes scene_bytes_;
  std::uint64_t glb_generation_ = 0;  // of glb_ (web thread)
  std::shared_ptr<const std::vector<std::uint8_t>> glb_;
  std::uint64_t edit_batches_ = 0;   // network thread: batches numbered for the log
  std::unique_ptr<EditBatch> edit_;  // network thread: scratch (too big for the stack)
  std::mutex upload_mutex_;
  std::deque<proto::SceneUploadDone> uploads_;  // guarded by upload_mutex_
};

}  // namespace hapticd::daemon
