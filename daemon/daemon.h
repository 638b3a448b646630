#pragma once
/// \file
/// The daemon's life (STYLE.md rule 15; chrony main.c): ordered init, the main thread's service
/// loop (signals, logging of servo events, device service, scene reclaim, watchdog, status), and
/// reverse teardown. main() only builds the Backends from the real libraries and calls
/// runDaemon(); tests call runDaemon() with fakes.
///
/// Threads: runDaemon() on the main thread. It starts the servo thread (real-time setup, then
/// ServoLoop::run()) and the record writer; everything else stays on the main thread.
/// Signals: SIGTERM and SIGINT ramp the force to zero and end (exit 0); SIGHUP reloads the
/// config file and the scene, keeping the old ones when the new are bad (the error is logged).

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "core/common/result.h"
#include "core/scene/scene.h"
#include "core/sim/simulation.h"
#include "daemon/command_line.h"
#include "daemon/config.h"
#include "daemon/device/device.h"
#include "daemon/realtime.h"

namespace hapticd::daemon {

/// Where devices, scenes and simulations come from (the real libraries in main(), fakes in tests).
struct Backends {
  std::function<Result<std::unique_ptr<device::Device>>(std::string_view spec,
                                                        const device::DeviceOptions&)>
      make_device;
  /// The scene of a config: [scene] path, or the built-in demo [scene] demo when path is empty.
  std::function<Result<std::shared_ptr<const scene::SceneModel>>(const Config&)> load_scene;
  std::function<Result<std::unique_ptr<sim::Simulation>>(std::shared_ptr<const scene::SceneModel>,
                                                         const sim::SimOptions&)>
      make_simulation;
  RealtimeOps realtime = RealtimeOps::system();
};

/// Exit codes of runDaemon().
enum ExitCode : int {
  kExitOk = 0,         ///< stopped by a signal or --ticks, or the replay stream ended
  kExitFailure = 1,    ///< a start-up step failed (device, scene, realtime "require", files)
  kExitBadConfig = 2,  ///< the configuration or the command line is bad
};

/// Runs the daemon until SIGTERM/SIGINT, the end of a replay stream or --ticks. Main thread.
/// Blocks SIGTERM, SIGINT and SIGHUP in the calling thread (and so in every thread it starts).
int runDaemon(const CommandLine& cli, const Backends& backends);

}  // namespace hapticd::daemon
