#include "daemon/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <utility>

namespace hapticd::daemon {

std::optional<int> parseCommandLine(int argc, char** argv, CommandLine& o) {
  CLI::App app{
      "hapticd: real-time 6-DOF haptic server. With no arguments it serves the sim device and the "
      "built-in demo scene (realtime \"prefer\"). Options override the config file. SIGTERM "
      "ramps the force to zero over [servo] stop_ramp_s and exits 0; a client's disarm ramps it "
      "to zero the same way (never at once: a sudden release makes the hand lurch); SIGHUP "
      "reloads the config and the scene.",
      "hapticd"};
  app.add_option("--config", o.config_path,
                 "config file (TOML; config/hapticd.toml lists every key with its default); "
                 "without it the built-in defaults apply");
  app.add_option("--scene", o.scene, "scene file .glb/.gltf ([scene] path; empty: built-in demo)");
  app.add_option("--demo", o.demo,
                 "built-in demo scene served when no scene file is given ([scene] demo)");
  app.add_option("--device", o.device,
                 "device: sim, replay:FILE.csv, hid, hid:PATH, usb, usb:falcon, "
                 "forcedimension[:INDEX], openhaptics[:NAME], haply[:ws://HOST:PORT] ([device] "
                 "spec)");
  app.add_option("--clock", o.clock,
                 "monotonic (real time) or virtual (ticks back to back) ([servo] clock)")
      ->check(CLI::IsMember({"monotonic", "virtual"}));
  app.add_option("--realtime", o.realtime, "require, prefer or off ([servo] realtime)")
      ->check(CLI::IsMember({"require", "prefer", "off"}));
  app.add_option("--rate", o.rate_hz, "servo rate in Hz ([servo] rate_hz)")
      ->check(CLI::Range(1.0, 20000.0));
  app.add_option("--priority", o.priority, "SCHED_FIFO priority 1..99 ([servo] priority)")
      ->check(CLI::Range(1, 99));
  app.add_option("--cpu", o.cpu, "CPU to pin the servo thread to, -1 none ([servo] cpu)")
      ->check(CLI::Range(-1, 1023));
  app.add_option("--udp", o.udp,
                 "UDP address ADDRESS:PORT, \"\" for none ([network] udp; with --clock virtual: "
                 "none unless given)");
  app.add_option("--shm", o.shm,
                 "shared-memory segment /NAME, \"\" for none ([network] shm; with --clock "
                 "virtual: none unless given)");
  app.add_option("--web", o.web,
                 "viewer and WebSocket API address ADDRESS:PORT, \"\" for none ([web] listen; with "
                 "--clock virtual: none unless given)");
  app.add_option("--log-level", o.log_level, "error, warning, info or debug ([log] level)")
      ->check(CLI::IsMember({"error", "warning", "info", "debug"}));
  app.add_option("--record", o.record,
                 "write one CSV row per tick (tick,t,dev_*,prx_*,fx..tz,contacts,max_penetration,"
                 "pairs_tested,pairs_skipped,tick_ns)");
  app.add_option("--record-bodies", o.record_bodies,
                 "write the pose of every non-static body per tick (tick,t,body,px..qw)");
  app.add_option("--status-file", o.status_file,
                 "write the status (JSON) to this file twice a second and at exit");
  app.add_option("--ticks", o.ticks,
                 "end after exactly this many ticks (the force is then set to zero); 0: no limit");
  app.add_flag("--check-config", o.check_config,
               "run the start-up checks and exit: the configuration, the scene and its "
               "simulation, the device (sim and replay opened, hid and usb by their spec), the "
               "network address and key file, real-time; 0 good, 2 bad configuration, 1 a "
               "start-up step refused");
  app.add_flag("--print-config", o.print_config,
               "print the effective configuration as documented TOML and exit (with no other "
               "option: config/hapticd.toml)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help: 0; any bad option or value: 2, as every other bad command line (CLI11's own codes
    // would be 105 and the like)
    return app.exit(e) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

namespace {

// a command-line override of a config value
template <class T>
void setIf(const std::optional<T>& value, T& out) {
  if (value)
    out = *value;
}
template <class E>
Result<bool> setChoice(const char* option,
                       const std::optional<std::string>& text,
                       Result<E> (*parse)(std::string_view),
                       E& out) {
  if (!text)
    return true;
  auto v = parse(*text);
  if (!v)
    return Error{std::string(option) + ": " + v.error().message};
  out = v.value();
  return true;
}

// A virtual-clock run (headless replay: ticks back to back on simulated time) serves no clients
// unless asked: [network] udp and shm and [web] listen are off unless the command line gives
// --udp / --shm / --web, or
// the config file that chose the virtual clock also sets the key. So a replay never competes
// with a running hapticd for its port or segment.
void virtualClockNetworkOff(const CommandLine& cli, ParsedConfig& parsed) {
  Config& c = parsed.config;
  if (c.servo.clock != ClockKind::kVirtual)
    return;
  const bool clock_from_file = !cli.clock;
  auto inFile = [&](const char* key) {
    return std::find(parsed.keys_set.begin(), parsed.keys_set.end(), key) != parsed.keys_set.end();
  };
  if (!cli.udp && !(clock_from_file && inFile("network.udp")))
    c.network.udp.clear();
  if (!cli.shm && !(clock_from_file && inFile("network.shm")))
    c.network.shm.clear();
  if (!cli.web && !(clock_from_file && inFile("web.listen")))
    c.web.listen.clear();
}

}  // namespace

Result<ParsedConfig> buildConfig(const CommandLine& cli) {
  ParsedConfig parsed;
  if (cli.config_path) {
    auto file = loadConfigFile(*cli.config_path);
    if (!file)
      return file.error();
    parsed = std::move(file.value());
  }
  Config& c = parsed.config;
  setIf(cli.scene, c.scene.path);
  setIf(cli.demo, c.scene.demo);
  setIf(cli.device, c.device.spec);
  setIf(cli.rate_hz, c.servo.rate_hz);
  setIf(cli.priority, c.servo.priority);
  setIf(cli.cpu, c.servo.cpu);
  setIf(cli.udp, c.network.udp);
  setIf(cli.shm, c.network.shm);
  setIf(cli.web, c.web.listen);
  for (const auto& r :
       {setChoice("--clock", cli.clock, &parseClockKind, c.servo.clock),
        setChoice("--realtime", cli.realtime, &parseRealtimePolicy, c.servo.realtime),
        setChoice("--log-level", cli.log_level, &parseLogLevel, c.log.level)})
    if (!r)
      return r.error();
  virtualClockNetworkOff(cli, parsed);
  if (auto v = validateConfig(c); !v)
    return v.error();
  return parsed;
}

}  // namespace hapticd::daemon
