#pragma once
/// \file
/// Scenes built off the servo thread: the scene of a config (start-up, SIGHUP) or of a client's
/// uploaded bytes, with its simulation; and the builder thread (`hapticd-build`, normal priority)
/// that runs one such build at a time, so that a large scene holds up neither the servo loop nor
/// the main thread's watchdog and log.
///
/// Threads: buildScene() and buildUploadedScene() on any normal thread; SceneBuilder's members on
/// its owner's thread (the main thread), its builds on the builder thread.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "daemon/backends.h"
#include "daemon/build_progress.h"
#include "daemon/command_line.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "protocol/server.h"

namespace hapticd::daemon {

/// A scene pipeline ready for the servo loop, with what the main thread records about it.
struct BuiltScene {
  std::unique_ptr<ServoScene> scene;
  std::string name;
  std::string plan;  ///< scene::describePlan of its plan
  std::vector<std::string> body_names;
  std::shared_ptr<const scene::SceneModel> model;  ///< what scene updates are validated against
  /// What the prewarm did ("prewarmed in 8.7 ms: 8 collision steps, 7 dynamics steps, at rest:
  /// sleeps from its first tick"); empty when the build ran none (the start-up scene).
  std::string prewarm;
};

/// Where the device is now (scene frame), read by a build right before its prewarm; none when
/// the servo loop has not ticked yet. Any thread.
using DevicePoseSource = std::function<std::optional<geom::Pose>()>;

/// The held body's start pose in `model`, device frame (through [device] workspace), when
/// [device] sim_home_from_scene is on and the scene has a probe body; else none. Any thread.
std::optional<geom::Pose> sceneHome(const Config& config, const scene::SceneModel& model);

/// The scene of `config` ([scene] path or demo) and its simulation (toSimOptions), as
/// generation `generation`. Error: the loader's or the simulation's text, naming the scene.
/// With `device_pose` (a scene that will be swapped into a running loop), the simulation is
/// prewarmed (sim::Simulation::prewarm, docs/architecture.md "Scene swaps") at the pose it gives
/// right then; without (the start-up scene), not.
Result<BuiltScene> buildScene(const Backends& backends,
                              const Config& config,
                              std::uint64_t generation,
                              const DevicePoseSource& device_pose = nullptr);
/// The same from an upload's bytes, parsed where they are (no file), named by the upload.
Result<BuiltScene> buildUploadedScene(const Backends& backends,
                                      const Config& config,
                                      const proto::SceneUploadDone& upload,
                                      std::uint64_t generation,
                                      const DevicePoseSource& device_pose = nullptr);

/// One build at a time on the builder thread: SIGHUP's reload, or an upload.
class SceneBuilder {
 public:
  /// What a build gives its owner.
  struct Finished {
    std::optional<proto::SceneUploadDone> upload;  ///< the upload built; empty: a reload
    std::optional<BuiltScene> built;               ///< empty: refused (error says why)
    std::string error;
    /// A reload: the configuration read again (the file and the command line), and the
    /// warnings it gave (deprecated keys).
    Config config;
    std::vector<std::string> warnings;
  };

  explicit SceneBuilder(const Backends& backends) : backends_(backends) {}
  ~SceneBuilder() { join(); }
  SceneBuilder(const SceneBuilder&) = delete;
  SceneBuilder& operator=(const SceneBuilder&) = delete;

  /// The device's pose for the prewarm of the scenes built from here on (every build of the
  /// builder swaps a scene into the running loop). Only when not busy().
  void setDevicePose(DevicePoseSource source) { device_pose_ = std::move(source); }
  /// A build runs, or has ended and was not taken by finished() yet.
  bool busy() const { return thread_.joinable(); }
  /// SIGHUP: reads the configuration again (buildConfig(cli)) and builds its scene, with
  /// `running`'s restart-only sections ([servo], [device], [network]). Error: the thread did not
  /// start (nothing runs). Only when not busy().
  Result<bool> startReload(const CommandLine& cli, const Config& running, std::uint64_t generation);
  /// An upload: builds its bytes with `running`. Error and precondition as startReload().
  Result<bool> startUpload(proto::SceneUploadDone upload,
                           const Config& running,
                           std::uint64_t generation);
  /// What the running build is doing ("loading scene 'x.glb': decomposing mesh 2 ..."), as its
  /// loader last reported (reportBuildProgress()); meaningful while busy().
  std::string progress() const { return progress_.text(); }
  /// The build that ended (its thread joined), once; nothing while one runs or none ran.
  std::optional<Finished> finished();
  /// Waits for a running build and drops its result (teardown).
  void join();

 private:
  Result<bool> start(std::string what, std::function<void(Finished&)> work);

  const Backends& backends_;
  DevicePoseSource device_pose_;
  Thread thread_;
  std::atomic<bool> done_{false};
  Finished result_;  // written by the builder before done_, read by the owner after
  BuildProgress progress_;
};

/// Sections a reload does not change (they take effect at restart).
inline constexpr std::string_view kRestartOnlySections[] = {"servo", "device", "network", "web"};

}  // namespace hapticd::daemon
