#include "daemon/config_keys.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>

#include "core/geometry/rotation.h"

namespace hapticd::daemon {
namespace {

// the field of Config a key sets
#define HAPTICD_FIELD(member) [](Config& c) -> FieldRef { return &c.member; }

constexpr Range closed(double lo, double hi) {
  return {lo, hi, false, false};
}
constexpr Range positive(double hi) {  // (0, hi]
  return {0.0, hi, true, false};
}
constexpr Range below(double lo, double hi) {  // [lo, hi)
  return {lo, hi, false, true};
}
constexpr Range kNoRange{};
constexpr double kCoordinateBound = 1e9;  // |element| of a configured translation, m

// "" (off) or "ADDRESS:PORT"
std::optional<std::string> checkUdp(const std::string& s) {
  if (s.empty())
    return std::nullopt;
  const auto colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0)
    return "must be \"ADDRESS:PORT\", or \"\" for no UDP (got \"" + s + "\")";
  const std::string port = s.substr(colon + 1);
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535)
    return "port must be 0..65535, 0 for any free port (got \"" + port + "\")";
  return std::nullopt;
}

// "" (off) or "/name" (POSIX shm_open: one leading slash, no other, at most NAME_MAX)
std::optional<std::string> checkShmName(const std::string& s) {
  if (s.empty())
    return std::nullopt;
  if (s.size() < 2 || s[0] != '/' || s.find('/', 1) != std::string::npos || s.size() > 255)
    return "must be empty (no shared memory) or \"/NAME\" with no other '/' (got \"" + s + "\")";
  return std::nullopt;
}

// "" (off) or what [network] udp accepts
std::optional<std::string> checkWebListen(const std::string& s) {
  if (s.empty())
    return std::nullopt;
  if (auto bad = checkUdp(s))
    return *bad + "; \"\" turns the web endpoint off";
  return std::nullopt;
}

std::optional<std::string> checkSpec(const std::string& s) {
  if (s.empty())
    return "must not be empty (\"sim\", \"replay:FILE\", \"hid\", \"usb\")";
  return std::nullopt;
}

std::optional<std::string> checkDemo(const std::string& s) {
  if (s.empty())
    return "must name a demo scene";
  return std::nullopt;
}

// "auto", "" (no cache) or an absolute folder
std::optional<std::string> checkCacheDir(const std::string& s) {
  if (s.empty() || s == "auto" || s.front() == '/')
    return std::nullopt;
  return "must be \"auto\", \"\" (no cache) or an absolute folder (got \"" + s + "\")";
}

