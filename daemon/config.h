#pragma once
/// \file
/// The daemon's configuration: the structs below hold every value, and one table of keys
/// (daemon/config_keys.h: section, name, range, unit, text, and the field each key sets) is what
/// parsing, checking, `--print-config` and config/hapticd.toml all come from. A default is the
/// field's initializer, in the struct that uses it (device::DeviceOptions, sim::SimOptions,
/// scene::SceneLimits) or here: each key lives in one place.
///
/// Read with toml++; command-line options override the file. A bad value, a wrong type or an
/// unknown key is refused with the file, the line, the key and what is wrong; nothing of a refused
/// file is used. A deprecated key is read into the key that replaced it, with a warning naming it.
///
/// Threads: everything here runs on a normal thread (start-up, SIGHUP's builder), never on the
/// servo thread.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/result.h"
#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/device/device.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"
#include "daemon/workspace.h"

namespace hapticd::daemon {

enum class ClockKind : std::uint8_t { kMonotonic, kVirtual };
enum class LogLevel : std::uint8_t { kError, kWarning, kInfo, kDebug };

/// [servo]
struct ServoConfig {
  double rate_hz = 1000.0;
  RealtimePolicy realtime = RealtimePolicy::kPrefer;
  int priority = 80;
  int cpu = -1;
  std::uint32_t miss_fault_count = 10;
  double fault_fade_s = 0.05;
  double stop_ramp_s = 0.2;
  double ramp_in_s = 0.5;  ///< the force's ramp-in (the output stage: toServoOptions, toSimOptions)
  bool armed_at_start = true;
  ClockKind clock = ClockKind::kMonotonic;
  std::uint32_t stack_prefault_kib = 256;
  std::uint32_t record_ring_rows = 16384;
};

/// [device]: the backend's own options (device::DeviceOptions, every backend key) and what the
/// daemon does around the device.
struct DeviceConfig {
  std::string spec = "sim";
  device::DeviceOptions options;  ///< limits, sim hand, replay, hid, usb (defaults: device.h)
  double max_force_step_n = 0.5;
  double max_torque_step_nm = 0.05;
  /// The sim hand starts at the held body's start pose in the scene (mapped back through the
  /// workspace); false: at options.sim_home.
  bool sim_home_from_scene = true;
  WorkspaceMapping workspace;  ///< device to scene
  double service_interval_s = 0.1;
};

/// [response]: sim::SimOptions (every field a key reads; defaults: core/sim/simulation.h).
struct ResponseConfig {
  /// The response's time step; 0 follows [servo] rate_hz (sim.response.tick_s is set from this
  /// by toSimOptions()).
  double tick_s = 0.0;
  sim::SimOptions sim;
};

/// [scene]: what to load, scene::SceneLimits, where external URIs may be read from, and how
/// meshes that are not convex are decomposed (scene::DecompositionOptions) and cached.
struct SceneConfig {
  std::string path;  ///< empty: the built-in demo scene `demo`
  std::string demo = "peg_in_hole";
  scene::SceneLimits limits;
  std::string allowed_uri_dir;                                 ///< empty: external URIs refused
  double concavity = scene::DecompositionOptions{}.concavity;  ///< fraction of the diagonal
  std::uint32_t max_pieces = scene::DecompositionOptions{}.max_pieces;
  double decompose_time_limit_s = scene::DecompositionOptions{}.time_limit_s;  ///< 0: none
  /// The decomposition cache's folder: "auto" (scene::decompositionCacheDir()), "" (no cache), or
  /// an absolute path.
  std::string cache_dir = "auto";
  /// Most MiB of entries the cache keeps (least recently used removed first); 0: no limit.
  std::uint32_t cache_max_mb =
      static_cast<std::uint32_t>(scene::DecompositionOptions{}.cache_max_bytes >> 20);
};

/// [network]
struct NetworkConfig {
  std::string udp = "127.0.0.1:47100";        ///< the protocol server's address
  std::string key_file;                       ///< 64 hex digits; empty: no pre-shared key
  double rate_limit_packets_per_s = 20000.0;  ///< per peer, sustained; 0: unlimited
  double rate_limit_burst = 2000.0;           ///< per peer, datagrams
  std::int64_t max_datagram_bytes = 16384;    ///< larger datagrams are refused (512..65507)
  double max_state_rate_hz = 1000.0;          ///< subscribe rates are clamped to this
  /// Shared-memory segment for clients on this host (POSIX shm name, "/" then a name without
  /// "/"); empty: no shared memory. A segment that cannot be created is a warning: the daemon
  /// runs without it.
  std::string shm = "/hapticd";
};

/// [web]: the WebSocket JSON API and the viewer (daemon/web/, protocol/websocket.md)
struct WebConfig {
  std::string listen = "127.0.0.1:47180";  ///< HTTP and WebSocket address; empty: off
  /// Folder served on "/" (the viewer); empty: the install's share/hapticd/web next to the
  /// binary (BIN/../share/hapticd/web), else the source tree's web/ (a build tree's binary)
  std::string root;
  std::int64_t max_message_bytes = 16ll << 20;  ///< larger client messages are refused
};

/// [log]
struct LogConfig {
  LogLevel level = LogLevel::kInfo;
  double status_interval_s = 10.0;  ///< a status line this often; 0: never
};

struct Config {
  ServoConfig servo;
  DeviceConfig device;
  ResponseConfig response;
  SceneConfig scene;
  NetworkConfig network;
  WebConfig web;
  LogConfig log;
};

/// Every key of the table has the same value in both (fields no key reads are not compared).
bool operator==(const Config& a, const Config& b);

/// The keys ("section.key", table order) whose values differ between `a` and `b`, in the given
/// sections (all sections when empty).
std::vector<std::string> changedKeys(const Config& a,
                                     const Config& b,
                                     std::span<const std::string_view> sections = {});

/// A key that was renamed or moved: read into `section.name`'s place with a warning.
struct DeprecatedKey {
  const char* old_section;
  const char* old_name;
  const char* section;  ///< the key that replaced it
  const char* name;
};
/// The deprecated keys the daemon still reads.
std::span<const DeprecatedKey> deprecatedConfigKeys();

/// A parsed file: the config, the keys it set ("servo.rate_hz", ..., table order) and the
/// warnings (deprecated keys: "NAME:LINE: [old] key is deprecated: use [new] key").
struct ParsedConfig {
  Config config;
  std::vector<std::string> keys_set;
  std::vector<std::string> warnings;
};

/// Parses TOML text over the defaults. `name` names the source in messages. Error: one line per
/// problem, "NAME:LINE: [section] key: what is wrong", in line order.
Result<ParsedConfig> parseConfig(
    std::string_view text,
    const std::string& name,
    std::span<const DeprecatedKey> deprecated = deprecatedConfigKeys());
/// Reads and parses a file.
Result<ParsedConfig> loadConfigFile(const std::filesystem::path& path);

/// Every key the format knows, "section.key", in table (and file) order.
std::vector<std::string> knownConfigKeys();

/// Checks every value against its key's rules (after command-line overrides). Error: one line
/// per problem, "[section] key: what is wrong".
Result<bool> validateConfig(const Config& config);

/// The configuration as documented TOML: every key with its value, the key's text, range and
/// default in the comment above it. `toToml(Config{})` is config/hapticd.toml (a test holds
/// them equal; regenerate it with `hapticd --print-config > config/hapticd.toml`).
std::string toToml(const Config& config);

/// Derived option blocks.
sim::SimOptions toSimOptions(const Config& config);
/// (cache_dir through scene::decompositionCacheDir: "auto" reads the environment)
scene::LoadOptions toLoadOptions(const Config& config);
RealtimeOptions toRealtimeOptions(const Config& config);
/// The servo loop's options (record flags are the caller's).
ServoOptions toServoOptions(const Config& config, const device::DeviceInfo& device);

const char* toString(ClockKind kind);
const char* toString(LogLevel level);
Result<LogLevel> parseLogLevel(std::string_view text);
Result<ClockKind> parseClockKind(std::string_view text);
const char* toString(sim::ResponseOptions::HingeAttach attach);
Result<sim::ResponseOptions::HingeAttach> parseHingeAttach(std::string_view text);

}  // namespace hapticd::daemon
