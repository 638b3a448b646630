#pragma once
/// \file
/// Where the daemon's devices, scenes and simulations come from: the real libraries in main(),
/// fakes in tests (runDaemon() takes them).
///
/// Threads: make_device on the main thread; load_scene, load_scene_bytes and make_simulation on
/// the main thread (start-up) and the builder thread (SIGHUP, uploads).

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "core/common/result.h"
#include "core/scene/scene.h"
#include "core/sim/simulation.h"
#include "daemon/config.h"
#include "daemon/device/device.h"
#include "daemon/realtime.h"

namespace hapticd::daemon {

using SceneResult = Result<std::shared_ptr<const scene::SceneModel>>;

struct Backends {
  std::function<Result<std::unique_ptr<device::Device>>(std::string_view spec,
                                                        const device::DeviceOptions&)>
      make_device;
  /// The scene of a config: [scene] path, or the built-in demo [scene] demo when path is empty.
  std::function<SceneResult(const Config&)> load_scene;
  /// A scene from bytes in memory (a client's upload), named `name` in messages, with the
  /// config's [scene] limits. Empty: uploads are refused.
  std::function<
      SceneResult(std::span<const std::uint8_t> bytes, const std::string& name, const Config&)>
      load_scene_bytes;
  std::function<Result<std::unique_ptr<sim::Simulation>>(std::shared_ptr<const scene::SceneModel>,
                                                         const sim::SimOptions&)>
      make_simulation;
  RealtimeOps realtime = RealtimeOps::system();
};

}  // namespace hapticd::daemon
