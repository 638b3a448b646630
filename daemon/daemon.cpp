#include "daemon/daemon.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <future>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "daemon/clock.h"
#include "daemon/log.h"
#include "daemon/notify.h"
#include "daemon/protocol_adapter.h"
#include "daemon/record_writer.h"
#include "daemon/scene_builder.h"
#include "daemon/servo_loop.h"
#include "daemon/status_report.h"

namespace hapticd::daemon {
namespace {

using SteadyClock = std::chrono::steady_clock;

double secondsSince(SteadyClock::time_point t) {
  return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

// What the servo thread's real-time setup achieved, handed to the main thread before the loop.
struct ServoSetup {
  bool ok = false;
  std::string error;
  RealtimeReport report;
  std::string scheduling;
};

// The main thread's timers of its service loop.
struct ServiceTimers {
  SteadyClock::time_point service = SteadyClock::now();
  SteadyClock::time_point watchdog = SteadyClock::now();
  SteadyClock::time_point status_file = SteadyClock::now();
  SteadyClock::time_point status_line = SteadyClock::now();
  std::uint64_t watchdog_tick = 0;
  std::chrono::microseconds watchdog_interval = watchdogInterval();  // systemd's WatchdogSec
};

class Daemon {
 public:
  Daemon(const CommandLine& cli, const Backends& backends)
      : cli_(cli), backends_(backends), builder_(backends) {}
  ~Daemon() {
    if (adapter_)
      adapter_->stopNetwork();
  }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  int run();

 private:
  // 1. the configuration (exit code when it is bad)
  std::optional<int> configure();
  // --check-config: the start-up steps run() takes that change nothing outside this process
  // (process and servo-thread real-time setup, the scene and its simulation, the device spec
  // and, for sim and replay, the device itself, the network settings), each refused as run()
  // refuses it. Exit code as run()'s.
  int checkConfig();
  // 2-7: signals, real-time setup, scene, device, loop, record writer, shm and network, in
  // order; an exit code when a step fails
  std::optional<int> start(sigset_t& signals);
  // 8: the servo thread (its real-time setup, then the loop); an exit code when it fails
  std::optional<int> startServo();
  // 9: the main thread's service loop, until the servo loop ends
  void serve(const sigset_t& signals);
  void serviceOnce(ServiceTimers& timers, bool stopping);
  // 10: reverse teardown; the exit code
  int teardown();

  // [servo] realtime, off with the virtual clock
  RealtimeOptions realtimeOptions() const;
  // the device's options: [device] with the sim hand's home at the held body's start pose
  device::DeviceOptions deviceOptions(const BuiltScene& built) const;
  // hands a built scene to the servo loop and tells the network side
  void install(BuiltScene built);
  // the running config's scene bytes for viewers, read when one asks (web thread)
  SceneBytes configSceneBytes() const {
    return [backends = &backends_, config = config_]() -> Result<std::vector<std::uint8_t>> {
      if (!backends->scene_bytes)
        return Error{"this daemon cannot send its scene"};
      return backends->scene_bytes(config);
    };
  }
  // SIGHUP: starts a reload on the builder (one build at a time)
  void startReload();
  // an upload waiting and the builder free: builds it
  void startUpload();
  // a build that ended: installs it or logs (and answers) its refusal
  void finishBuild();
  void finishReload(SceneBuilder::Finished f);
  void finishUpload(SceneBuilder::Finished f);
  void drainEvents();
  void writeStatus(const char* phase);

  const CommandLine& cli_;
  const Backends& backends_;
  Config config_;
  std::unique_ptr<Clock> clock_;
  std::unique_ptr<device::Device> device_;
  std::unique_ptr<ServoLoop> loop_;
  std::unique_ptr<ProtocolAdapter> adapter_;
  std::unique_ptr<RecordWriter> writer_;
  SceneBuilder builder_;
  std::string scene_name_;
  std::uint64_t generation_ = 0;
  ServoSetup setup_;
  RealtimeOptions rt_;
  RealtimeReport process_rt_;
  std::string last_reload_ = "none";
  Thread servo_thread_;
  std::atomic<int> go_{0};  // servo thread: 1 run the loop, 2 end without running it
  std::atomic<bool> servo_done_{false};
  std::atomic<int> exit_reason_{-1};
};

RealtimeOptions Daemon::realtimeOptions() const {
  RealtimeOptions rt = toRealtimeOptions(config_);
  if (config_.servo.clock == ClockKind::kVirtual)
    rt.policy = RealtimePolicy::kOff;  // a FIFO thread that never sleeps starves the others
  return rt;
}

device::DeviceOptions Daemon::deviceOptions(const BuiltScene& built) const {
  device::DeviceOptions o = config_.device.options;
  if (built.model)
    if (auto home = sceneHome(config_, *built.model))
      o.sim_home = *home;
  return o;
}

void Daemon::install(BuiltScene built) {
  generation_ = built.scene->generation;
  scene_name_ = built.name;
  if (writer_)
    writer_->setBodyNames(generation_, std::move(built.body_names));
  auto model = std::move(built.model);
  // what the loader ignored, stood in for or parsed without simulating (the plan's notes)
  for (const std::string& note : model->plan.notes)
    logInfo("scene '" + built.name + "': " + note);
  if (!built.prewarm.empty())
    logInfo("scene '" + built.name + "': " + built.prewarm);
  loop_->offerScene(std::move(built.scene));
  // after the offer, so that a batch validated against this scene meets it at the servo
  adapter_->setScene(built.name, built.plan, std::move(model), generation_);
}

void Daemon::startReload() {
  if (builder_.busy()) {
    logWarning("SIGHUP: a reload is still being built; this one is ignored");
    return;
  }
  notifyReloading();
  logInfo("SIGHUP: reloading the configuration and the scene");
  if (auto started = builder_.startReload(cli_, config_, generation_ + 1); !started)
    logError("reload: " + started.error().message);
}

void Daemon::startUpload() {
  if (builder_.busy()) {
    // a build (SIGHUP or upload) runs: an upload that completes meanwhile is refused at once,
    // saying what the build is doing; the running scene stays until the build ends
    while (auto waiting = adapter_->takeUpload()) {
      const std::string why = "another scene is being built (" + builder_.progress() +
                              "); scene '" + scene_name_ +
                              "' runs until it is done: upload again then";
      logWarning("upload '" + waiting->name + "' refused: " + why);
      adapter_->finishUpload(waiting->ticket, false, why);
    }
    return;
  }
  auto up = adapter_->takeUpload();
  if (!up)
    return;
  logInfo("upload: building scene '" + up->name + "' (" + std::to_string(up->bytes.size()) +
          " bytes)");
  const std::uint64_t ticket = up->ticket;
  if (auto started = builder_.startUpload(std::move(*up), config_, generation_ + 1); !started) {
    logError("upload: " + started.error().message);
    adapter_->finishUpload(ticket, false, started.error().message);
  }
}

void Daemon::finishBuild() {
  auto f = builder_.finished();
  if (!f)
    return;
  if (f->upload)
    finishUpload(std::move(*f));
  else
    finishReload(std::move(*f));
}

void Daemon::finishUpload(SceneBuilder::Finished f) {
  const proto::SceneUploadDone& up = *f.upload;
  if (!f.built) {
    logError("upload '" + up.name + "' refused, keeping scene '" + scene_name_ + "': " + f.error);
    adapter_->finishUpload(up.ticket, false, f.error);
    return;
  }
  install(std::move(*f.built));
  auto glb = std::make_shared<const std::vector<std::uint8_t>>(std::move(f.upload->bytes));
  adapter_->setSceneBytes([glb]() -> Result<std::vector<std::uint8_t>> { return *glb; });
  last_reload_ =
      "ok: uploaded scene '" + scene_name_ + "' generation " + std::to_string(generation_);
  logInfo("upload: scene '" + scene_name_ + "' (generation " + std::to_string(generation_) +
          ") handed to the servo loop");
  adapter_->finishUpload(up.ticket, true, "");
}

void Daemon::finishReload(SceneBuilder::Finished f) {
  if (!f.built) {
    last_reload_ = "refused: " + f.error;
    logError("reload refused, keeping the running configuration and scene: " + f.error);
    notifyReady("running; last reload refused");
    return;
  }
  for (const auto& w : f.warnings)
    logWarning(w);
  if (const auto changed = changedKeys(config_, f.config, kRestartOnlySections); !changed.empty()) {
    std::string list;
    for (const auto& k : changed)
      list += (list.empty() ? "" : ", ") + k;
    logWarning(
        "reload: changes to [servo], [device], [network] and [web] take effect at restart (" +
        list + ")");
  }
  const Config running = config_;
  config_ = f.config;
  config_.servo = running.servo;
  config_.device = running.device;
  config_.network = running.network;
  config_.web = running.web;
  setLogLevel(config_.log.level);
  install(std::move(*f.built));
  adapter_->setSceneBytes(configSceneBytes());
  last_reload_ = "ok: scene '" + scene_name_ + "' generation " + std::to_string(generation_);
  logInfo("reload: scene '" + scene_name_ + "' (generation " + std::to_string(generation_) +
          ") handed to the servo loop");
  notifyReady("running; reloaded");
}

void Daemon::drainEvents() {
  ServoEvent e;
  while (loop_->popEvent(e)) {
    const bool bad =
        e.kind == ServoEventKind::kMissFault || e.kind == ServoEventKind::kNonFiniteForce ||
        e.kind == ServoEventKind::kStreamLost || e.kind == ServoEventKind::kDeviceLost ||
        e.kind == ServoEventKind::kRecordDropped || e.kind == ServoEventKind::kDeviceWriteFailed ||
        e.kind == ServoEventKind::kEditRefused || e.kind == ServoEventKind::kEditBatchDropped ||
        e.kind == ServoEventKind::kDeviceFault;
    logLine(bad ? LogLevel::kWarning : LogLevel::kInfo, describe(e));
  }
}

void Daemon::writeStatus(const char* phase) {
  if (cli_.status_file.empty())
    return;
  const ServoState st = loop_->state();
  const StatusFacts facts{.phase = phase,
                          .config = &config_,
                          .device = device::describeDevice(device_->info()),
                          .scene = scene_name_,
                          .offered_generation = generation_,
                          .memory_locked = process_rt_.memory_locked,
                          .servo_realtime = setup_.report,
                          .servo_scheduling = setup_.scheduling,
                          .last_reload = last_reload_,
                          .edits_pending = loop_->editsPending()};
  nlohmann::json j = statusJson(st, loop_->lateness(), loop_->compute(), facts);
  adapter_->addStatus(j, st);
  // what a SIGHUP reload or an upload being built is doing; "" when none runs
  j["loading"] = builder_.busy() ? builder_.progress() : std::string();
  j["pid"] = static_cast<long>(getpid());
  writeJsonFile(cli_.status_file, j);
}

std::optional<int> Daemon::configure() {
  auto config = buildConfig(cli_);
  if (!config) {
    logError(config.error().message);
    return kExitBadConfig;
  }
  config_ = config.value().config;
  setLogLevel(config_.log.level);
  for (const auto& w : config.value().warnings)
    logWarning(w);
  return std::nullopt;
}

int Daemon::checkConfig() {
  const RealtimeOptions rt = realtimeOptions();
  auto prt = setupProcessRealtime(rt, backends_.realtime);
  if (!prt) {
    logError(prt.error().message);
    return kExitFailure;
  }
  for (const auto& w : prt.value().warnings)
    logWarning(w);
  auto scene = buildScene(backends_, config_, 1);
  if (!scene) {
    logError("cannot load the scene: " + scene.error().message);
    return kExitFailure;
  }
  auto spec = device::parseDeviceSpec(config_.device.spec);
  if (!spec) {
    logError("device: " + spec.error().message);
    return kExitFailure;
  }
  if (spec.value().openIsHarmless()) {
    auto device = backends_.make_device(config_.device.spec, deviceOptions(scene.value()));
    if (!device) {
      logError("device: " + device.error().message);
      return kExitFailure;
    }
  }
  if (auto net = serverConfigOf(config_); !net) {
    logError(net.error().message);
    return kExitFailure;
  }
  if (!config_.web.listen.empty()) {
    if (auto web = webConfigOf(config_); !web) {
      logError(web.error().message);
      return kExitFailure;
    }
  }
  // the servo thread's setup, on a thread that ends at once
  Result<RealtimeReport> servo_rt = Error{"the servo thread did not start"};
  Thread servo;
  if (auto started =
          servo.start("hapticd-servo", 1 << 20,
                      [&] { servo_rt = setupServoThreadRealtime(rt, backends_.realtime); });
      !started) {
    logError(started.error().message);
    return kExitFailure;
  }
  servo.join();
  if (!servo_rt) {
    logError(servo_rt.error().message);
    return kExitFailure;
  }
  for (const auto& w : servo_rt.value().warnings)
    logWarning(w);
  std::printf("configuration ok%s: scene '%s', device '%s'\n",
              cli_.config_path ? (": " + *cli_.config_path).c_str() : " (built-in defaults)",
              scene.value().name.c_str(), config_.device.spec.c_str());
  return kExitOk;
}

std::optional<int> Daemon::start(sigset_t& signals) {
  const bool virtual_clock = config_.servo.clock == ClockKind::kVirtual;
  // 2. signals: blocked here so that every thread started below inherits the mask; the main
  // thread takes them with sigtimedwait()
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // 3. process real-time setup (memory locking), before any thread starts
  rt_ = realtimeOptions();
  if (virtual_clock && config_.servo.realtime != RealtimePolicy::kOff)
    logInfo("virtual clock: real-time scheduling and memory locking skipped");
  auto prt = setupProcessRealtime(rt_, backends_.realtime);
  if (!prt) {
    logError(prt.error().message);
    return kExitFailure;
  }
  process_rt_ = prt.value();
  for (const auto& w : process_rt_.warnings)
    logWarning(w);

  // 4. the scene and its simulation (handed to the loop below, before it starts); first, so that
  // the sim hand can start where the held body starts; then the device
  auto scene = buildScene(backends_, config_, 1);
  if (!scene) {
    logError("cannot load the scene: " + scene.error().message);
    return kExitFailure;
  }
  auto device = backends_.make_device(config_.device.spec, deviceOptions(scene.value()));
  if (!device) {
    logError("device: " + device.error().message);
    return kExitFailure;
  }
  device_ = std::move(device.value());
  logInfo("device: " + device::describeDevice(device_->info()));

  // 5. clock and servo loop (rings allocated here, before the loop starts)
  if (virtual_clock)
    clock_ = std::make_unique<VirtualClock>();
  else if (device_->ownsClock())
    clock_ = std::make_unique<DeviceClock>();  // the device's scheduler runs the ticks
  else
    clock_ = std::make_unique<MonotonicClock>();
  ServoOptions servo = toServoOptions(config_, device_->info());
  servo.record = !cli_.record.empty();
  servo.record_bodies = !cli_.record_bodies.empty();
  servo.wait_for_record_space = virtual_clock;
  servo.max_ticks = cli_.ticks;
  loop_ = std::make_unique<ServoLoop>(servo, *clock_, *device_, nullptr);
  adapter_ = std::make_unique<ProtocolAdapter>(*loop_);
  adapter_->setDevice(device::describeDevice(device_->info()));
  // scenes swapped in later are prewarmed at the device's pose (the loop's seqlock state)
  builder_.setDevicePose([loop = loop_.get()]() -> std::optional<geom::Pose> {
    const ServoState st = loop->state();
    if (st.tick == 0 || !st.device_connected)
      return std::nullopt;
    return st.X_W_device;
  });

  // 6. record writer (files opened now: a bad path fails start-up)
  if (servo.record || servo.record_bodies) {
    auto w = RecordWriter::open(*loop_, cli_.record, cli_.record_bodies);
    if (!w) {
      logError(w.error().message);
      return kExitFailure;
    }
    writer_ = std::move(w.value());
  }

  // 7. the scene built in step 4, handed over before the loop starts; shared memory, created
  // before the servo thread runs (its publish and command ring are the servo thread's from then
  // on); the network thread, whose commands go to the servo through the loop's command ring
  install(std::move(scene.value()));
  adapter_->setSceneBytes(configSceneBytes());
  logInfo("scene: '" + scene_name_ + "'");
  adapter_->startShm(config_.network.shm);
  if (auto net = adapter_->startNetwork(config_); !net) {
    logError(net.error().message);
    return kExitFailure;
  }
  if (auto web = adapter_->startWeb(config_); !web) {
    logError(web.error().message);
    return kExitFailure;
  }
  if (writer_) {
    if (auto started = writer_->start(); !started) {
      logError(started.error().message);
      return kExitFailure;
    }
  }
  return startServo();
}

std::optional<int> Daemon::startServo() {
  std::promise<ServoSetup> setup_promise;
  auto setup_future = setup_promise.get_future();
  auto started = servo_thread_.start("hapticd-servo", 1 << 20, [&] {
    ServoSetup s;
    auto r = setupServoThreadRealtime(rt_, backends_.realtime);
    s.ok = r.ok();
    if (r)
      s.report = r.value();
    else
      s.error = r.error().message;
    s.scheduling = describeThreadScheduling();
    loop_->prepareServoThread();  // the scene's per-thread scratch, before the loop starts
    setup_promise.set_value(std::move(s));
    while (go_.load(std::memory_order_acquire) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (go_.load() == 1) {
      exit_reason_ = static_cast<int>(loop_->run());
      // whatever ended the loop, the device is left at zero force
      device_->write(geom::Vec3(0.0), geom::Vec3(0.0));
    }
    servo_done_ = true;
  });
  if (!started) {
    logError(started.error().message);
    return kExitFailure;
  }
  setup_ = setup_future.get();
  if (!setup_.ok) {
    go_ = 2;
    servo_thread_.join();
    logError(setup_.error);
    if (writer_)
      (void)writer_->finish();
    return kExitFailure;
  }
  for (const auto& w : setup_.report.warnings)
    logWarning(w);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g Hz", config_.servo.rate_hz);
  logInfo("servo thread: " + setup_.scheduling + ", " + rate + ", clock " +
          toString(config_.servo.clock) +
          (process_rt_.memory_locked ? ", memory locked" : ", memory not locked"));
  go_ = 1;
  notifyReady("running: scene '" + scene_name_ + "', device " + device_->info().name);
  return std::nullopt;
}

void Daemon::serviceOnce(ServiceTimers& timers, bool stopping) {
  finishBuild();
  startUpload();
  adapter_->setLoading(builder_.busy() ? builder_.progress() : std::string());
  drainEvents();
  loop_->reclaimScenes();
  if (secondsSince(timers.service) >= config_.device.service_interval_s) {
    device_->service();
    timers.service = SteadyClock::now();
  }
  // the watchdog is fed only while the loop is healthy: it ticked since the last feed and is
  // not in a run of overruns as long as the one that latches the miss fault (a latched fault
  // after the loop recovered is a safe state, force zero until re-armed: the daemon stays up)
  const auto quarter =
      std::chrono::duration_cast<SteadyClock::duration>(timers.watchdog_interval / 4);
  if (timers.watchdog_interval.count() > 0 && SteadyClock::now() - timers.watchdog >= quarter) {
    const ServoState st = loop_->state();
    if (st.tick > timers.watchdog_tick && st.consecutive_misses < config_.servo.miss_fault_count)
      notifyWatchdog();
    timers.watchdog_tick = st.tick;
    timers.watchdog = SteadyClock::now();
  }
  if (secondsSince(timers.status_file) >= 0.5) {
    writeStatus(stopping ? "stopping" : "running");
    timers.status_file = SteadyClock::now();
  }
  if (config_.log.status_interval_s > 0.0 &&
      secondsSince(timers.status_line) >= config_.log.status_interval_s) {
    logInfo(statusLine(loop_->state(), loop_->lateness(), loop_->compute()));
    timers.status_line = SteadyClock::now();
  }
}

void Daemon::serve(const sigset_t& signals) {
  ServiceTimers timers;
  bool stopping = false;
  writeStatus("running");
  while (!servo_done_.load()) {
    timespec timeout{0, 20'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if ((sig == SIGTERM || sig == SIGINT) && !stopping) {
      stopping = true;
      logInfo(std::string(sig == SIGTERM ? "SIGTERM" : "SIGINT") + ": ramping the force to zero");
      notifyStopping();
      loop_->requestStop();
    } else if (sig == SIGHUP && !stopping) {
      startReload();
    }
    serviceOnce(timers, stopping);
  }
}

int Daemon::teardown() {
  // reverse order: network, reload builder, servo thread, writer, scenes, shm, device
  adapter_->stopNetwork();
  builder_.join();
  servo_thread_.join();
  drainEvents();
  loop_->reclaimScenes();
  int code = kExitOk;
  if (writer_) {
    if (auto done = writer_->finish(); !done) {
      logError(done.error().message);
      code = kExitFailure;
    }
  }
  const auto exit = static_cast<ServoExit>(exit_reason_.load());
  writeStatus("stopped");
  adapter_->closeShm();
  std::printf("%s\n", summaryLine(exit, loop_->state(), loop_->compute(), config_, scene_name_,
                                  writer_ ? writer_->rowsWritten() : 0)
                          .c_str());
  std::fflush(stdout);
  writer_.reset();
  adapter_.reset();
  loop_.reset();
  device_.reset();
  return code;
}

int Daemon::run() {
  // 1. configuration
  if (auto code = configure())
    return *code;
  if (cli_.print_config) {
    std::fputs(toToml(config_).c_str(), stdout);
    return kExitOk;
  }
  if (cli_.check_config)
    return checkConfig();
  sigset_t signals;
  if (auto code = start(signals))
    return *code;
  serve(signals);
  return teardown();
}

}  // namespace

int runDaemon(const CommandLine& cli, const Backends& backends) {
  Daemon daemon(cli, backends);
  return daemon.run();
}

}  // namespace hapticd::daemon
