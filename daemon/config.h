#pragma once
/// \file
/// The daemon's configuration: config/hapticd.toml (every key listed there with its default; the
/// defaults below are the same values, and a test holds the two equal), read with toml++,
/// overridden by command-line options. A bad value, a wrong type or an unknown key is refused
/// with the file, the line, the key and what is wrong; nothing of a refused file is used.
///
/// Threads: everything here runs on the main thread (startup and SIGHUP), never on the servo
/// thread.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/result.h"
#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/device/device.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"

namespace hapticd::daemon {

enum class ClockKind : std::uint8_t { kMonotonic, kVirtual };

/// [servo]
struct ServoConfig {
  double rate_hz = 1000.0;
  RealtimePolicy realtime = RealtimePolicy::kPrefer;
  int priority = 80;
  int cpu = -1;
  std::uint32_t miss_fault_count = 10;
  double fault_fade_s = 0.05;
  double stop_ramp_s = 0.2;
  bool armed_at_start = true;
  ClockKind clock = ClockKind::kMonotonic;
  std::uint32_t stack_prefault_kib = 256;
  std::uint32_t record_ring_rows = 16384;
  bool operator==(const ServoConfig&) const = default;
};

/// [device]
struct DeviceConfig {
  std::string spec = "sim";
  double max_force_n = 10.0;
  double max_torque_nm = 1.0;
  double max_force_step_n = 0.5;
  double max_torque_step_nm = 0.05;
  double sim_hand_mass_kg = 0.5;
  double sim_hand_stiffness_n_per_m = 200.0;
  double sim_hand_damping_n_s_per_m = 20.0;
  double sim_idle_motion_after_s = 1.0;
  /// The sim hand starts at the held body's start pose in the scene (mapped back through the
  /// workspace); false: at sim_home_translation_m / sim_home_rotation.
  bool sim_home_from_scene = true;
  std::array<double, 3> sim_home_translation_m{0.0, 0.0, 0.0};
  std::array<double, 4> sim_home_rotation{0.0, 0.0, 0.0, 1.0};  ///< x, y, z, w
  std::array<double, 3> workspace_translation_m{0.0, 0.0, 0.0};
  std::array<double, 4> workspace_rotation{0.0, 0.0, 0.0, 1.0};  ///< x, y, z, w
  double workspace_scale = 1.0;
  double service_interval_s = 0.1;
  double sim_hand_inertia_kg_m2 = 0.001;
  double sim_hand_rot_stiffness_nm_per_rad = 1.0;
  double sim_hand_rot_damping_nm_s_per_rad = 0.06;
  double sim_idle_amplitude_m = 0.02;
  double sim_idle_angle_rad = 0.1;
  double sim_max_step_s = 0.001;
  double replay_quat_tolerance = 0.01;
  double hid_spacemouse_speed_m_per_s = 0.1;
  double hid_spacemouse_angular_speed_rad_per_s = 1.0;
  double hid_spacemouse_full_scale = 350.0;
  double hid_spacemouse_deadband = 8.0;
  double hid_spacemouse_workspace_m = 0.2;
  double usb_silence_lost_s = 0.1;
  int usb_falcon_max_motor_command = 4096;
  std::string usb_falcon_firmware;  ///< empty: never load firmware
  bool operator==(const DeviceConfig&) const = default;
};

/// [response]: sim::ResponseOptions and the rest of sim::SimOptions.
struct ResponseConfig {
  double stiffness_n_per_m = 600.0;
  double tick_s = 0.0;  ///< 0: follows [servo] rate_hz
  double max_force_n = 10.0;
  double max_torque_nm = 1.0;
  double max_force_step_n = 0.5;
  double max_torque_step_nm = 0.05;
  double ramp_s = 0.5;
  std::uint32_t max_pairs_per_tick = 0;
  double probe_sphere_radius_m = 0.01;
  double max_speed_m_per_s = 0.5;
  double speed_decay_s = 0.02;
  double min_predictive_fraction = 1e-3;
  double proxy_stiffness_ratio = 50.0;
  double coupling_damping_factor = 1.0;
  double rot_stiffness_nm_per_rad = 0.0;
  double penetration_allowance_m = 0.5e-3;
  double crease_angle_deg = 40.0;
  std::uint32_t attach_button_mask = 1u;
  double attach_distance_m = 1e-3;
  sim::ResponseOptions::HingeAttach hinge_attach = sim::ResponseOptions::HingeAttach::kAuto;
  double centre_radius_fraction = 0.3;
  bool grab_weight = true;
  bool grab_inertia = true;
  double grab_inertia_filter_s = 0.010;
  double dynamic_backstop_fraction = 0.5;
  double impulse_window_s = 0.020;
  double dynamics_sleep_time_s = 0.5;
  bool operator==(const ResponseConfig&) const = default;
};

/// [scene]: what to load, scene::SceneLimits, and where external URIs may be read from.
struct SceneConfig {
  std::string path;  ///< empty: the built-in demo scene `demo`
  std::string demo = "peg_in_hole";
  std::uint64_t max_file_bytes = 64ull << 20;
  std::uint32_t max_nodes = 10000;
  std::uint32_t max_bodies = 2000;
  std::uint32_t max_primitives = 10000;
  std::uint32_t max_hull_input_points = 100000;
  std::uint32_t max_hull_vertices = 4096;
  double tessellation_tolerance = 1e-3;
  std::string allowed_uri_dir;  ///< empty: external URIs refused
  bool operator==(const SceneConfig&) const = default;
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
  bool operator==(const NetworkConfig&) const = default;
};

enum class LogLevel : std::uint8_t { kError, kWarning, kInfo, kDebug };

/// [log]
struct LogConfig {
  LogLevel level = LogLevel::kInfo;
  double status_interval_s = 10.0;  ///< a status line this often; 0: never
  bool operator==(const LogConfig&) const = default;
};

struct Config {
  ServoConfig servo;
  DeviceConfig device;
  ResponseConfig response;
  SceneConfig scene;
  NetworkConfig network;
  LogConfig log;
  bool operator==(const Config&) const = default;
};

/// A parsed file: the config and the keys it set ("servo.rate_hz", ...).
struct ParsedConfig {
  Config config;
  std::vector<std::string> keys_set;
};

/// Parses TOML text over the defaults. `name` names the source in messages. Error: one line per
/// problem, "NAME:LINE: [section] key: what is wrong".
Result<ParsedConfig> parseConfig(std::string_view text, const std::string& name);
/// Reads and parses a file.
Result<ParsedConfig> loadConfigFile(const std::filesystem::path& path);

/// Every key the format knows, "section.key", in file order.
std::vector<std::string> knownConfigKeys();

/// Cross-field checks after command-line overrides (e.g. rate against tick_s). Error names keys.
Result<bool> validateConfig(const Config& config);

/// Derived option blocks.
sim::SimOptions toSimOptions(const Config& config);
device::DeviceOptions toDeviceOptions(const Config& config);
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
