#pragma once
/// \file
/// hapticd's command line (CLI11). Options override the config file; `hapticd --help` lists them.
/// Main thread.

#include <cstdint>
#include <optional>
#include <string>

#include "core/common/result.h"
#include "daemon/config.h"

namespace hapticd::daemon {

struct CommandLine {
  std::optional<std::string> config_path;  ///< --config; absent: built-in defaults only
  std::optional<std::string> scene;        ///< --scene (overrides [scene] path)
  std::optional<std::string> demo;         ///< --demo (overrides [scene] demo)
  std::optional<std::string> device;       ///< --device (overrides [device] spec)
  std::optional<std::string> clock;        ///< --clock monotonic|virtual
  std::optional<std::string> realtime;     ///< --realtime require|prefer|off
  std::optional<double> rate_hz;           ///< --rate
  std::optional<int> priority;             ///< --priority
  std::optional<int> cpu;                  ///< --cpu
  std::optional<std::string> udp;          ///< --udp
  std::optional<std::string> shm;          ///< --shm ("" turns shared memory off)
  std::optional<std::string> log_level;    ///< --log-level
  std::string record;                      ///< --record FILE.csv
  std::string record_bodies;               ///< --record-bodies FILE.csv
  std::string status_file;                 ///< --status-file FILE.json
  std::uint64_t ticks = 0;                 ///< --ticks: stop after this many ticks (0: no limit)
  bool check_config = false;               ///< --check-config: validate and exit
  bool print_config = false;               ///< --print-config: the effective config as TOML
};

/// Parses argv. Returns an exit code when the process should end now (--help: 0, a bad option or
/// value: 2, the message already printed), or nullopt to run.
std::optional<int> parseCommandLine(int argc, char** argv, CommandLine& out);

/// The effective configuration: the file (when --config is given) over the defaults, then the
/// command-line overrides, then every value checked against its key (validateConfig). Error:
/// what and where; the result's warnings name deprecated keys the file used.
Result<ParsedConfig> buildConfig(const CommandLine& cli);

}  // namespace hapticd::daemon
