#pragma once
/// \file
/// The daemon's life (docs/architecture.md rule 15; chrony main.c): ordered init, the main
/// thread's service loop, and reverse teardown. main() only builds the Backends from the real
/// libraries and calls runDaemon(); tests call runDaemon() with fakes. The jobs around it live in
/// their own files: daemon/scene_builder.h (SIGHUP reloads and uploads, built off the servo
/// thread), daemon/protocol_adapter.h (the UDP server and the shared-memory segment),
/// daemon/status_report.h (the status file, status line and summary).
///
/// Threads (docs/daemon.md "Threads and how they meet"), all started by runDaemon():
///  - main (the caller): init and teardown, signals, servo events to the log, device service(),
///    scene reclaim, watchdog, status file;
///  - servo (`hapticd-servo`): its real-time setup, then ServoLoop::run() and nothing else;
///  - record (`hapticd-record`, with --record / --record-bodies): the record rows to the files;
///  - builder (`hapticd-build`, while a SIGHUP reload or an upload is built): the scene and its
///    simulation;
///  - network (`hapticd-net`): the protocol server on [network] udp.
/// Signals: SIGTERM and SIGINT ramp the force to zero over [servo] stop_ramp_s and end (exit 0);
/// SIGHUP reloads the config file and the scene, keeping the old ones when the new are bad (the
/// error is logged).

#include "daemon/backends.h"
#include "daemon/command_line.h"

namespace hapticd::daemon {

/// Exit codes of runDaemon().
enum ExitCode : int {
  kExitOk = 0,         ///< stopped by a signal or --ticks, or the replay stream ended
  kExitFailure = 1,    ///< a start-up step failed (device, scene, realtime "require", files)
  kExitBadConfig = 2,  ///< the configuration or the command line is bad
};

/// Runs the daemon until SIGTERM/SIGINT, the end of a replay stream or --ticks. Main thread.
/// Blocks SIGTERM, SIGINT and SIGHUP in the calling thread (and so in every thread it starts).
int runDaemon(const CommandLine& cli, const Backends& backends);

}  // namespace hapticd::daemon
