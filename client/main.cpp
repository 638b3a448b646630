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
  // --shm for the streaming commands: the shared-memory segment instead of UDP
  auto shmFlag = [&](CLI::App* sub) {
    sub->add_flag("--shm{/hapticd}", target.shm_name,
                  "use the daemon's shared memory instead of UDP: --shm is /hapticd, --shm=NAME "
                  "another segment (default: off, UDP)");
  };
  auto* pose = daemonCommand("pose", "Arm and stream one target pose to the sim device (scene "
                                     "frame, metres, glTF quaternion order)");
  shmFlag(pose);
  pose->add_option("VALUES", pose_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  pose->add_option("--seconds", pose_options.seconds, "stream the pose this long (default 0.5)");
  pose->add_option("--rate", pose_options.rate_hz, "stream rate, Hz (default 200)");
  hc::ReplayOptions replay_options;
  auto* replay = daemonCommand("replay",
                               "Arm and send a pose stream CSV as pose commands, "
                               "interpolated (lerp, slerp) at the send rate and timed "
                               "by its t");
  replay->add_option("FILE", replay_options.file, "t,px,py,pz,qx,qy,qz,qw,buttons")->required();
  replay->add_option("--rate", replay_options.rate_hz,
                     "send rate, Hz, at most the daemon's tick rate (default 0: the tick rate)");
  replay->add_flag("--quiet", replay_options.quiet,
                   "no progress lines on stderr (default: one a second for replays over 2 s)");
  shmFlag(replay);
  hc::RecordOptions record_options;
  auto* record = daemonCommand("record", "Write the state stream as the daemon's --record CSV");
  record->add_option("OUT", record_options.file, "output CSV")->required();
  record->add_option("--seconds", record_options.seconds, "how long (default 1)");
  record->add_option("--rate", record_options.rate_hz,
                     "state rate, Hz (default 0: the daemon's tick rate, at most 1000)");
  shmFlag(record);
  hc::WatchOptions watch_options;
  auto* watch = daemonCommand("watch", "Live tick percentiles, force, contacts and faults, one "
                                       "line per state");
  watch->add_option("--count", watch_options.count, "stop after N lines (default 0: never)");
  watch->add_option("--rate", watch_options.rate_hz, "lines per second (default 10)");
  watch->add_flag("--json", watch_options.json, "one JSON object per line");
  watch->add_option("--deepest", watch_options.deepest,
                    "contacts listed per line, deepest first (default 3)");
  shmFlag(watch);
  // scene edits: one SceneUpdate each
  hc::SceneEditOptions edit_options;
  std::vector<double> edit_values;
  auto* move = daemonCommand("move",
                             "Set a kinematic body's pose (scene frame, metres, glTF "
                             "quaternion order): exit 0 acknowledged, 1 refused");
  move->add_option("BODY", edit_options.body,
                   "body index in the scene (hapticctl check lists them)")
      ->required();
  move->add_option("POSE", edit_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  auto* add = daemonCommand("add",
                            "Make an inactive body active at a pose: exit 0 "
                            "acknowledged, 1 refused");
  add->add_option("BODY", edit_options.body, "body index in the scene")->required();
  add->add_option("POSE", edit_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  auto* remove = daemonCommand("remove", "Make a body inactive: exit 0 acknowledged, 1 refused");
  remove->add_option("BODY", edit_options.body, "body index in the scene")->required();
  auto* arm = daemonCommand("arm", "Enable forces; clears a latched fault");
  auto* disarm = daemonCommand("disarm",
                               "Ramp the force to zero over [servo] stop_ramp_s (0.2 s by "
                               "default)");
  CLI11_PARSE(app, argc, argv);

  if (status->parsed()) return hc::runStatus(target, status_options, std::cout, std::cerr);
  if (load->parsed()) return hc::runLoad(target, load_file, std::cout, std::cerr);
  if (arm->parsed()) return hc::runArm(target, true, std::cout, std::cerr);
  if (disarm->parsed()) return hc::runArm(target, false, std::cout, std::cerr);
  if (record->parsed()) return hc::runRecord(target, record_options, std::cout, std::cerr);
  if (watch->parsed()) return hc::runWatch(target, watch_options, std::cout, std::cerr);
  if (replay->parsed()) return hc::runReplay(target, replay_options, std::cout, std::cerr);
  if (remove->parsed()) {
    edit_options.kind = hc::SceneEditOptions::Kind::kRemove;
    return hc::runSceneEdit(target, edit_options, std::cout, std::cerr);
  }
  if (move->parsed() || add->parsed()) {
    const char* verb = move->parsed() ? "move" : "add";
    if (edit_values.size() != 3 && edit_values.size() != 7) {
      std::cerr << "hapticctl " << verb << ": give BODY PX PY PZ or BODY PX PY PZ QX QY QZ QW\n";
      return 2;
    }
    edit_options.kind =
        move->parsed() ? hc::SceneEditOptions::Kind::kMove : hc::SceneEditOptions::Kind::kAdd;
    edit_options.px = edit_values[0];
    edit_options.py = edit_values[1];
    edit_options.pz = edit_values[2];
    if (edit_values.size() == 7) {
      edit_options.qx = edit_values[3];
      edit_options.qy = edit_values[4];
      edit_options.qz = edit_values[5];
      edit_options.qw = edit_values[6];
    }
    return hc::runSceneEdit(target, edit_options, std::cout, std::cerr);
  }
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
