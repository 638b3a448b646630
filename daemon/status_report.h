#pragma once
/// \file
/// What the daemon says about itself: the status file (--status-file, JSON, twice a second and
/// at exit), the status line logged every [log] status_interval_s, and the one-line summary
/// printed at exit. Faults by name (faultNames()), their bits in the protocol's numbering.
///
/// Threads: any normal thread (the main thread calls them); they allocate.

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "daemon/config.h"
#include "daemon/histogram.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"

namespace hapticd::daemon {

/// What the status file says besides the servo state and its histograms.
struct StatusFacts {
  const char* phase = "running";  ///< "running", "stopping", "stopped"
  const Config* config = nullptr;
  std::string device;
  std::string scene;
  std::uint64_t offered_generation = 0;  ///< the newest scene handed to the loop
  bool memory_locked = false;
  RealtimeReport servo_realtime;  ///< what the servo thread's setup achieved
  std::string servo_scheduling;   ///< describeThreadScheduling() on the servo thread
  std::string last_reload;
  std::size_t edits_pending = 0;
};

/// The status file's object (docs/daemon.md "Status"), without "shm" and "network"
/// (ProtocolAdapter::addStatus) and "pid".
nlohmann::json statusJson(const ServoState& st,
                          const DurationHistogram& lateness,
                          const DurationHistogram& compute,
                          const StatusFacts& facts);
/// Writes `j` to `path` through `path`.tmp and a rename, so that a reader never sees half a
/// file. A failure leaves the old file (the status is advisory).
void writeJsonFile(const std::string& path, const nlohmann::json& j);

/// "status: tick N, faults NAMES, overruns N, device connected, force F N; lateness ...;
/// compute ..."
std::string statusLine(const ServoState& st,
                       const DurationHistogram& lateness,
                       const DurationHistogram& compute);

/// The summary printed at exit: "hapticd: end of stream: N ticks, T s simulated time, scene
/// 'S', peak force ..., faults NAMES (latched K times: NAMES), records ..., tick p50 ...".
std::string summaryLine(ServoExit exit,
                        const ServoState& st,
                        const DurationHistogram& compute,
                        const Config& config,
                        const std::string& scene,
                        std::uint64_t records_written);

}  // namespace hapticd::daemon
