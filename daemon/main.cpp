// hapticd: a thin main. Parses the command line, binds the real device backends, scene loader,
// demo scenes and simulation, and runs the daemon (daemon/daemon.h: ordered init, reverse
// teardown).
#include <exception>
#include <memory>
#include <string>

#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/command_line.h"
#include "daemon/daemon.h"
#include "daemon/device/device.h"
#include "daemon/log.h"
#include "scenes/demo_scenes.h"

namespace {

using namespace hapticd;

Result<std::shared_ptr<const scene::SceneModel>> loadConfiguredScene(const daemon::Config& c) {
  const scene::LoadOptions options = daemon::toLoadOptions(c);
  scene::LoadReport report;
  if (c.scene.path.empty()) {
    const std::vector<std::uint8_t> bytes = scenes::makeDemoScene(c.scene.demo);
    if (bytes.empty()) {
      std::string known;
      for (auto n : scenes::demoSceneNames())
        known += (known.empty() ? "" : ", ") + std::string(n);
      return Error{"[scene] demo: \"" + c.scene.demo + "\" is not a demo scene (" + known + ")"};
    }
    report = scene::loadScene(bytes, c.scene.demo, options);
  } else {
    report = scene::loadSceneFile(c.scene.path, options);
  }
  if (!report.ok()) {
    const std::string what = c.scene.path.empty() ? "[scene] demo '" + c.scene.demo + "'"
                                                  : "[scene] path '" + c.scene.path + "'";
    std::string text = report.message();
    while (!text.empty() && text.back() == '\n')
      text.pop_back();
    return Error{what + ": " + text};
  }
  return std::shared_ptr<const scene::SceneModel>(
      std::make_shared<scene::SceneModel>(std::move(*report.scene)));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    daemon::CommandLine cli;
    if (auto code = daemon::parseCommandLine(argc, argv, cli))
      return *code;
    daemon::Backends backends;
    backends.make_device = &device::makeDevice;
    backends.load_scene = &loadConfiguredScene;
    backends.make_simulation = &sim::Simulation::create;
    return daemon::runDaemon(cli, backends);
  } catch (const std::exception& e) {
    daemon::logError(std::string("fatal: ") + e.what());
    return daemon::kExitFailure;
  }
}
