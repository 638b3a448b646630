// hapticd: a thin main. Parses the command line, binds the real device backends, scene loader,
// demo scenes and simulation, and runs the daemon (daemon/daemon.h: ordered init, reverse
// teardown).
#include <exception>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/build_progress.h"
#include "daemon/command_line.h"
#include "daemon/daemon.h"
#include "daemon/device/device.h"
#include "daemon/log.h"
#include "scenes/demo_scenes.h"

namespace {

using namespace hapticd;

// the loader's model, or its problems named by `what`
daemon::SceneResult modelOf(scene::LoadReport report, const std::string& what) {
  for (const std::string& w : report.warnings) {
    std::string line = what;
    line += ": ";
    line += w;
    daemon::logWarning(line);
  }
  if (!report.ok()) {
    std::string text = report.message();
    while (!text.empty() && text.back() == '\n')
      text.pop_back();
    return Error{what + ": " + text};
  }
  return std::shared_ptr<const scene::SceneModel>(
      std::make_shared<scene::SceneModel>(std::move(*report.scene)));
}

daemon::SceneResult loadConfiguredScene(const daemon::Config& c) {
  scene::LoadOptions options = daemon::toLoadOptions(c);
  options.progress =
      daemon::loadProgressReporter(c.scene.path.empty() ? c.scene.demo : c.scene.path);
  if (!c.scene.path.empty())
    return modelOf(scene::loadSceneFile(c.scene.path, options),
                   "[scene] path '" + c.scene.path + "'");
  const std::vector<std::uint8_t> bytes = scenes::makeDemoScene(c.scene.demo);
  if (bytes.empty()) {
    std::string known;
    for (auto n : scenes::demoSceneNames())
      known += (known.empty() ? "" : ", ") + std::string(n);
    return Error{"[scene] demo: \"" + c.scene.demo + "\" is not a demo scene (" + known + ")"};
  }
  return modelOf(scene::loadScene(bytes, c.scene.demo, options),
                 "[scene] demo '" + c.scene.demo + "'");
}

// an upload: parsed from the bytes as they arrived (no file). Its external URIs are refused: a
// client's relative path never resolves against the daemon's folders ([scene] allowed_uri_dir is
// for the daemon's own scene files); `hapticctl load` bundles a .gltf's buffers into a GLB.
daemon::SceneResult loadUploadedScene(std::span<const std::uint8_t> bytes,
                                      const std::string& name,
                                      const daemon::Config& c) {
  scene::LoadOptions options = daemon::toLoadOptions(c);
  options.allowed_uri_dir.reset();
  options.progress = daemon::loadProgressReporter(name);
  return modelOf(scene::loadScene(bytes, name, options), "scene '" + name + "'");
}

// the bytes of a config's scene, for viewers: the file (a .glb) or the demo
Result<std::vector<std::uint8_t>> configuredSceneBytes(const daemon::Config& c) {
  if (c.scene.path.empty())
    return scenes::makeDemoScene(c.scene.demo);
  std::ifstream in(c.scene.path, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
  if (!in && !in.eof())
    return Error{"[scene] path '" + c.scene.path + "': cannot read it"};
  if (bytes.size() < 4 || bytes[0] != 'g' || bytes[1] != 'l' || bytes[2] != 'T' || bytes[3] != 'F')
    return Error{
        "[scene] path '" + c.scene.path +
        "' is not a .glb: viewers take the binary glTF (a .gltf's data is in other files)"};
  return bytes;
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
    backends.load_scene_bytes = &loadUploadedScene;
    backends.scene_bytes = &configuredSceneBytes;
    backends.make_simulation = &sim::Simulation::create;
    return daemon::runDaemon(cli, backends);
  } catch (const std::exception& e) {
    daemon::logError(std::string("fatal: ") + e.what());
    return daemon::kExitFailure;
  }
}
