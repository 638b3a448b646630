#pragma once
/// \file
/// The haptic device behind one interface: pose and buttons in, force and torque out, limits,
/// capabilities. Backends: `sim` (default), `replay:FILE`, `hid`, `usb`, `forcedimension`,
/// `openhaptics`, `haply` (daemon/device/*.cpp).
///
/// This header is the contract between the device backends and the servo loop: members may be
/// added, none renamed or removed.
///
/// Threads: makeDevice() and service() on a normal thread; read(), write() and command() on the
/// servo thread only (no allocation, no lock, no log, no throw; the device I/O itself may block
/// for at most its own short timeout).

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/common/result.h"
#include "core/geometry/pose.h"

namespace hapticd::device {

using geom::Pose;
using geom::Vec3;

/// What a device can do (DeviceInfo::capabilities bits).
enum Capability : std::uint32_t {
  kCapPosition = 1u << 0,     ///< reports a position
  kCapOrientation = 1u << 1,  ///< reports an orientation
  kCapForce = 1u << 2,        ///< displays force
  kCapTorque = 1u << 3,       ///< displays torque
  kCapButtons = 1u << 4,
  kCapPoseCommands = 1u << 5,  ///< driven by clients' pose commands (the sim device)
  kCapEndOfStream = 1u << 6,   ///< ends by itself (replay)
};

struct DeviceLimits {
  double max_force_n = 10.0;
  double max_torque_nm = 1.0;
};

struct DeviceInfo {
  std::string name;  ///< e.g. "sim", "replay:poses.csv", "hid 046d:c626 SpaceMouse Pro"
  std::uint32_t capabilities = 0;
  DeviceLimits limits;
  /// Vendor devices: the model as the vendor's library names it (e.g. "sigma.7"), its serial
  /// number ("" when unknown), and the degrees of freedom it senses and renders (e.g. 7 and 7 for
  /// a sigma.7: position, orientation and gripper). Empty and 0 for the other backends.
  std::string model;
  std::string serial;
  int sensing_dof = 0;
  int force_dof = 0;
};

/// The device as status shows it: the name, and for vendor devices the model, serial, DOF of
/// sensing and of force, and the limits, e.g. "forcedimension:0 sigma.7: serial 12345, sensing 7
/// DOF, force 7 DOF, limits 20 N 0.4 N m". Any thread; allocates.
std::string describeDevice(const DeviceInfo& info);

/// One reading, in the device's workspace frame (metres, radians), before the workspace mapping.
struct DeviceSample {
  Pose X_WD;  ///< pose of the handle
  Vec3 linear_velocity{0.0};
  Vec3 angular_velocity{0.0};
  std::uint32_t buttons = 0;
  /// Devices with a gripper: its opening angle (radians; 0 for the others). The loop's
  /// simulation has no gripper degree of freedom: it is reported, not rendered.
  double gripper_rad = 0.0;
};

/// How a servo-thread call ended.
enum class DeviceStatus : std::uint8_t {
  kOk,
  kLost,         ///< not connected (removed, I/O error): the loop sets force to zero at once
  kEndOfStream,  ///< replay finished: the loop ends
  /// connected, but the device reported an error (or came back after a loss and must be
  /// re-armed): the sample is the last good one; the loop latches its `device` fault, which
  /// fades the force to zero until re-armed
  kFault
};

/// A pose command from a client (protocol), handed to the device on the servo thread.
struct PoseCommand {
  Pose X_W_target;
  Vec3 linear_velocity{0.0};
  Vec3 angular_velocity{0.0};
  std::uint32_t buttons = 0;
};

/// The command held still (velocities zero): what the command gate hands on while it ramps.
inline void zeroVelocities(PoseCommand& c) noexcept {
  c.linear_velocity = Vec3(0.0);
  c.angular_velocity = Vec3(0.0);
}

class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceInfo& info() const = 0;

