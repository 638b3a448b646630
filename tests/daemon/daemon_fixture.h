#pragma once
// What the daemon's integration tests share (daemon_test and daemon_edit_test run runDaemon() in
// this process; binary_test and net_test run the real binaries): a scratch folder per test, the
// daemon's signals blocked, JSON status files read, bounded polls, child processes with their
// output in files, and the shared-memory stream-stop watch. Waits are bounded by counts of polls
// (a hang fails the test); no wall-clock duration is ever asserted.
#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "protocol/client.h"
#include "protocol/server.h"
#include "protocol/shm.h"

namespace hapticd::testing {

namespace fs = std::filesystem;

/// The whole file ("" when it cannot be read).
std::string slurp(const fs::path& p);
/// A JSON document (a file's text), or an empty object when it is missing or half written.
nlohmann::json parseJsonOrEmpty(const std::string& text);

/// A folder of its own for the running test: <tmp>/<prefix>_<pid>_<test name> (a "/" of a
/// parametrised name made "_"), emptied when made
/// and removed at the end.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

/// The running test's name.
std::string testName();

/// Blocks SIGTERM, SIGINT and SIGHUP in the calling thread: runDaemon() takes them with
/// sigtimedwait(), and the helper threads a test starts inherit the mask.
void blockDaemonSignals();

/// Polls `pred` up to `polls` times, `ms` apart; true as soon as it holds.
bool pollUntil(const std::function<bool()>& pred, int polls = 6000, int ms = 10);

/// The daemon's status file `file` parsed (an empty object while it is missing or half written).
nlohmann::json readStatus(const fs::path& file);
/// Waits (bounded by pollUntil's generous count of polls, never asserting a duration) until the
/// status file `file` holds a status for which `pred` holds.
bool waitForStatus(const fs::path& file, const std::function<bool(const nlohmann::json&)>& pred);

/// The pose of body `body` in a state's body list, or nullptr when it is not listed.
const proto::SceneUpdate::BodyPose* listedBody(const proto::State& s, std::uint32_t body);

/// How a child is started.
struct SpawnOptions {
  std::vector<std::string> extra_env;  ///< added to this process's environment
  void (*prepare)() = nullptr;         ///< runs in the child before exec (async-signal-safe)
};
/// Starts `argv` (argv[0] a path) with stdout and stderr into files and no signal blocked.
pid_t spawn(const std::vector<std::string>& argv,
            const fs::path& out,
            const fs::path& err,
            const SpawnOptions& options = {});
/// The child's exit code (128 + signal when killed by one), or -1 after killing a child that did
/// not end within limit_s (a hang).
int waitExit(pid_t pid, double limit_s);
/// True while the child runs (it has not exited; reaped here when it has, and false from then on).
bool running(pid_t pid);

/// Receives states until `pred` holds (true) or limit_s passes (false, a bound, not a timing);
/// `last`, when given, gets every state received.
bool receiveUntil(proto::Client& c,
                  const std::function<bool(const proto::State&)>& pred,
                  double limit_s = 30.0,
                  proto::State* last = nullptr);

/// A shm client whose stream stopped (its heartbeat goes on): reads the segment's state until the
/// gate latches stream_lost or `polls` ms pass; `st` is the last state read.
struct StreamStop {
  bool faulted = false;   ///< stream_lost latched
  bool saw_ramp = false;  ///< a state with the ramping flag and 0 < force scale < 1 on the way
};
StreamStop awaitStreamStop(proto::ShmClient& c, proto::ShmState& st, int polls = 30000);

}  // namespace hapticd::testing
