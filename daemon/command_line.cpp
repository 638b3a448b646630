#include "daemon/command_line.h"

#include <CLI/CLI.hpp>
#include <sstream>

namespace hapticd::daemon {

std::optional<int> parseCommandLine(int argc, char** argv, CommandLine& o) {
  CLI::App app{
      "hapticd: real-time 6-DOF haptic server. With no arguments it serves the sim device and the "
      "built-in demo scene (realtime \"prefer\"). Options override the config file.",
      "hapticd"};
  app.add_option("--config", o.config_path,
                 "config file (TOML; config/hapticd.toml lists every key with its default); "
                 "without it the built-in defaults apply");
  app.add_option("--scene", o.scene, "scene file .glb/.gltf ([scene] path; empty: built-in demo)");
  app.add_option("--demo", o.demo,
                 "built-in demo scene served when no scene file is given ([scene] demo)");
  app.add_option("--device", o.device,
                 "device: sim, replay:FILE.csv, hid, hid:PATH, usb, usb:falcon ([device] spec)");
  app.add_option("--clock", o.clock,
                 "monotonic (real time) or virtual (ticks back to back) ([servo] clock)")
      ->check(CLI::IsMember({"monotonic", "virtual"}));
  app.add_option("--realtime", o.realtime, "require, prefer or off ([servo] realtime)")
      ->check(CLI::IsMember({"require", "prefer", "off"}));
  app.add_option("--rate", o.rate_hz, "servo rate in Hz ([servo] rate_hz)")
      ->check(CLI::Range(1.0, 20000.0));
  app.add_option("--priority", o.priority, "SCHED_FIFO priority 1..99 ([servo] priority)")
      ->check(CLI::Range(1, 99));
  app.add_option("--cpu", o.cpu, "CPU to pin the servo thread to, -1 none ([servo] cpu)")
      ->check(CLI::Range(-1, 1023));
  app.add_option("--udp", o.udp, "UDP address ADDRESS:PORT ([network] udp)");
  app.add_option("--shm", o.shm, "shared-memory segment /NAME, \"\" for none ([network] shm)");
  app.add_option("--log-level", o.log_level, "error, warning, info or debug ([log] level)")
      ->check(CLI::IsMember({"error", "warning", "info", "debug"}));
  app.add_option("--record", o.record,
                 "write one CSV row per tick (tick,t,dev_*,prx_*,fx..tz,contacts,max_penetration,"
                 "pairs_tested,pairs_skipped,tick_ns)");
  app.add_option("--record-bodies", o.record_bodies,
                 "write the pose of every non-static body per tick (tick,t,body,px..qw)");
  app.add_option("--status-file", o.status_file,
                 "write the status (JSON) to this file twice a second and at exit");
  app.add_option("--ticks", o.ticks,
                 "end after exactly this many ticks (the force is then set to zero); 0: no limit");
  app.add_flag("--check-config", o.check_config,
               "check the configuration and exit (0 good, 2 bad)");
  app.add_flag("--print-config", o.print_config,
               "print the effective configuration as TOML and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is 0; any refusal is 2 (CLI11's own codes are 100 and up)
    return app.exit(e) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

Result<Config> buildConfig(const CommandLine& cli) {
  Config c;
  if (cli.config_path) {
    auto parsed = loadConfigFile(*cli.config_path);
    if (!parsed)
      return parsed.error();
    c = parsed.value().config;
  }
  if (cli.scene)
    c.scene.path = *cli.scene;
  if (cli.demo)
    c.scene.demo = *cli.demo;
  if (cli.device)
    c.device.spec = *cli.device;
  if (cli.clock) {
    auto k = parseClockKind(*cli.clock);
    if (!k)
      return Error{"--clock: " + k.error().message};
    c.servo.clock = k.value();
  }
  if (cli.realtime) {
    auto p = parseRealtimePolicy(*cli.realtime);
    if (!p)
      return Error{"--realtime: " + p.error().message};
    c.servo.realtime = p.value();
  }
  if (cli.rate_hz)
    c.servo.rate_hz = *cli.rate_hz;
  if (cli.priority)
    c.servo.priority = *cli.priority;
  if (cli.cpu)
    c.servo.cpu = *cli.cpu;
  if (cli.udp)
    c.network.udp = *cli.udp;
  if (cli.shm)
    c.network.shm = *cli.shm;
  if (cli.log_level) {
    auto l = parseLogLevel(*cli.log_level);
    if (!l)
      return Error{"--log-level: " + l.error().message};
    c.log.level = l.value();
  }
  if (auto v = validateConfig(c); !v)
    return v.error();
  return c;
}

namespace {
std::string q(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\')
      out += '\\';
    out += ch;
  }
  return out + "\"";
}
template <std::size_t N>
std::string arr(const std::array<double, N>& a) {
  std::ostringstream os;
  os.precision(17);
  os << "[";
  for (std::size_t i = 0; i < N; ++i)
    os << (i ? ", " : "") << a[i];
  os << "]";
  return os.str();
}
}  // namespace

std::string toToml(const Config& c) {
  std::ostringstream os;
  os.precision(17);
  os << "[servo]\nrate_hz = " << c.servo.rate_hz << "\nrealtime = " << q(toString(c.servo.realtime))
     << "\npriority = " << c.servo.priority << "\ncpu = " << c.servo.cpu
     << "\nmiss_fault_count = " << c.servo.miss_fault_count
     << "\nfault_fade_s = " << c.servo.fault_fade_s << "\nstop_ramp_s = " << c.servo.stop_ramp_s
     << "\narmed_at_start = " << (c.servo.armed_at_start ? "true" : "false")
     << "\nclock = " << q(toString(c.servo.clock))
     << "\nstack_prefault_kib = " << c.servo.stack_prefault_kib
     << "\nrecord_ring_rows = " << c.servo.record_ring_rows << "\n";
  const auto& d = c.device;
  os << "\n[device]\nspec = " << q(d.spec) << "\nmax_force_n = " << d.max_force_n
     << "\nmax_torque_nm = " << d.max_torque_nm << "\nmax_force_step_n = " << d.max_force_step_n
     << "\nmax_torque_step_nm = " << d.max_torque_step_nm
     << "\nsim_hand_mass_kg = " << d.sim_hand_mass_kg
     << "\nsim_hand_stiffness_n_per_m = " << d.sim_hand_stiffness_n_per_m
     << "\nsim_hand_damping_n_s_per_m = " << d.sim_hand_damping_n_s_per_m
     << "\nsim_idle_motion_after_s = " << d.sim_idle_motion_after_s
     << "\nsim_home_from_scene = " << (d.sim_home_from_scene ? "true" : "false")
     << "\nsim_home_translation_m = " << arr(d.sim_home_translation_m)
     << "\nsim_home_rotation = " << arr(d.sim_home_rotation)
     << "\nworkspace_translation_m = " << arr(d.workspace_translation_m)
     << "\nworkspace_rotation = " << arr(d.workspace_rotation)
     << "\nworkspace_scale = " << d.workspace_scale
     << "\nservice_interval_s = " << d.service_interval_s
     << "\nsim_hand_inertia_kg_m2 = " << d.sim_hand_inertia_kg_m2
     << "\nsim_hand_rot_stiffness_nm_per_rad = " << d.sim_hand_rot_stiffness_nm_per_rad
     << "\nsim_hand_rot_damping_nm_s_per_rad = " << d.sim_hand_rot_damping_nm_s_per_rad
     << "\nsim_idle_amplitude_m = " << d.sim_idle_amplitude_m
     << "\nsim_idle_angle_rad = " << d.sim_idle_angle_rad
     << "\nsim_max_step_s = " << d.sim_max_step_s
     << "\nreplay_quat_tolerance = " << d.replay_quat_tolerance
     << "\nhid_spacemouse_speed_m_per_s = " << d.hid_spacemouse_speed_m_per_s
     << "\nhid_spacemouse_angular_speed_rad_per_s = " << d.hid_spacemouse_angular_speed_rad_per_s
     << "\nhid_spacemouse_full_scale = " << d.hid_spacemouse_full_scale
     << "\nhid_spacemouse_deadband = " << d.hid_spacemouse_deadband
     << "\nhid_spacemouse_workspace_m = " << d.hid_spacemouse_workspace_m
     << "\nusb_silence_lost_s = " << d.usb_silence_lost_s
     << "\nusb_falcon_max_motor_command = " << d.usb_falcon_max_motor_command
     << "\nusb_falcon_firmware = " << q(d.usb_falcon_firmware) << "\n";
  const auto& r = c.response;
  os << "\n[response]\nstiffness_n_per_m = " << r.stiffness_n_per_m << "\ntick_s = " << r.tick_s
     << "\nmax_force_n = " << r.max_force_n << "\nmax_torque_nm = " << r.max_torque_nm
     << "\nmax_force_step_n = " << r.max_force_step_n
     << "\nmax_torque_step_nm = " << r.max_torque_step_nm << "\nramp_s = " << r.ramp_s
     << "\nmax_pairs_per_tick = " << r.max_pairs_per_tick
     << "\nprobe_sphere_radius_m = " << r.probe_sphere_radius_m
     << "\nmax_speed_m_per_s = " << r.max_speed_m_per_s << "\nspeed_decay_s = " << r.speed_decay_s
     << "\nmin_predictive_fraction = " << r.min_predictive_fraction
     << "\nproxy_stiffness_ratio = " << r.proxy_stiffness_ratio
     << "\ncoupling_damping_factor = " << r.coupling_damping_factor
     << "\nrot_stiffness_nm_per_rad = " << r.rot_stiffness_nm_per_rad
     << "\npenetration_allowance_m = " << r.penetration_allowance_m
     << "\ncrease_angle_deg = " << r.crease_angle_deg
     << "\nattach_button_mask = " << r.attach_button_mask
     << "\nattach_distance_m = " << r.attach_distance_m
     << "\nhinge_attach = " << q(toString(r.hinge_attach))
     << "\ncentre_radius_fraction = " << r.centre_radius_fraction
     << "\ngrab_weight = " << (r.grab_weight ? "true" : "false")
     << "\ngrab_inertia = " << (r.grab_inertia ? "true" : "false")
     << "\ngrab_inertia_filter_s = " << r.grab_inertia_filter_s
     << "\ndynamic_backstop_fraction = " << r.dynamic_backstop_fraction
     << "\nimpulse_window_s = " << r.impulse_window_s
     << "\ndynamics_sleep_time_s = " << r.dynamics_sleep_time_s << "\n";
  const auto& s = c.scene;
  os << "\n[scene]\npath = " << q(s.path) << "\ndemo = " << q(s.demo)
     << "\nmax_file_bytes = " << s.max_file_bytes << "\nmax_nodes = " << s.max_nodes
     << "\nmax_bodies = " << s.max_bodies << "\nmax_primitives = " << s.max_primitives
     << "\nmax_hull_input_points = " << s.max_hull_input_points
     << "\nmax_hull_vertices = " << s.max_hull_vertices
     << "\ntessellation_tolerance = " << s.tessellation_tolerance
     << "\nallowed_uri_dir = " << q(s.allowed_uri_dir) << "\n";
  os << "\n[network]\nudp = " << q(c.network.udp) << "\nkey_file = " << q(c.network.key_file)
     << "\nrate_limit_packets_per_s = " << c.network.rate_limit_packets_per_s
     << "\nrate_limit_burst = " << c.network.rate_limit_burst
     << "\nmax_datagram_bytes = " << c.network.max_datagram_bytes
     << "\nmax_state_rate_hz = " << c.network.max_state_rate_hz << "\nshm = " << q(c.network.shm)
     << "\n";
  os << "\n[log]\nlevel = " << q(toString(c.log.level))
     << "\nstatus_interval_s = " << c.log.status_interval_s << "\n";
  return os.str();
}

}  // namespace hapticd::daemon