const ConfigKey kKeys[] = {
    // [servo]
    {"servo", "rate_hz", HAPTICD_FIELD(servo.rate_hz), closed(1.0, 20000.0), "Hz",
     "Servo loop rate; the period is rounded to whole nanoseconds (4000 works). Restart to "
     "change."},
    {"servo", "realtime", HAPTICD_FIELD(servo.realtime), kNoRange, "",
     "Real-time policy: \"require\" refuses to start unless memory locking and SCHED_FIFO (and "
     "pinning, when cpu is set) are granted; \"prefer\" warns and runs without what is refused; "
     "\"off\" changes nothing (the servo thread runs at normal priority)."},
    {"servo", "priority", HAPTICD_FIELD(servo.priority), closed(1, 99), "",
     "SCHED_FIFO priority of the servo thread. Every other thread runs at normal priority."},
    {"servo", "cpu", HAPTICD_FIELD(servo.cpu), closed(-1, 1023), "",
     "CPU the servo thread is pinned to; -1 leaves it unpinned."},
    {"servo", "miss_fault_count", HAPTICD_FIELD(servo.miss_fault_count), closed(1, 1000000), "",
     "Consecutive ticks that overrun their period before a fault (tick_overrun) is latched: the "
     "force fades to zero and stays there until re-armed (hapticctl arm). Missed periods are "
     "skipped, never queued."},
    {"servo", "fault_fade_s", HAPTICD_FIELD(servo.fault_fade_s), closed(0.0, 10.0), "s",
     "Time over which the force fades to zero after a latched fault."},
    {"servo", "stop_ramp_s", HAPTICD_FIELD(servo.stop_ramp_s), closed(0.0, 10.0), "s",
     "Time over which the force ramps to zero on SIGTERM and on a client's disarm, for the "
     "user's safety (a sudden release of a 10 N force makes the hand lurch)."},
    {"servo", "ramp_in_s", HAPTICD_FIELD(servo.ramp_in_s), closed(0.0, 60.0), "s",
     "Time the force takes to ramp in from zero at start, after an arm and after the device "
     "comes back (0: at once)."},
    {"servo", "armed_at_start", HAPTICD_FIELD(servo.armed_at_start), kNoRange, "",
     "Forces are on from the start (true), or zero until an arm command (false)."},
    {"servo", "clock", HAPTICD_FIELD(servo.clock), kNoRange, "",
     "\"monotonic\": real time, clock_nanosleep(TIMER_ABSTIME) on CLOCK_MONOTONIC; \"virtual\": "
     "simulated time, ticks back to back (headless replay, CI)."},
    {"servo", "stack_prefault_kib", HAPTICD_FIELD(servo.stack_prefault_kib), closed(0, 8192), "KiB",
     "Stack the servo thread touches before its loop so that no page fault happens in a "
     "tick."},
    {"servo", "record_ring_rows", HAPTICD_FIELD(servo.record_ring_rows), closed(64, 1 << 24), "",
     "Rows the record ring holds between the servo thread and the record writer (--record); with "
     "the real clock a full ring drops rows (counted in the status), with the virtual clock the "
     "loop waits."},

    // [device]
    {"device", "spec", HAPTICD_FIELD(device.spec), kNoRange, "",
     "The device: \"sim\" (a simulated 6-DOF hand), \"replay:FILE\" (a pose stream CSV), "
     "\"hid\", \"hid:PATH\", \"usb\", \"usb:falcon\", \"forcedimension[:INDEX]\", "
     "\"openhaptics[:NAME]\", \"haply[:ws://HOST:PORT]\" (docs/devices.md).",
     &checkSpec},
    {"device", "max_force_n", HAPTICD_FIELD(device.options.limits.max_force_n), positive(1000.0),
     "N",
     "Largest force written to the device (the backend's own limit applies when lower); the "
     "simulation's pull on the proxy is clamped to it too."},
    {"device", "max_torque_nm", HAPTICD_FIELD(device.options.limits.max_torque_nm), positive(100.0),
     "N m", "Largest torque written to the device."},
    {"device", "max_force_step_n", HAPTICD_FIELD(device.max_force_step_n), positive(1000.0), "N",
     "F_max of paper section 5.3: largest change of the written force between two ticks."},
    {"device", "max_torque_step_nm", HAPTICD_FIELD(device.max_torque_step_nm), positive(100.0),
     "N m", "Largest change of the written torque between two ticks."},
    {"device", "sim_hand_mass_kg", HAPTICD_FIELD(device.options.sim_hand_mass_kg), positive(1000.0),
     "kg", "sim device: mass of the simulated hand."},
    {"device", "sim_hand_stiffness_n_per_m",
     HAPTICD_FIELD(device.options.sim_hand_stiffness_n_per_m), positive(1e7), "N/m",
     "sim device: spring pulling the hand toward the commanded pose."},
    {"device", "sim_hand_damping_n_s_per_m",
     HAPTICD_FIELD(device.options.sim_hand_damping_n_s_per_m), closed(0.0, 1e6), "N s/m",
     "sim device: damper of the hand."},
    {"device", "sim_idle_motion_after_s", HAPTICD_FIELD(device.options.sim_idle_motion_after_s),
     closed(0.0, 1e6), "s",
     "sim device: with no pose command for this long, a built-in gentle motion drives the "
     "hand."},
    {"device", "sim_home_from_scene", HAPTICD_FIELD(device.sim_home_from_scene), kNoRange, "",
     "sim device: the hand starts at the held body's start pose in the scene (through the "
     "inverse of the workspace mapping below), so that the gentle motion plays around it; "
     "false: at sim_home_translation_m and sim_home_rotation."},
    {"device", "sim_home_translation_m", HAPTICD_FIELD(device.options.sim_home.translation),
     closed(-kCoordinateBound, kCoordinateBound), "m",
     "sim device: start position of the hand when sim_home_from_scene is false."},
    {"device", "sim_home_rotation", HAPTICD_FIELD(device.options.sim_home.rotation), kNoRange, "",
     "sim device: start orientation of the hand when sim_home_from_scene is false."},
    {"device", "workspace_translation_m", HAPTICD_FIELD(device.workspace.X_SD.translation),
     closed(-kCoordinateBound, kCoordinateBound), "m",
     "Workspace mapping, device to scene: position of the device frame in the scene. A device "
     "point p maps to translation + rotation * (scale * p)."},
    {"device", "workspace_rotation", HAPTICD_FIELD(device.workspace.X_SD.rotation), kNoRange, "",
     "Workspace mapping: orientation of the device frame in the scene."},
    {"device", "workspace_scale", HAPTICD_FIELD(device.workspace.scale), positive(1e9), "",
     "Workspace mapping: scene metres per device metre. Forces map back by the same factor so "
     "that power is preserved."},
    {"device", "service_interval_s", HAPTICD_FIELD(device.service_interval_s), positive(10.0), "s",
     "How often the device's hotplug and reconnection work runs (on a normal thread)."},
    {"device", "sim_hand_inertia_kg_m2", HAPTICD_FIELD(device.options.sim_hand_inertia_kg_m2),
     positive(1000.0), "kg m^2", "sim device: isotropic rotational inertia of the hand."},
    {"device", "sim_hand_rot_stiffness_nm_per_rad",
     HAPTICD_FIELD(device.options.sim_hand_rot_stiffness_nm_per_rad), positive(1e6), "N m/rad",
     "sim device: rotational spring toward the commanded orientation."},
    {"device", "sim_hand_rot_damping_nm_s_per_rad",
     HAPTICD_FIELD(device.options.sim_hand_rot_damping_nm_s_per_rad), closed(0.0, 1e6), "N m s/rad",
     "sim device: rotational damper."},
    {"device", "sim_idle_amplitude_m", HAPTICD_FIELD(device.options.sim_idle_amplitude_m),
     closed(0.0, 1e6), "m",
     "sim device: translation amplitude per axis of the built-in gentle motion (a Lissajous "
     "path around the home pose, periods in docs/devices.md)."},
    {"device", "sim_idle_angle_rad", HAPTICD_FIELD(device.options.sim_idle_angle_rad),
     closed(0.0, 3.14159), "rad", "sim device: rotation amplitude per axis of the gentle motion."},
    {"device", "sim_max_step_s", HAPTICD_FIELD(device.options.sim_max_step_s), positive(1.0), "s",
     "sim device: the longest integration step; a longer gap between readings is sub-stepped."},
    {"device", "replay_quat_tolerance", HAPTICD_FIELD(device.options.replay_quat_tolerance),
     positive(0.5), "",
     "replay device: how far from unit length a quaternion may be (| |q| - 1 |) before the file "
     "is refused; nearer ones are normalised."},
    {"device", "hid_spacemouse_speed_m_per_s",
     HAPTICD_FIELD(device.options.hid_spacemouse_speed_m_per_s), positive(1e3), "m/s",
     "hid device (SpaceMouse): linear speed at full deflection."},
    {"device", "hid_spacemouse_angular_speed_rad_per_s",
     HAPTICD_FIELD(device.options.hid_spacemouse_angular_speed_rad_per_s), positive(1e3), "rad/s",
     "hid device (SpaceMouse): angular speed at full deflection."},
    {"device", "hid_spacemouse_full_scale", HAPTICD_FIELD(device.options.hid_spacemouse_full_scale),
     positive(32767.0), "",
     "hid device (SpaceMouse): the deflection (counts) that counts as full."},
    {"device", "hid_spacemouse_deadband", HAPTICD_FIELD(device.options.hid_spacemouse_deadband),
     closed(0.0, 32767.0), "",
     "hid device (SpaceMouse): deadband (counts) below which an axis reads zero."},
    {"device", "hid_spacemouse_workspace_m",
     HAPTICD_FIELD(device.options.hid_spacemouse_workspace_m), positive(1e6), "m",
     "hid device (SpaceMouse): half-size of the box around the home pose that the integrated "
     "position is kept in."},
    {"device", "usb_silence_lost_s", HAPTICD_FIELD(device.options.usb_silence_lost_s),
     positive(60.0), "s",
     "usb device (Falcon): with no packet from the device for this long it counts as lost."},
    {"device", "usb_falcon_max_motor_command",
     HAPTICD_FIELD(device.options.usb_falcon_max_motor_command), closed(1, 32767), "",
     "usb device (Falcon): largest motor command magnitude sent (firmware units); larger "
     "commands are scaled down together, keeping the force direction."},
    {"device", "usb_falcon_firmware", HAPTICD_FIELD(device.options.usb_falcon_firmware), kNoRange,
     "",
     "usb device (Falcon): the Novint firmware file loaded into a Falcon that does not answer "
     "(after power-up); empty never loads one (the Falcon must have its firmware already)."},
    {"device", "forcedimension_library", HAPTICD_FIELD(device.options.forcedimension_library),
     kNoRange, "",
     "forcedimension device: the Force Dimension DHD library to load (a path or a library "
     "name); empty uses $HAPTICD_DHD_LIBRARY, else libdhd.so and libdhd.so.3 from the SDK."},
    {"device", "openhaptics_library", HAPTICD_FIELD(device.options.openhaptics_library), kNoRange,
     "",
     "openhaptics device: the OpenHaptics HD library to load (a path or a library name); empty "
     "uses $HAPTICD_HD_LIBRARY, else libHD.so and libHD.so.3.4."},
    {"device", "haply_silence_lost_s", HAPTICD_FIELD(device.options.haply_silence_lost_s),
     closed(1e-3, 60.0), "s",
     "haply device: the Haply Inverse Service answering no command for this long counts as the "
     "device lost (reconnected when it is back)."},
    {"device", "haply_connect_timeout_s", HAPTICD_FIELD(device.options.haply_connect_timeout_s),
     closed(1e-3, 60.0), "s",
     "haply device: how long opening (and each reconnection) waits for the service's WebSocket "
     "and its device list."},

    // [response]
    {"response", "stiffness_n_per_m", HAPTICD_FIELD(response.sim.response.stiffness_n_per_m),
     positive(1e9), "N/m",
     "Contact stiffness k_s (0.6 N/mm, paper section 5.1); a body's extras.haptic.stiffness "
     "wins."},
    {"response", "tick_s", HAPTICD_FIELD(response.tick_s), closed(0.0, 1.0), "s",
     "Time step of the response; 0 follows [servo] rate_hz (1 / rate_hz)."},
    {"response", "max_pairs_per_tick", HAPTICD_FIELD(response.sim.max_pairs_per_tick),
     closed(0, 100000000), "",
     "Narrow-phase pair tests per tick, 0 for no limit (pairs only, never a time budget, so that "
     "runs are bitwise identical)."},
    {"response", "probe_sphere_radius_m", HAPTICD_FIELD(response.sim.probe_sphere_radius_m),
     positive(1e6), "m", "Radius of the probe sphere used when the scene marks no probe body."},
    {"response", "max_speed_m_per_s", HAPTICD_FIELD(response.sim.response.max_speed_m_per_s),
     closed(0.0, 1e6), "m/s",
     "Deprecated, kept for configurations that set it: > 0 makes the safe distance absolute, "
     "max_speed_m_per_s * tick scene units per proxy sub-step (it no longer bounds the proxy's "
     "speed); 0 takes it from safe_distance_fraction."},
    {"response", "safe_distance_fraction",
     HAPTICD_FIELD(response.sim.response.safe_distance_fraction), positive(1.0), "",
     "The safe distance (paper section 5.2) is this fraction of the probe body's radius: no "
     "point of the held body moves farther in one proxy sub-step, and the broad phase looks "
     "twice that far. The proxy takes as many sub-steps as it needs to reach the device in one "
     "tick (up to max_substeps), so in free space it keeps up at any speed."},
    {"response", "max_substeps", HAPTICD_FIELD(response.sim.response.max_substeps),
     closed(1, 100000), "",
     "Most proxy sub-steps in one tick; beyond max_substeps safe distances per tick the proxy "
     "catches up over the next ticks (TickOutput travel_limited)."},
    {"response", "speed_decay_s", HAPTICD_FIELD(response.sim.response.speed_decay_s),
     positive(60.0), "s",
     "The predictive distance delta = v_c * tick (paper section 5.2); v_c, the bound on the held "
     "body's point speed from the device's motion, decays with this time constant."},
    {"response", "min_predictive_fraction",
     HAPTICD_FIELD(response.sim.response.min_predictive_fraction), positive(1.0), "",
     "delta is at least this fraction of the held body's radius."},
    {"response", "proxy_stiffness_ratio",
     HAPTICD_FIELD(response.sim.response.proxy_stiffness_ratio), Range{1.0, 1e6, true, false}, "",
     "The proxy's contact stiffness is this many times stiffness_n_per_m; the coupling "
     "stiffness is chosen so that the two in series give exactly stiffness_n_per_m at the "
     "device."},
    {"response", "coupling_damping_factor",
     HAPTICD_FIELD(response.sim.response.coupling_damping_factor), closed(0.0, 1e3), "",
     "Coupling damping B = factor * K * tick (linear and rotational); 1 keeps a factor 2 over "
     "the sampled-spring passivity bound."},
    {"response", "rot_stiffness_nm_per_rad",
     HAPTICD_FIELD(response.sim.response.rot_stiffness_nm_per_rad), closed(0.0, 1e6), "N m/rad",
     "Rotational coupling stiffness; 0 takes k_c * r^2 with r the held body's radius."},
    {"response", "penetration_allowance_m",
     HAPTICD_FIELD(response.sim.response.penetration_allowance_m), closed(0.0, 1e6), "m",
     "A proxy step that would leave the proxy deeper than this is bisected back; 0 derives it "
     "from the device and the stiffness: 1.5 max_force_n / (proxy_stiffness_ratio * "
     "stiffness_n_per_m), 1.5 times the proxy's penetration at the force limit (0.5 mm at the "
     "defaults)."},
    {"response", "crease_angle_deg", HAPTICD_FIELD(response.sim.response.crease_angle_deg),
     below(0.0, 90.0), "degrees",
     "Force shading (paper section 5.3): edges whose faces bend by less than this are "
     "smoothed; 0 turns shading off."},
    {"response", "attach_button_mask", HAPTICD_FIELD(response.sim.response.attach_button_mask),
     closed(0, 4294967295.0), "",
     "Buttons (bit mask) that attach the probe to the body it touches while held down (section "
     "6.2)."},
    {"response", "attach_distance_fraction",
     HAPTICD_FIELD(response.sim.response.attach_distance_fraction), closed(0.0, 1.0), "",
     "The probe attaches to a body no farther than this fraction of the probe body's radius "
     "(and never less than two safe distances)."},
    {"response", "attach_distance_m", HAPTICD_FIELD(response.sim.response.attach_distance_m),
     closed(0.0, 1e6), "m",
     "Deprecated, kept for configurations that set it: > 0 is an absolute attach distance "
     "(scene units) instead of attach_distance_fraction; 0 uses the fraction."},
    {"response", "hinge_attach", HAPTICD_FIELD(response.sim.response.hinge_attach), kNoRange, "",
     "How the probe attaches to a body on a hinge: \"rim\", \"centre\", or \"auto\" (centre when "
     "the probe is within centre_radius_fraction of the body's radius from the axis, else "
     "rim)."},
    {"response", "centre_radius_fraction",
     HAPTICD_FIELD(response.sim.response.centre_radius_fraction), closed(0.0, 1.0), "",
     "See hinge_attach."},
    {"response", "grab_weight", HAPTICD_FIELD(response.sim.response.grab_weight), kNoRange, "",
     "With dynamics: a dynamic body grabbed rigidly is felt with its weight (m g in the scene's "
     "gravity, at its centre of mass); false: it weighs nothing in the hand."},
    {"response", "grab_inertia", HAPTICD_FIELD(response.sim.response.grab_inertia), kNoRange, "",
     "... and with its inertia (-m a and -(I alpha + w x I w) from the device's accelerations). "
     "Heavy bodies (several times the hand's mass) may swing: turn this off or lengthen the "
     "filter."},
    {"response", "grab_inertia_filter_s",
     HAPTICD_FIELD(response.sim.response.grab_inertia_filter_s), closed(0.0, 10.0), "s",
     "Time constant of the low-pass on the device's accelerations for grab_inertia; 0: "
     "unfiltered."},
    {"response", "dynamic_backstop_fraction",
     HAPTICD_FIELD(response.sim.response.dynamic_backstop_fraction), closed(0.0, 1.0), "",
     "With dynamics: the held set's contacts with a dynamic body are the dynamics' (impulses); "
     "its penalty rows act only once the held set is deeper than this fraction of "
     "penetration_allowance_m into the body (a body wedged against something fixed); 0: penalty "
     "rows from the surface as well."},
    {"response", "impulse_window_s", HAPTICD_FIELD(response.sim.dynamics_impulse_window_s),
     closed(0.0, 10.0), "s",
     "With dynamics: each impulse on the held body is spread as a force on the hand over this "
     "window, so that it can be felt (docs/dynamics.md shows what it does to the force record); "
     "0: one tick of force J / dt."},
    {"response", "dynamics_sleep_time_s", HAPTICD_FIELD(response.sim.dynamics_sleep_time_s),
     closed(0.0, 1e6), "s",
     "With dynamics: the scene sleeps (the dynamics skip their solve) after it has been still "
     "this long, with the held body touching no dynamic body; 0: never."},
    {"response", "dynamics_velocity_iterations",
     HAPTICD_FIELD(response.sim.dynamics_velocity_iterations), closed(1, 1000), "",
     "With dynamics: sequential-impulse iterations per contact solve, at most (a solve stops "
     "earlier once converged). More holds stacks stiffer and costs time per tick "
     "(docs/accuracy.md, part dynamics/)."},
    {"response", "dynamics_position_iterations",
     HAPTICD_FIELD(response.sim.dynamics_position_iterations), closed(0, 1000), "",
     "With dynamics: split-impulse iterations per tick that push penetrating bodies apart "
     "without adding energy; 0: no drift correction (bodies sink into each other)."},
    {"response", "dynamics_velocity_iterations_max",
     HAPTICD_FIELD(response.sim.dynamics_velocity_iterations_max), closed(0, 1000), "",
     "With dynamics: a contact solve not converged after dynamics_velocity_iterations goes on "
     "while its error still falls and would still move the smallest body of its island by more "
     "than 1e-6 of its size in a tick, up to this many iterations (settling towers; "
     "docs/dynamics.md); at most dynamics_velocity_iterations: never beyond it."},
    {"response", "dynamics_position_iterations_max",
     HAPTICD_FIELD(response.sim.dynamics_position_iterations_max), closed(0, 1000), "",
     "With dynamics: the split impulses go on beyond dynamics_position_iterations while a "
     "resting frictionless contact's levelling still converges, up to this many (frictionless "
     "stacks; docs/dynamics.md); at most dynamics_position_iterations: never beyond it."},

    // [scene]
    {"scene", "path", HAPTICD_FIELD(scene.path), kNoRange, "",
     "Scene file (.glb, or .gltf with embedded data); empty serves the built-in demo scene."},
    {"scene", "demo", HAPTICD_FIELD(scene.demo), kNoRange, "",
     "The built-in demo scene served when path is empty.", &checkDemo},
    {"scene", "max_file_bytes", HAPTICD_FIELD(scene.limits.max_file_bytes),
     closed(1, 1099511627776.0), "bytes", "Largest scene file accepted."},
    {"scene", "max_nodes", HAPTICD_FIELD(scene.limits.max_nodes), closed(1, 100000000), "",
     "Largest number of glTF nodes."},
    {"scene", "max_bodies", HAPTICD_FIELD(scene.limits.max_bodies), closed(1, 100000000), "",
     "Largest number of bodies."},
    {"scene", "max_primitives", HAPTICD_FIELD(scene.limits.max_primitives), closed(1, 100000000),
     "", "Largest number of convex primitives."},
    {"scene", "max_hull_input_points", HAPTICD_FIELD(scene.limits.max_hull_input_points),
     closed(4, 100000000), "", "Largest number of points given to one convex hull."},
    {"scene", "max_hull_vertices", HAPTICD_FIELD(scene.limits.max_hull_vertices),
     closed(4, 100000000), "", "Largest number of vertices of one hull."},
    {"scene", "tessellation_tolerance", HAPTICD_FIELD(scene.limits.tessellation_tolerance),
     Range{0.0, 0.5, true, true}, "",
     "Curved implicit shapes are tessellated so that no surface point is farther than this "
     "fraction of the shape's size from its polytope."},
    {"scene", "allowed_uri_dir", HAPTICD_FIELD(scene.allowed_uri_dir), kNoRange, "",
     "The folder the scene file's external URIs (buffers, images) resolve in; empty: the file's "
     "own folder. Uploads never resolve external URIs (hapticctl load bundles them)."},
    {"scene", "concavity", HAPTICD_FIELD(scene.concavity), Range{0.0, 1.0, true, true}, "",
     "Meshes that are not convex (TRIMESH colliders, mesh colliders without convexHull, plain "
     "models) are touched through convex pieces of an approximate convex decomposition, each "
     "within this fraction of the mesh's bounding-box diagonal; extras.haptic.concavity on a "
     "node (or an ancestor) overrides it for its meshes."},
    {"scene", "max_pieces", HAPTICD_FIELD(scene.max_pieces), closed(1, 10000), "",
     "Most convex pieces per decomposed mesh (each a primitive, counted against "
     "max_primitives)."},
    {"scene", "decompose_time_limit_s", HAPTICD_FIELD(scene.decompose_time_limit_s),
     closed(0.0, 86400.0), "s",
     "Wall-clock limit of one mesh's decomposition: past it the best pieces so far are used "
     "and hapticctl check says so; 0: no limit."},
    {"scene", "cache_dir", HAPTICD_FIELD(scene.cache_dir), kNoRange, "",
     "Folder of the decomposition cache (a mesh decomposed once with the same options is read "
     "back on the next load): \"auto\" is $CACHE_DIRECTORY (the unit's CacheDirectory=), else "
     "$XDG_CACHE_HOME/hapticd, else $HOME/.cache/hapticd; \"\" turns the cache off. Entries "
     "that fail their checks are rebuilt; a folder that cannot be written is a warning.",
     &checkCacheDir},
    {"scene", "cache_max_mb", HAPTICD_FIELD(scene.cache_max_mb), closed(0, 4000000), "MiB",
     "Most the decomposition cache's entries may take: after an entry is written, the least "
     "recently used (read or written) are removed until the rest fit; 0: no limit. Only "
     "entries (<key>.pieces) and dead writers' temporary files are ever removed."},

    // [network]
    {"network", "udp", HAPTICD_FIELD(network.udp), kNoRange, "",
     "UDP address the protocol listens on, \"ADDRESS:PORT\" (loopback by default; another "
     "address needs key_file). \"\" turns it off. With [servo] clock = \"virtual\" it is off "
     "unless set (here, or by --udp).",
     &checkUdp},
    {"network", "key_file", HAPTICD_FIELD(network.key_file), kNoRange, "",
     "File holding the pre-shared key (64 hex digits); when set, scene uploads, scene updates, "
     "pose commands, arm and disarm need a valid per-packet MAC (libsodium) and replay "
     "protection."},
    {"network", "rate_limit_packets_per_s", HAPTICD_FIELD(network.rate_limit_packets_per_s),
     closed(0.0, 1e9), "", "Per-peer rate limit: sustained datagrams per second (0: unlimited)."},
    {"network", "rate_limit_burst", HAPTICD_FIELD(network.rate_limit_burst), closed(1.0, 1e9), "",
     "Per-peer rate limit: burst size in datagrams."},
    {"network", "max_datagram_bytes", HAPTICD_FIELD(network.max_datagram_bytes), closed(512, 65507),
     "bytes", "Larger datagrams are refused and counted."},
    {"network", "max_state_rate_hz", HAPTICD_FIELD(network.max_state_rate_hz), closed(1.0, 1000.0),
     "Hz", "Subscribers' state rates are clamped to this."},
    {"network", "shm", HAPTICD_FIELD(network.shm), kNoRange, "",
     "Shared-memory segment for clients on this host (POSIX shm name: \"/\" then a name without "
     "\"/\"), mode 0600, removed at exit: a seqlock state block written every tick and a command "
     "ring that feeds the same command gate as UDP (docs/daemon.md). \"\" turns it off. A "
     "segment that cannot be created is a warning and the daemon runs without it; one held by "
     "another live hapticd is left alone. With [servo] clock = \"virtual\" it is off unless set "
     "(here, or by --shm).",
     &checkShmName},

    // [web]
    {"web", "listen", HAPTICD_FIELD(web.listen), kNoRange, "",
     "HTTP and WebSocket address, \"ADDRESS:PORT\": the viewer on \"/\", the JSON API on \"/ws\" "
     "(protocol/websocket.md); \"\" turns it off. Loopback by default; another address needs "
     "[network] key_file (the same key as UDP: commands need the key's tag, watching does not). "
     "With [servo] clock = \"virtual\" it is off unless set on the command line (--web) or in "
     "the file that sets the clock.",
     &checkWebListen},
    {"web", "root", HAPTICD_FIELD(web.root), kNoRange, "",
     "Folder served on \"/\" (the viewer's files). \"\": the install's share/hapticd/web next "
     "to the binary (BIN/../share/hapticd/web), else the source tree's web/."},
    {"web", "max_message_bytes", HAPTICD_FIELD(web.max_message_bytes), closed(4096, 1073741824),
     "bytes",
     "Larger WebSocket messages from a client are refused (the connection is closed with "
     "1009); a load's glb_base64 is 4/3 of the scene's size."},

    // [log]
    {"log", "level", HAPTICD_FIELD(log.level), kNoRange, "",
     "Least severe level logged: \"error\", \"warning\", \"info\", \"debug\"."},
    {"log", "status_interval_s", HAPTICD_FIELD(log.status_interval_s), closed(0.0, 86400.0), "s",
     "A status line (tick figures, faults) is logged this often; 0 never."},
};