  /// The pose at loop time t_s (seconds from the loop's start). Servo thread.
  virtual DeviceStatus read(double t_s, DeviceSample& out) noexcept = 0;
  /// Displays force and torque (device frame, already checked finite and clamped to limits()).
  /// Servo thread.
  virtual DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept = 0;
  /// A client's pose command; devices without kCapPoseCommands ignore it. Servo thread.
  virtual void command(const PoseCommand& /*cmd*/) noexcept {}
  /// The loop tells the device whether its output is held at zero (true: a latched fault or a
  /// disarm after its fade, or a stop; false: forces are live). Called at the loop's first tick
  /// and at every change. Devices with brakes engage them while held (forcedimension); the
  /// others ignore it. Servo thread.
  virtual void setOutputHeld(bool /*held*/) noexcept {}

  /// One tick of the loop, run by a device that owns the clock; false ends the run.
  using ClockedTick = bool (*)(void* context) noexcept;
  /// True for a device whose own servo scheduler paces the loop (openhaptics): the loop's tick
  /// then runs inside the device's scheduler callback (runClocked()). Any thread.
  virtual bool ownsClock() const noexcept { return false; }
  /// Devices that own the clock: calls `tick(context)` once per device tick, from the device's
  /// scheduler (where read(), write() and setOutputHeld() are then called), until it returns
  /// false, and returns true then; false when the scheduler could not run (the loop then runs
  /// on its own clock). The others return false at once. Called by ServoLoop::run() on the servo
  /// thread, which waits in it.
  virtual bool runClocked(ClockedTick /*tick*/, void* /*context*/) noexcept { return false; }

  /// The start pose of the held body in a newly swapped-in scene, device frame (after the
  /// workspace mapping; only with [device] sim_home_from_scene). Backends with a home of their
  /// own (the sim hand and its idle motion) move it there; others ignore it. Servo thread, at
  /// the tick boundary where the scene is taken.
  virtual void setHome(const Pose& /*X_D_home*/) noexcept {}
  /// Hotplug and reconnection work; called about every 100 ms from a normal thread. Returns true
  /// while the device is connected. Must not race read()/write(): backends hand state over with
  /// atomics only.
  virtual bool service() { return true; }

  /// True while the device is connected (false after a removal or an I/O error, until
  /// service() reconnects it). Any thread (an atomic load).
  virtual bool connected() const noexcept { return true; }
  /// How many times the device was lost since it was opened. Any thread (an atomic load).
  virtual std::uint64_t disconnects() const noexcept { return 0; }
};

/// Options of every backend (config [device]).
struct DeviceOptions {
  DeviceLimits limits;
  /// sim: the hand model (a mass on a spring and damper pulled toward the commanded pose).
  double sim_hand_mass_kg = 0.5;
  double sim_hand_stiffness_n_per_m = 200.0;
  double sim_hand_damping_n_s_per_m = 20.0;
  /// sim: with no pose command for this long, the built-in gentle motion drives the hand.
  double sim_idle_motion_after_s = 1.0;
  /// sim: the start pose of the hand (scene frame).
  Pose sim_home;
  /// sim: the hand's rotational model (isotropic inertia, rotational spring and damper toward the
  /// commanded orientation).
  double sim_hand_inertia_kg_m2 = 0.001;
  double sim_hand_rot_stiffness_nm_per_rad = 1.0;
  double sim_hand_rot_damping_nm_s_per_rad = 0.06;
  /// sim: the built-in gentle motion around sim_home: translation amplitude per axis and rotation
  /// amplitude per axis (a Lissajous path, periods in docs/devices.md).
  double sim_idle_amplitude_m = 0.02;
  double sim_idle_angle_rad = 0.1;
  /// sim: the longest integration step; a longer gap between read() calls is sub-stepped.
  double sim_max_step_s = 0.001;

  /// replay: how far from unit length a quaternion may be (| |q| - 1 |) before the file is refused;
  /// nearer ones are normalised.
  double replay_quat_tolerance = 0.01;

