#pragma once
/// \file
/// The haptic device behind one interface: pose and buttons in, force and torque out, limits,
/// capabilities. Backends: `sim` (default), `replay:FILE`, `hid`, `usb` (daemon/device/*.cpp).
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
};

/// One reading, in the device's workspace frame (metres, radians), before the workspace mapping.
struct DeviceSample {
  Pose X_WD;  ///< pose of the handle
  Vec3 linear_velocity{0.0};
  Vec3 angular_velocity{0.0};
  std::uint32_t buttons = 0;
};

/// How a servo-thread call ended.
enum class DeviceStatus : std::uint8_t {
  kOk,
  kLost,        ///< not connected (removed, I/O error): the loop sets force to zero at once
  kEndOfStream  ///< replay finished: the loop ends
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
};

/// A device spec taken apart: the backend and its argument.
struct DeviceSpec {
  enum class Backend : std::uint8_t { kSim, kReplay, kHid, kUsb };
  Backend backend = Backend::kSim;
  std::string arg;  ///< replay: the file; hid: the hidraw path or ""; usb: "falcon" or ""
  /// Opening it has no effect outside the process (sim, replay): `hapticd --check-config` opens
  /// such a device; hid and usb are checked by their spec only (opening one would take it from
  /// a running daemon).
  bool openIsHarmless() const { return backend == Backend::kSim || backend == Backend::kReplay; }
};

/// Checks a spec: "sim", "replay:FILE", "hid", "hid:PATH", "usb", "usb:falcon". Any thread.
/// Errors name the spec and what is wrong.
Result<DeviceSpec> parseDeviceSpec(std::string_view spec);

/// Opens a device from its spec (parseDeviceSpec). Off the servo thread. Errors name the spec
/// and what is wrong.
Result<std::unique_ptr<Device>> makeDevice(std::string_view spec, const DeviceOptions& options);

}  // namespace hapticd::device