#undef HAPTICD_FIELD

constexpr std::string_view kSections[] = {"servo",   "device", "response", "scene",
                                          "network", "web",    "log"};

template <class T>
constexpr bool kIsEnum = std::is_enum_v<T>;

// an enum's name and parser, by type
const char* enumName(RealtimePolicy v) {
  return toString(v);
}
const char* enumName(ClockKind v) {
  return toString(v);
}
const char* enumName(LogLevel v) {
  return toString(v);
}
const char* enumName(sim::ResponseOptions::HingeAttach v) {
  return toString(v);
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(ch));
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

template <class V>
std::string tomlArray(const V& v, int n) {
  std::string out = "[";
  for (int i = 0; i < n; ++i)
    out += (i ? ", " : "") + tomlFloat(v[i]);
  return out + "]";
}

}  // namespace

bool Range::contains(double v) const {
  if (!std::isfinite(v))
    return false;
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

std::string Range::text() const {
  // whole numbers below 1e7 in full (1000000, not 1e+06)
  const auto num = [](double v) {
    return v == std::floor(v) && std::fabs(v) < 1e7 ? std::to_string(static_cast<std::int64_t>(v))
                                                    : shortestNumber(v);
  };
  return std::string(lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
}

std::string ConfigKey::label() const {
  return "[" + std::string(section) + "] " + std::string(name);
}

std::span<const ConfigKey> configKeys() {
  return kKeys;
}

std::span<const std::string_view> configSections() {
  return kSections;
}

const ConfigKey* findConfigKey(std::string_view section, std::string_view name) {
  for (const ConfigKey& k : kKeys)
    if (k.section == section && k.name == name)
      return &k;
  return nullptr;
}

std::string shortestNumber(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string tomlFloat(double v) {
  if (std::isnan(v))
    return "nan";
  if (std::isinf(v))
    return v > 0 ? "inf" : "-inf";
  char buf[64];
  // fixed notation where it stays short (0.0005, 67108864.0), else the shortest (1e-09)
  const double a = std::fabs(v);
  const bool fixed = a == 0.0 || (a >= 1e-5 && a < 1e16);
  const auto r = fixed ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
                       : std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eE") == std::string::npos)
    s += ".0";
  return s;
}

std::string tomlValue(const ConfigKey& key, const Config& c) {
  return std::visit(
      [](const auto* p) -> std::string {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_same_v<T, bool>) {
          return *p ? "true" : "false";
        } else if constexpr (std::is_same_v<T, double>) {
          return tomlFloat(*p);
        } else if constexpr (std::is_integral_v<T>) {
          return std::to_string(*p);
        } else if constexpr (std::is_same_v<T, std::string>) {
          return quoted(*p);
        } else if constexpr (std::is_same_v<T, geom::Vec3>) {
          return tomlArray(*p, 3);
        } else if constexpr (std::is_same_v<T, geom::Quat>) {
          const double xyzw[4] = {p->x, p->y, p->z, p->w};
          return tomlArray(xyzw, 4);
        } else {
          static_assert(kIsEnum<T>);
          return quoted(enumName(*p));
        }
      },
      key.in(c));
}

std::optional<std::string> checkNumber(const ConfigKey& key, double v) {
  if (key.range.contains(v))
    return std::nullopt;
  if (key.range.lo_open && std::isfinite(v) && v <= key.range.lo)
    return "must be > " + shortestNumber(key.range.lo) + " (got " + shortestNumber(v) + ")";
  const std::string unit = key.unit.empty() ? "" : " " + std::string(key.unit);
  return "must be in " + key.range.text() + unit + " (got " + shortestNumber(v) + ")";
}

std::optional<std::string> checkValue(const ConfigKey& key, const Config& c) {
  return std::visit(
      [&](const auto* p) -> std::optional<std::string> {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_same_v<T, bool>) {
          return std::nullopt;
        } else if constexpr (std::is_same_v<T, double> || std::is_integral_v<T>) {
          return checkNumber(key, static_cast<double>(*p));
        } else if constexpr (std::is_same_v<T, std::string>) {
          return key.check != nullptr ? key.check(*p) : std::nullopt;
        } else if constexpr (std::is_same_v<T, geom::Vec3>) {
          for (int i = 0; i < 3; ++i)
            if (!std::isfinite((*p)[i]) || std::fabs((*p)[i]) > key.range.hi)
              return "element " + std::to_string(i) + " must be finite and within ±" +
                     shortestNumber(key.range.hi) + " (got " + shortestNumber((*p)[i]) + ")";
          return std::nullopt;
        } else if constexpr (std::is_same_v<T, geom::Quat>) {
          const double len = std::sqrt(glm::dot(*p, *p));
          if (!geom::finite(*p) || std::fabs(len - 1.0) > 1e-6)
            return "must be a unit quaternion [x, y, z, w] (length " + shortestNumber(len) + ")";
          return std::nullopt;
        } else {
          static_assert(kIsEnum<T>);
          if (std::string_view(enumName(*p)) == "?")
            return "has no valid value";
          return std::nullopt;
        }
      },
      key.in(c));
}

bool sameValue(const ConfigKey& key, const Config& a, const Config& b) {
  return std::visit([&](auto* pa) { return *pa == *std::get<decltype(pa)>(key.in(b)); }, key.in(a));
}

}  // namespace hapticd::daemon
