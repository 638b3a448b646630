#include "daemon/scene_builder.h"

#include <chrono>
#include <cstdio>
#include <utility>

namespace hapticd::daemon {
namespace {

// "prewarmed in 8.7 ms: 8 collision steps, 7 dynamics steps, at rest: sleeps from its first tick"
std::string describePrewarm(const sim::PrewarmReport& r, double ms) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f", ms);
  std::string s = "prewarmed in " + std::string(buf) + " ms: " + std::to_string(r.collision_steps) +
                  " collision steps";
  if (r.dynamics_steps > 0)
    s += ", " + std::to_string(r.dynamics_steps) + " dynamics steps";
  if (r.at_rest)
    s += ", at rest: sleeps from its first tick";
  return s;
}

Result<BuiltScene> withSimulation(const Backends& backends,
                                  const Config& config,
                                  SceneResult scene,
                                  std::uint64_t generation,
                                  const DevicePoseSource& device_pose) {
  if (!scene)
    return scene.error();
  auto model = scene.value();
  auto sim = backends.make_simulation(model, toSimOptions(config));
  if (!sim)
    return Error{"scene '" + model->name + "': " + sim.error().message};
  std::string prewarm;
  if (device_pose) {
    // the scene's first ticks' cold work, here rather than on the servo thread, at the pose the
    // device has now (docs/architecture.md "Scene swaps")
    const auto t0 = std::chrono::steady_clock::now();
    const sim::PrewarmReport r = sim.value()->prewarm(device_pose());
    prewarm = describePrewarm(
        r,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  BuiltScene built;
  built.prewarm = std::move(prewarm);
  built.scene = std::make_unique<ServoScene>();
  built.scene->sim = std::move(sim.value());
  built.scene->generation = generation;
  built.scene->X_D_home = sceneHome(config, *model);
  built.name = model->name;
  built.model = model;
  built.plan = scene::describePlan(model->plan);
  built.body_names.reserve(model->bodies.size());
  for (const auto& b : model->bodies)
    built.body_names.push_back(b.name);
  return built;
}

// restart-only sections keep running as they are
Config withRunningRestartOnly(Config next, const Config& running) {
  next.servo = running.servo;
  next.device = running.device;
  next.network = running.network;
  return next;
}

}  // namespace

std::optional<geom::Pose> sceneHome(const Config& config, const scene::SceneModel& model) {
  if (!config.device.sim_home_from_scene || model.probe_body < 0)
    return std::nullopt;
  return config.device.workspace.toDevice(
      model.bodies[static_cast<std::size_t>(model.probe_body)].X_WB);
}

Result<BuiltScene> buildScene(const Backends& backends,
                              const Config& config,
                              std::uint64_t generation,
                              const DevicePoseSource& device_pose) {
  return withSimulation(backends, config, backends.load_scene(config), generation, device_pose);
}

Result<BuiltScene> buildUploadedScene(const Backends& backends,
                                      const Config& config,
                                      const proto::SceneUploadDone& upload,
                                      std::uint64_t generation,
                                      const DevicePoseSource& device_pose) {
  if (!backends.load_scene_bytes)
    return Error{"this daemon takes no scene uploads"};
  const std::string name = upload.name.empty() ? std::string("upload") : upload.name;
  return withSimulation(backends, config, backends.load_scene_bytes(upload.bytes, name, config),
                        generation, device_pose);
}

Result<bool> SceneBuilder::start(std::string what, std::function<void(Finished&)> work) {
  done_ = false;
  result_ = Finished{};
  progress_.set(std::move(what));
  return thread_.start("hapticd-build", 4 << 20, [this, work = std::move(work)] {
    const BuildProgressScope scope(&progress_);
    work(result_);
    done_ = true;
  });
}

Result<bool> SceneBuilder::startReload(const CommandLine& cli,
                                       const Config& running,
                                       std::uint64_t generation) {
  return start("reloading the configuration and the scene (SIGHUP)",
               [this, &cli, running, generation](Finished& f) {
                 auto config = buildConfig(cli);
                 if (!config) {
                   f.error = config.error().message;
                   return;
                 }
                 f.config = config.value().config;
                 f.warnings = config.value().warnings;
                 auto built = buildScene(backends_, withRunningRestartOnly(f.config, running),
                                         generation, device_pose_);
                 if (built)
                   f.built = std::move(built.value());
                 else
                   f.error = built.error().message;
               });
}

Result<bool> SceneBuilder::startUpload(proto::SceneUploadDone upload,
                                       const Config& running,
                                       std::uint64_t generation) {
  std::string what = "loading uploaded scene '" + upload.name + "' (" +
                     std::to_string(upload.bytes.size()) + " bytes)";
  return start(
      std::move(what), [this, up = std::move(upload), running, generation](Finished& f) mutable {
        auto built = buildUploadedScene(backends_, running, up, generation, device_pose_);
        if (built)
          f.built = std::move(built.value());
        else
          f.error = built.error().message;
        if (!built)
          up.bytes = {};  // else kept: the daemon hands the running scene's bytes to viewers
        f.upload = std::move(up);
      });
}

std::optional<SceneBuilder::Finished> SceneBuilder::finished() {
  if (!thread_.joinable() || !done_.load())
    return std::nullopt;
  thread_.join();
  return std::move(result_);
}

void SceneBuilder::join() {
  thread_.join();
  result_ = Finished{};
}

}  // namespace hapticd::daemon
