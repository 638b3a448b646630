// hapticctl: the command-line client of hapticd: the offline `query` and `check` commands, and
// the commands that talk to a running daemon over the protocol (client/daemon_commands.h).
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <variant>

#include "client/check.h"
#include "client/daemon_commands.h"
#include "client/import.h"
#include "client/query.h"
#include "client/study.h"

namespace {

namespace hc = hapticd::client;

// A subcommand and the values its options fill.
template <class Options>
struct Command {
  CLI::App* app = nullptr;
  Options options;
  bool parsed() const { return app->parsed(); }
};

// What `check` takes besides its options: the file and --allowed-uri-dir.
struct CheckArgs {
  std::string file;
  std::string allowed_dir;
  std::string cache_dir = "auto";
  hc::CheckOptions options;
};

// hapticctl's subcommands. The daemon commands share one target (--host, --port, ...).
struct Commands {
  Command<std::string> query;  // FILE
  Command<CheckArgs> check;
  hc::DaemonTarget target;
  Command<hc::StatusOptions> status;
  Command<std::string> load;  // FILE
  Command<hc::PoseOptions> pose;
  std::vector<double> pose_values;  // PX PY PZ [QX QY QZ QW]
  Command<hc::ReplayOptions> replay;
  Command<hc::RecordOptions> record;
  Command<hc::WatchOptions> watch;
  Command<hc::SceneEditOptions> move, add, remove;  // one SceneEditOptions each
  std::vector<double> edit_values;                  // PX PY PZ [QX QY QZ QW] of move and add
  Command<std::monostate> arm, disarm;              // no options
  CLI::App* import = nullptr;                       // hapticctl import (client/import.h)
  hc::ImportOptions import_options;
  Command<hc::StudyOptions> study;  // hapticctl study (client/study.h)
  std::string study_cache_dir = "auto";
};

void defineOffline(CLI::App& app, Commands& c) {
  c.query.app = app.add_subcommand(
      "query",
      "Answer convex pair queries offline: one JSON object per line in FILE (- for stdin), "
      "one result per line out (docs/query.md)");
  c.query.app
      ->add_option("FILE", c.query.options, "JSON-lines file of queries, or - for standard input")
      ->required();
  c.check.app = app.add_subcommand(
      "check",
      "Validate a scene offline (.glb or .gltf): list its bodies, primitives and "
      "simulation plan, or every problem (exit 1); docs/scenes.md");
  CheckArgs& k = c.check.options;
  c.check.app->add_option("FILE", k.file, "scene file (.glb or .gltf)")->required();
  c.check.app->add_flag("--json", k.options.json, "print a machine-readable JSON report");
  c.check.app->add_option("--allowed-uri-dir", k.allowed_dir,
                          "folder external URIs may be read from (default: none, external URIs "
                          "refused)");
  c.check.app->add_option("--tessellation-tolerance", k.options.load.limits.tessellation_tolerance,
                          "curved shapes' tessellation tolerance, a fraction of their size "
                          "(default 1e-3)");
  // the decomposition of meshes that are not convex, as the daemon's [scene] keys
  c.check.app->add_option("--concavity", k.options.load.decomposition.concavity,
                          "decomposition target, a fraction of a mesh's diagonal in (0, 1); "
                          "extras.haptic.concavity on a node overrides it (default 0.01, as "
                          "[scene] concavity)");
  c.check.app->add_option("--max-pieces", k.options.load.decomposition.max_pieces,
                          "most convex pieces per decomposed mesh (default 64, as [scene] "
                          "max_pieces)");
  c.check.app->add_option("--time-limit", k.options.load.decomposition.time_limit_s,
                          "seconds one mesh's decomposition may take, 0: none (default 5, as "
                          "[scene] decompose_time_limit_s)");
  c.check.app->add_option("--cache-dir", k.cache_dir,
                          "decomposition cache folder: auto ($XDG_CACHE_HOME/hapticd or "
                          "~/.cache/hapticd), \"\" for none, or a folder (default auto, as "
                          "[scene] cache_dir)");
}

// hapticctl study (registered after the others: `hapticctl nosuch` lists the commands in order)
void defineStudy(CLI::App& app, Commands& c) {
  c.study.app = app.add_subcommand(
      "study",
      "The accuracy study on your scene: the real tick at its most accurate settings and at each "
      "setting that trades accuracy for time, tables, CSV and plots in --out, and the most "
      "accurate settings whose p99.9 tick fits the budget as a config snippet (docs/accuracy.md)");
  hc::StudyOptions& s = c.study.options;
  CLI::App* sub = c.study.app;
  sub->add_option("SCENE", s.scene, "scene file (.glb or .gltf)")->required();
  sub->add_option("STREAM", s.stream,
                  "pose stream CSV (t,px,py,pz,qx,qy,qz,qw,buttons); default: an approach stream "
                  "generated for the scene, written to OUT/stream.csv");
  sub->add_option("--budget-us", s.budget_us,
                  "p99.9 tick time the settings must fit, µs (default: one tick at --rate)");
  sub->add_option("--rate", s.rate_hz, "servo rate, Hz, [100, 20000] (default 1000)");
  sub->add_option("--out", s.out_dir,
                  "folder for tables.md, results.csv, the plot and recommended.toml (default "
                  "study-<scene name>)");
  sub->add_flag("--quick", s.quick, "at most 3 s of the stream (a generated one at half length)");
  sub->add_option("--time-limit", s.time_limit_s,
                  "refuse before starting when the estimate is longer, seconds; 0: none "
                  "(default 600)");
  sub->add_option("--cache-dir", c.study_cache_dir,
                  "decomposition cache folder, as check's --cache-dir (default auto)");
}

// the daemon commands: --host, --port, --key-file, --timeout-ms on each
template <class Options>
void daemonCommand(CLI::App& app,
                   Commands& c,
                   Command<Options>& cmd,
                   const char* name,
                   const char* help) {
  auto* sub = app.add_subcommand(name, help);
  sub->add_option("--host", c.target.host, "daemon address (default 127.0.0.1)");
  sub->add_option("--port", c.target.port, "daemon UDP port (default 47100)");
  sub->add_option("--key-file", c.target.key_file,
                  "pre-shared key file, 64 hex digits (default: none)");
  sub->add_option("--timeout-ms", c.target.timeout_ms,
                  "per request; no answer this long: no daemon (default 2000)");
  cmd.app = sub;
}

// --shm for the streaming commands: the shared-memory segment instead of UDP
void shmFlag(CLI::App* sub, Commands& c) {
  sub->add_flag("--shm{/hapticd}", c.target.shm_name,
                "use the daemon's shared memory instead of UDP: --shm is /hapticd, --shm=NAME "
                "another segment (default: off, UDP)");
}

void defineStreaming(CLI::App& app, Commands& c) {
  daemonCommand(app, c, c.pose, "pose",
                "Arm and stream one target pose to the sim device (scene frame, metres, glTF "
                "quaternion order)");
  CLI::App* pose = c.pose.app;
  shmFlag(pose, c);
  pose->add_option("VALUES", c.pose_values, "PX PY PZ [QX QY QZ QW]")->required()->expected(3, 7);
  pose->add_option("--seconds", c.pose.options.seconds,
                   "stream the pose this long, ≥ 0 (default 0.5; 0: once)");
  pose->add_option("--rate", c.pose.options.rate_hz, "stream rate, Hz, > 0 (default 200)");
  daemonCommand(app, c, c.replay, "replay",
                "Arm and send a pose stream CSV as pose commands, interpolated (lerp, slerp) at "
                "the send rate and timed by its t");
  CLI::App* replay = c.replay.app;
  hc::ReplayOptions& r = c.replay.options;
  replay->add_option("FILE", r.file, "t,px,py,pz,qx,qy,qz,qw,buttons")->required();
  replay->add_option("--rate", r.rate_hz,
                     "send rate, Hz, at most the daemon's tick rate (default 0: the tick rate)");
  replay->add_flag("--quiet", r.quiet,
                   "no progress lines on stderr (default: one a second for replays over 2 s)");
  shmFlag(replay, c);
  daemonCommand(app, c, c.record, "record", "Write the state stream as the daemon's --record CSV");
  CLI::App* record = c.record.app;
  record->add_option("OUT", c.record.options.file, "output CSV")->required();
  record->add_option("--seconds", c.record.options.seconds, "how long (default 1)");
  record->add_option("--rate", c.record.options.rate_hz,
                     "state rate, Hz (default 0: the daemon's tick rate, at most 1000)");
  record->add_option("--bodies", c.record.options.bodies_file,
                     "also write the body poses to this CSV, the daemon's --record-bodies columns "
                     "(tick,t,body,px..qw; at most 64 bodies a state, 16 over --shm)");
  record->add_option("--scene", c.record.options.scene_file,
                     "the scene file the daemon runs, for the bodies' names in --bodies (default: "
                     "body<index>)");
  shmFlag(record, c);
  daemonCommand(app, c, c.watch, "watch",
                "Live tick percentiles, force, contacts and faults, one line per state");
  CLI::App* watch = c.watch.app;
  hc::WatchOptions& w = c.watch.options;
  watch->add_option("--count", w.count, "stop after N lines (default 0: never)");
  watch->add_option("--rate", w.rate_hz, "lines per second (default 10)");
  watch->add_flag("--json", w.json, "one JSON object per line");
  watch->add_option("--deepest", w.deepest, "contacts listed per line, deepest first (default 3)");
  watch->add_flag("--bodies", w.bodies, "also the pose of every body the state lists");
  shmFlag(watch, c);
}

void defineControl(CLI::App& app, Commands& c) {
  daemonCommand(app, c, c.status, "status",
                "The daemon's device, scene, plan, tick figures, faults, force and contacts, and "
                "refusal counters");
  c.status.app->add_flag("--json", c.status.options.json, "print JSON");
  daemonCommand(app, c, c.load, "load",
                "Upload a scene (.glb) to the daemon: exit 0 accepted, 1 refused (the first error "
                "on stderr)");
  c.load.app->add_option("FILE", c.load.options, "scene file (.glb)")->required();
}

// scene edits (one SceneUpdate each), arm and disarm
void defineEdits(CLI::App& app, Commands& c) {
  daemonCommand(app, c, c.move, "move",
                "Set a kinematic body's pose (scene frame, metres, glTF quaternion order): exit 0 "
                "acknowledged, 1 refused");
  c.move.app
      ->add_option("BODY", c.move.options.body,
                   "body index in the scene (hapticctl check lists them)")
      ->required();
  c.move.app->add_option("POSE", c.edit_values, "PX PY PZ [QX QY QZ QW]")
      ->required()
      ->expected(3, 7);
  daemonCommand(app, c, c.add, "add",
                "Make an inactive body active at a pose: exit 0 acknowledged, 1 refused");
  c.add.app->add_option("BODY", c.add.options.body, "body index in the scene")->required();
  c.add.app->add_option("POSE", c.edit_values, "PX PY PZ [QX QY QZ QW]")
      ->required()
      ->expected(3, 7);
  daemonCommand(app, c, c.remove, "remove", "Make a body inactive: exit 0 acknowledged, 1 refused");
  c.remove.app->add_option("BODY", c.remove.options.body, "body index in the scene")->required();
  daemonCommand(app, c, c.arm, "arm", "Enable forces; clears a latched fault");
  daemonCommand(app, c, c.disarm, "disarm",
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

// move, add or remove: one scene update
int runSceneEdit(Commands& c) {
  using Kind = hc::SceneEditOptions::Kind;
  Command<hc::SceneEditOptions>& cmd = c.remove.parsed() ? c.remove
                                       : c.move.parsed() ? c.move
                                                         : c.add;
  cmd.options.kind = &cmd == &c.remove ? Kind::kRemove : &cmd == &c.move ? Kind::kMove : Kind::kAdd;
  if (cmd.options.kind != Kind::kRemove &&
      !takePose(c.edit_values, cmd.options,
                cmd.options.kind == Kind::kMove
                    ? "hapticctl move: give BODY PX PY PZ or BODY PX PY PZ QX QY QZ QW\n"
                    : "hapticctl add: give BODY PX PY PZ or BODY PX PY PZ QX QY QZ QW\n"))
    return 2;
  return hc::runSceneEdit(c.target, cmd.options, std::cout, std::cerr);
}

int runDaemonCommand(Commands& c) {
  const hc::DaemonTarget& t = c.target;
  if (c.status.parsed())
    return hc::runStatus(t, c.status.options, std::cout, std::cerr);
  if (c.load.parsed())
    return hc::runLoad(t, c.load.options, std::cout, std::cerr);
  if (c.arm.parsed())
    return hc::runArm(t, true, std::cout, std::cerr);
  if (c.disarm.parsed())
    return hc::runArm(t, false, std::cout, std::cerr);
  if (c.record.parsed())
    return hc::runRecord(t, c.record.options, std::cout, std::cerr);
  if (c.watch.parsed())
    return hc::runWatch(t, c.watch.options, std::cout, std::cerr);
  if (c.replay.parsed())
    return hc::runReplay(t, c.replay.options, std::cout, std::cerr);
  if (c.remove.parsed() || c.move.parsed() || c.add.parsed())
    return runSceneEdit(c);
  if (c.pose.parsed()) {
    if (!takePose(c.pose_values, c.pose.options,
                  "hapticctl pose: give PX PY PZ or PX PY PZ QX QY QZ QW\n"))
      return 2;
    return hc::runPose(t, c.pose.options, std::cout, std::cerr);
  }
  return -1;  // not a daemon command
}

int runOffline(Commands& c) {
  if (c.study.parsed()) {
    c.study.options.load.decomposition.cache_dir =
        hapticd::scene::decompositionCacheDir(c.study_cache_dir);
    return hc::runStudy(c.study.options, std::cout, std::cerr);
  }
  if (c.import->parsed())
    return hc::runImport(c.import_options, std::cout, std::cerr);
  if (c.check.parsed()) {
    CheckArgs& k = c.check.options;
    if (!k.allowed_dir.empty())
      k.options.load.allowed_uri_dir = k.allowed_dir;
    k.options.load.decomposition.cache_dir = hapticd::scene::decompositionCacheDir(k.cache_dir);
    return hc::runCheck(k.file, k.options, std::cout, std::cerr);
  }
  if (c.query.parsed()) {
    const std::string& file = c.query.options;
    if (file == "-")
      return hc::runQuery(std::cin, std::cout);
    std::ifstream in(file);
    if (!in) {
      std::cerr << "hapticctl query: cannot open " << file << ": " << std::strerror(errno) << '\n';
      return 1;
    }
    return hc::runQuery(in, std::cout);
  }
  return 0;
}

// Parses the command line: nullopt to run, or the exit code (0 after --help; 2 for a bad command
// line, the problem on stderr: an unknown command by its name, else CLI11's message).
std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "hapticctl: unknown command '" << argv[1] << "' (the commands: " << names
                << "; hapticctl --help says more)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // CLI11's own codes for a refusal are 100 and up
  }
  return std::nullopt;
}

}  // namespace

namespace {
int run(int argc, char** argv) {
  CLI::App app{"hapticctl: the command-line client of the hapticd haptic server"};
  app.require_subcommand(1);
  Commands c;
  defineOffline(app, c);
  defineControl(app, c);
  defineStreaming(app, c);
  defineEdits(app, c);
  c.import = hc::defineImport(app, c.import_options);
  defineStudy(app, c);
  if (const auto rc = parse(app, argc, argv))
    return *rc;
  if (const int rc = runDaemonCommand(c); rc >= 0)
    return rc;
  return runOffline(c);
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // a bug: every expected failure is reported where it happens
    std::fprintf(stderr, "hapticctl: unexpected error: %s\n", e.what());
    return 1;
  }
}
