// hapticctl: the command-line client of hapticd: the offline `query` and `check` commands, and
// the commands that talk to a running daemon over the protocol (client/daemon_commands.h).
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include "client/check.h"
#include "client/daemon_commands.h"
#include "client/query.h"

int main(int argc, char** argv) {
  CLI::App app{"hapticctl: the command-line client of the hapticd haptic server"};
  app.require_subcommand(1);
  std::string file;
  auto* query = app.add_subcommand(
      "query", "Answer convex pair queries offline: one JSON object per line in FILE (- for stdin), "
               "one result per line out (docs/query.md)");
  query->add_option("FILE", file, "JSON-lines file of queries, or - for standard input")->required();
  auto* check = app.add_subcommand(
      "check", "Validate a scene offline (.glb or .gltf): list its bodies, primitives and "
               "simulation plan, or every problem (exit 1); docs/scenes.md");
  std::string scene_file;
  hapticd::client::CheckOptions check_options;
  std::string allowed_dir;
  check->add_option("FILE", scene_file, "scene file (.glb or .gltf)")->required();
  check->add_flag("--json", check_options.json, "print a machine-readable JSON report");
  check->add_option("--allowed-uri-dir", allowed_dir,
                    "folder external URIs may be read from (default: none, external URIs refused)");
  check->add_option("--tessellation-tolerance", check_options.load.limits.tessellation_tolerance,
                    "curved shapes' tessellation tolerance, a fraction of their size (default 1e-3)");

  // the daemon commands: --host, --port, --key-file, --timeout-ms on each
  namespace hc = hapticd::client;
  hc::DaemonTarget target;
  auto daemonCommand = [&](const char* name, const char* help) {
    auto* sub = app.add_subcommand(name, help);
    sub->add_option("--host", target.host, "daemon address (default 127.0.0.1)");
    sub->add_option("--port", target.port, "daemon UDP port (default 47100)");
    sub->add_option("--key-file", target.key_file,
                    "pre-shared key file, 64 hex digits (default: none)");
    sub->add_option("--timeout-ms", target.timeout_ms,
                    "per request; no answer this long: no daemon (default 2000)");
    return sub;
  };
  hc::StatusOptions status_options;
  auto* status = daemonCommand("status", "The daemon's device, scene, plan, tick figures, faults "
                                         "and refusal counters");
  status->add_flag("--json", status_options.json, "print JSON");
  std::string load_file;
  auto* load = daemonCommand("load", "Upload a scene (.glb) to the daemon: exit 0 accepted, 1 "
                                     "refused (the first error on stderr)");
  load->add_option("FILE", load_file, "scene file (.glb)")->required();
  hc::PoseOptions pose_options;
  std::vector<double> pose_values;
  auto* pose = daemonCommand("pose", "Arm and stream one target pose to the sim device (scene "
                                     "frame, metres, glTF quaternion order)");
  pose->add_option("VALUES", pose_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  pose->add_option("--seconds", pose_options.seconds, "stream the pose this long (default 0.5)");
  pose->add_option("--rate", pose_options.rate_hz, "stream rate, Hz (default 200)");
  hc::ReplayOptions replay_options;
  auto* replay = daemonCommand("replay", "Arm and send a pose stream CSV as pose commands");
  replay->add_option("FILE", replay_options.file, "t,px,py,pz,qx,qy,qz,qw,buttons")->required();
  replay->add_option("--rate", replay_options.rate_hz,
                     "resample at this rate, Hz (default 0: rows at their own times)");
  hc::RecordOptions record_options;
  auto* record = daemonCommand("record", "Write the state stream as the daemon's --record CSV");
  record->add_option("OUT", record_options.file, "output CSV")->required();
  record->add_option("--seconds", record_options.seconds, "how long (default 1)");
  record->add_option("--rate", record_options.rate_hz, "state rate, Hz (default 1000)");
  hc::WatchOptions watch_options;
  auto* watch = daemonCommand("watch", "Live tick percentiles, force, contacts and faults, one "
                                       "line per state");
  watch->add_option("--count", watch_options.count, "stop after N lines (default 0: never)");
  watch->add_option("--rate", watch_options.rate_hz, "lines per second (default 10)");
  auto* arm = daemonCommand("arm", "Enable forces; clears a latched fault");
  auto* disarm = daemonCommand("disarm", "Force to zero now");
  CLI11_PARSE(app, argc, argv);

  if (status->parsed()) return hc::runStatus(target, status_options, std::cout, std::cerr);
  if (load->parsed()) return hc::runLoad(target, load_file, std::cout, std::cerr);
  if (arm->parsed()) return hc::runArm(target, true, std::cout, std::cerr);
  if (disarm->parsed()) return hc::runArm(target, false, std::cout, std::cerr);
  if (record->parsed()) return hc::runRecord(target, record_options, std::cout, std::cerr);
  if (watch->parsed()) return hc::runWatch(target, watch_options, std::cout, std::cerr);
  if (replay->parsed()) return hc::runReplay(target, replay_options, std::cout, std::cerr);
  if (pose->parsed()) {
    if (pose_values.size() != 3 && pose_values.size() != 7) {
      std::cerr << "hapticctl pose: give PX PY PZ or PX PY PZ QX QY QZ QW\n";
      return 2;
    }
    pose_options.px = pose_values[0];
    pose_options.py = pose_values[1];
    pose_options.pz = pose_values[2];
    if (pose_values.size() == 7) {
      pose_options.qx = pose_values[3];
      pose_options.qy = pose_values[4];
      pose_options.qz = pose_values[5];
      pose_options.qw = pose_values[6];
    }
    return hc::runPose(target, pose_options, std::cout, std::cerr);
  }

  if (check->parsed()) {
    if (!allowed_dir.empty()) check_options.load.allowed_uri_dir = allowed_dir;
    return hapticd::client::runCheck(scene_file, check_options, std::cout, std::cerr);
  }

  if (query->parsed()) {
    if (file == "-") return hapticd::client::runQuery(std::cin, std::cout);
    std::ifstream in(file);
    if (!in) {
      std::cerr << "hapticctl query: cannot open " << file << ": " << std::strerror(errno) << '\n';
      return 1;
    }
    return hapticd::client::runQuery(in, std::cout);
  }
  return 0;
}