  /// hid (SpaceMouse): speed at full deflection, linear and angular; the deflection that counts as
  /// full; a deadband (counts) below which an axis reads zero; the half-size of the box (around
  /// sim_home) the integrated position is kept in.
  double hid_spacemouse_speed_m_per_s = 0.1;
  double hid_spacemouse_angular_speed_rad_per_s = 1.0;
  double hid_spacemouse_full_scale = 350.0;
  double hid_spacemouse_deadband = 8.0;
  double hid_spacemouse_workspace_m = 0.2;

  /// usb (Falcon): with no packet from the device for this long, it counts as lost.
  double usb_silence_lost_s = 0.1;
  /// usb (Falcon): the largest motor command magnitude sent (firmware units, at most 32767);
  /// commands above it are scaled down together, keeping the force direction.
  int usb_falcon_max_motor_command = 4096;
  /// usb (Falcon): the Novint firmware file to load into a Falcon that does not answer (after
  /// power-up); empty: never load (the Falcon must have its firmware already).
  std::string usb_falcon_firmware;

  /// forcedimension: the Force Dimension DHD library to load (a path or a name for dlopen);
  /// empty: $HAPTICD_DHD_LIBRARY when set, else the names the SDK installs (libdhd.so,
  /// libdhd.so.3).
  std::string forcedimension_library;

  /// openhaptics: the OpenHaptics HD library to load (a path or a name for dlopen); empty:
  /// $HAPTICD_HD_LIBRARY when set, else libHD.so, libHD.so.3.4.
  std::string openhaptics_library;

  /// haply: how long the Haply Inverse Service may leave a command unanswered before the device
  /// counts as lost (the service answers every command with one state message).
  double haply_silence_lost_s = 0.1;
  /// haply: how long opening (and each reconnection by service()) may wait for the service's
  /// WebSocket: the TCP connection, the handshake and the first message (the device list).
  double haply_connect_timeout_s = 1.0;
};

/// A device spec taken apart: the backend and its argument.
struct DeviceSpec {
  enum class Backend : std::uint8_t {
    kSim,
    kReplay,
    kHid,
    kUsb,
    kForceDimension,
    kOpenHaptics,
    kHaply
  };
  Backend backend = Backend::kSim;
  /// replay: the file; hid: the hidraw path or ""; usb: "falcon" or ""; forcedimension: the
  /// device index ("" is 0); openhaptics: the device's configured name ("": the default); haply:
  /// the service's WebSocket URL (kHaplyDefaultUrl when none is given)
  std::string arg;
  /// Opening it has no effect outside the process (sim, replay): `hapticd --check-config` opens
  /// such a device; hid and usb are checked by their spec only (opening one would take it from
  /// a running daemon).
  bool openIsHarmless() const { return backend == Backend::kSim || backend == Backend::kReplay; }
};

/// The largest device index of forcedimension:INDEX.
inline constexpr int kMaxForceDimensionIndex = 15;

/// The Haply Inverse Service's WebSocket (its simulation channel, the 3.x JSON format).
inline constexpr const char* kHaplyDefaultUrl = "ws://127.0.0.1:10001";

/// A `ws://HOST:PORT[/PATH]` URL taken apart (haply:URL).
struct WsUrl {
  std::string host;
  std::uint16_t port = 0;
  std::string path = "/";  ///< the request target, "/" when the URL has none
};

/// Checks a WebSocket URL: `ws://`, a host (a name, an IPv4 address or `[IPv6]`), `:PORT`
/// (1-65535) and an optional path; `wss://` (TLS) is refused. Any thread.
Result<WsUrl> parseWsUrl(std::string_view url);

/// Checks a spec: "sim", "replay:FILE", "hid", "hid:PATH", "usb", "usb:falcon",
/// "forcedimension", "forcedimension:INDEX" (0-15), "openhaptics", "openhaptics:NAME", "haply",
/// "haply:ws://HOST:PORT". Any thread. Errors name the spec and what is wrong.
Result<DeviceSpec> parseDeviceSpec(std::string_view spec);

/// Opens a device from its spec (parseDeviceSpec). Off the servo thread. Errors name the spec
/// and what is wrong.
Result<std::unique_ptr<Device>> makeDevice(std::string_view spec, const DeviceOptions& options);

}  // namespace hapticd::device
