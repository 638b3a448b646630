// hapticctl: the command-line client of hapticd: the offline `query` and `check` commands, and
// the commands that talk to a running daemon over the protocol (client/daemon_commands.h).
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include "client/check.h"
#include "client/daemon_commands.h"
#include "client/import.h"
#include "client/query.h"

namespace {

namespace hc = hapticd::client;

// Every subcommand and the values its options fill.
struct Commands {
  CLI::App* query = nullptr;
  std::string query_file;
  CLI::App* check = nullptr;
  std::string scene_file;
  hc::CheckOptions check_options;
  std::string allowed_dir;

  hc::DaemonTarget target;
  CLI::App* status = nullptr;
  hc::StatusOptions status_options;
  CLI::App* load = nullptr;
  std::string load_file;
  CLI::App* pose = nullptr;
  hc::PoseOptions pose_options;
  std::vector<double> pose_values;
  CLI::App* replay = nullptr;
  hc::ReplayOptions replay_options;
  CLI::App* record = nullptr;
  hc::RecordOptions record_options;
  CLI::App* watch = nullptr;
  hc::WatchOptions watch_options;
  CLI::App* move = nullptr;
  CLI::App* add = nullptr;
  CLI::App* remove = nullptr;
  hc::SceneEditOptions edit_options;
  std::vector<double> edit_values;
  CLI::App* arm = nullptr;
  CLI::App* disarm = nullptr;
  CLI::App* import = nullptr;
  hc::ImportOptions import_options;
};

void defineOffline(CLI::App& app, Commands& c) {
  c.query = app.add_subcommand(
      "query",
      "Answer convex pair queries offline: one JSON object per line in FILE (- for stdin), "
      "one result per line out (docs/query.md)");
  c.query->add_option("FILE", c.query_file, "JSON-lines file of queries, or - for standard input")
      ->required();
  c.check = app.add_subcommand(
      "check",
      "Validate a scene offline (.glb or .gltf): list its bodies, primitives and "
      "simulation plan, or every problem (exit 1); docs/scenes.md");
  c.check->add_option("FILE", c.scene_file, "scene file (.glb or .gltf)")->required();
  c.check->add_flag("--json", c.check_options.json, "print a machine-readable JSON report");
  c.check->add_option("--allowed-uri-dir", c.allowed_dir,
                      "folder external URIs may be read from (default: none, external URIs "
                      "refused)");
  c.check->add_option("--tessellation-tolerance",
                      c.check_options.load.limits.tessellation_tolerance,
                      "curved shapes' tessellation tolerance, a fraction of their size (default "
                      "1e-3)");
}

// the daemon commands: --host, --port, --key-file, --timeout-ms on each
CLI::App* daemonCommand(CLI::App& app, Commands& c, const char* name, const char* help) {
  auto* sub = app.add_subcommand(name, help);
  sub->add_option("--host", c.target.host, "daemon address (default 127.0.0.1)");
  sub->add_option("--port", c.target.port, "daemon UDP port (default 47100)");
  sub->add_option("--key-file", c.target.key_file,
                  "pre-shared key file, 64 hex digits (default: none)");
  sub->add_option("--timeout-ms", c.target.timeout_ms,
                  "per request; no answer this long: no daemon (default 2000)");
  return sub;
}

// --shm for the streaming commands: the shared-memory segment instead of UDP
void shmFlag(CLI::App* sub, Commands& c) {
  sub->add_flag("--shm{/hapticd}", c.target.shm_name,
                "use the daemon's shared memory instead of UDP: --shm is /hapticd, --shm=NAME "
                "another segment (default: off, UDP)");
}

void defineStreaming(CLI::App& app, Commands& c) {
  c.pose = daemonCommand(app, c, "pose",
                         "Arm and stream one target pose to the sim device (scene frame, metres, "
                         "glTF quaternion order)");
  shmFlag(c.pose, c);
  c.pose->add_option("VALUES", c.pose_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  c.pose->add_option("--seconds", c.pose_options.seconds,
                     "stream the pose this long (default 0.5)");
  c.pose->add_option("--rate", c.pose_options.rate_hz, "stream rate, Hz (default 200)");
  c.replay = daemonCommand(app, c, "replay",
                           "Arm and send a pose stream CSV as pose commands, "
                           "interpolated (lerp, slerp) at the send rate and timed "
                           "by its t");
  c.replay->add_option("FILE", c.replay_options.file, "t,px,py,pz,qx,qy,qz,qw,buttons")->required();
  c.replay->add_option("--rate", c.replay_options.rate_hz,
                       "send rate, Hz, at most the daemon's tick rate (default 0: the tick rate)");
  c.replay->add_flag("--quiet", c.replay_options.quiet,
                     "no progress lines on stderr (default: one a second for replays over 2 s)");
  shmFlag(c.replay, c);
  c.record = daemonCommand(app, c, "record", "Write the state stream as the daemon's --record CSV");
  c.record->add_option("OUT", c.record_options.file, "output CSV")->required();
  c.record->add_option("--seconds", c.record_options.seconds, "how long (default 1)");
  c.record->add_option("--rate", c.record_options.rate_hz,
                       "state rate, Hz (default 0: the daemon's tick rate, at most 1000)");
  shmFlag(c.record, c);
  c.watch = daemonCommand(app, c, "watch",
                          "Live tick percentiles, force, contacts and faults, one line per state");
  c.watch->add_option("--count", c.watch_options.count, "stop after N lines (default 0: never)");
  c.watch->add_option("--rate", c.watch_options.rate_hz, "lines per second (default 10)");
  c.watch->add_flag("--json", c.watch_options.json, "one JSON object per line");
  c.watch->add_option("--deepest", c.watch_options.deepest,
                      "contacts listed per line, deepest first (default 3)");
  shmFlag(c.watch, c);
}

void defineControl(CLI::App& app, Commands& c) {
  c.status = daemonCommand(app, c, "status",
                           "The daemon's device, scene, plan, tick figures, faults and refusal "
                           "counters");
  c.status->add_flag("--json", c.status_options.json, "print JSON");
  c.load = daemonCommand(app, c, "load",
                         "Upload a scene (.glb) to the daemon: exit 0 accepted, 1 refused (the "
                         "first error on stderr)");
  c.load->add_option("FILE", c.load_file, "scene file (.glb)")->required();
}

// scene edits (one SceneUpdate each), arm and disarm
void defineEdits(CLI::App& app, Commands& c) {
  c.move = daemonCommand(app, c, "move",
                         "Set a kinematic body's pose (scene frame, metres, glTF "
                         "quaternion order): exit 0 acknowledged, 1 refused");
  c.move
      ->add_option("BODY", c.edit_options.body,
                   "body index in the scene (hapticctl check lists them)")
      ->required();
  c.move->add_option("POSE", c.edit_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  c.add = daemonCommand(app, c, "add",
                        "Make an inactive body active at a pose: exit 0 acknowledged, 1 refused");
  c.add->add_option("BODY", c.edit_options.body, "body index in the scene")->required();
  c.add->add_option("POSE", c.edit_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  c.remove =
      daemonCommand(app, c, "remove", "Make a body inactive: exit 0 acknowledged, 1 refused");
  c.remove->add_option("BODY", c.edit_options.body, "body index in the scene")->required();
  c.arm = daemonCommand(app, c, "arm", "Enable forces; clears a latched fault");
  c.disarm = daemonCommand(app, c, "disarm",
                           "Ramp the force to zero over [servo] stop_ramp_s (0.2 s by default)");
}

// PX PY PZ [QX QY QZ QW] into o's px .. qw; false (with `usage` on stderr) for another count
template <class Options>
bool takePose(const std::vector<double>& v, Options& o, const char* usage) {
  if (v.size() != 3 && v.size() != 7) {
    std::cerr << usage;
    return false;
  }
  o.px = v[0];
  o.py = v[1];
  o.pz = v[2];
  if (v.size() == 7) {
    o.qx = v[3];
    o.qy = v[4];
    o.qz = v[5];
    o.qw = v[6];
  }
  return true;
}

int runDaemonCommand(Commands& c) {
  const hc::DaemonTarget& t = c.target;
  if (c.status->parsed())
    return hc::runStatus(t, c.status_options, std::cout, std::cerr);
  if (c.load->parsed())
    return hc::runLoad(t, c.load_file, std::cout, std::cerr);
  if (c.arm->parsed())
    return hc::runArm(t, true, std::cout, std::cerr);
  if (c.disarm->parsed())
    return hc::runArm(t, false, std::cout, std::cerr);
  if (c.record->parsed())
    return hc::runRecord(t, c.record_options, std::cout, std::cerr);
  if (c.watch->parsed())
    return hc::runWatch(t, c.watch_options, std::cout, std::cerr);
  if (c.replay->parsed())
    return hc::runReplay(t, c.replay_options, std::cout, std::cerr);
  if (c.remove->parsed()) {
    c.edit_options.kind = hc::SceneEditOptions::Kind::kRemove;
    return hc::runSceneEdit(t, c.edit_options, std::cout, std::cerr);
  }
  if (c.move->parsed() || c.add->parsed()) {
    const bool move = c.move->parsed();
    if (!takePose(c.edit_values, c.edit_options,
                  move ? "hapticctl move: give BODY PX PY PZ or BODY PX PY PZ QX QY QZ QW\n"
                       : "hapticctl add: give BODY PX PY PZ or BODY PX PY PZ QX QY QZ QW\n"))
      return 2;
    c.edit_options.kind =
        move ? hc::SceneEditOptions::Kind::kMove : hc::SceneEditOptions::Kind::kAdd;
    return hc::runSceneEdit(t, c.edit_options, std::cout, std::cerr);
  }
  if (c.pose->parsed()) {
    if (!takePose(c.pose_values, c.pose_options,
                  "hapticctl pose: give PX PY PZ or PX PY PZ QX QY QZ QW\n"))
      return 2;
    return hc::runPose(t, c.pose_options, std::cout, std::cerr);
  }
  return -1;  // not a daemon command
}

int runOffline(Commands& c) {
  if (c.import->parsed())
    return hc::runImport(c.import_options, std::cout, std::cerr);
  if (c.check->parsed()) {
    if (!c.allowed_dir.empty())
      c.check_options.load.allowed_uri_dir = c.allowed_dir;
    return hc::runCheck(c.scene_file, c.check_options, std::cout, std::cerr);
  }
  if (c.query->parsed()) {
    if (c.query_file == "-")
      return hc::runQuery(std::cin, std::cout);
    std::ifstream in(c.query_file);
    if (!in) {
      std::cerr << "hapticctl query: cannot open " << c.query_file << ": " << std::strerror(errno)
                << '\n';
      return 1;
    }
    return hc::runQuery(in, std::cout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hapticctl: the command-line client of the hapticd haptic server"};
  app.require_subcommand(1);
  Commands c;
  defineOffline(app, c);
  defineControl(app, c);
  defineStreaming(app, c);
  defineEdits(app, c);
  c.import = hc::defineImport(app, c.import_options);
  CLI11_PARSE(app, argc, argv);
  if (const int rc = runDaemonCommand(c); rc >= 0)
    return rc;
  return runOffline(c);
}
