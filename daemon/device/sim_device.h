#pragma once
/// \file
/// The `sim` device: a simulated 6-DOF hand (a mass and an inertia on springs and dampers) pulled
/// toward the latest pose command, or toward a built-in gentle motion when no command came for a
/// while; the force and torque written by the servo loop act on it, so that the loop is closed.
/// The model, its integrator and the idle path are in docs/devices.md ("sim").

#include "daemon/device/device.h"

namespace hapticd::device {

/// A point of the built-in gentle motion: the pose and its exact time derivative (linear m/s,
/// angular rad/s, world frame).
struct IdleMotion {
  Pose X_W;
  Vec3 v_W{0.0};
  Vec3 w_W{0.0};
};
/// The built-in gentle motion: a smooth Lissajous path around X_W_home at t_s seconds.
IdleMotion simIdleMotion(const Pose& X_W_home,
                         double amplitude_m,
                         double angle_rad,
                         double t_s) noexcept;

/// The simulated hand. Deterministic: the same calls give bitwise the same samples.
class SimDevice final : public Device {
 public:
  /// Off the servo thread. options are checked by makeSimDevice().
  explicit SimDevice(const DeviceOptions& options);

  const DeviceInfo& info() const override { return info_; }
  /// Integrates the hand from the previous call's time to t_s (semi-implicit Euler, sub-stepped at
  /// sim_max_step_s) with the force last written, then reports it. A t_s not after the previous
  /// call reports the same state. Servo thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// The force and torque on the hand until the next read (world frame). Servo thread.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  /// The new target of the hand's springs. Servo thread.
  void command(const PoseCommand& cmd) noexcept override;

  /// The hand's mechanical energy relative to the current target (kinetic plus the springs'),
  /// joules. For tests and status.
  double energy() const noexcept;

 private:
  void target(double t_s, Pose& X_W_target, Vec3& v_W_target, Vec3& w_W_target) const noexcept;
  void step(double t_s, double h_s) noexcept;

  DeviceOptions options_;
  DeviceInfo info_;
  // hand state (world frame)
  Vec3 p_W_;
  Vec3 v_W_{0.0};
  geom::Quat q_WH_;
  Vec3 w_W_{0.0};
  // the loop's force and torque on the hand
  Vec3 force_W_{0.0};
  Vec3 torque_W_{0.0};
  // the latest command and when it came (loop time)
  bool has_command_ = false;
  PoseCommand command_;
  double command_t_s_ = 0.0;
  double t_s_ = 0.0;
  bool started_ = false;
  std::uint32_t buttons_ = 0;
};

/// Checks the sim options (finite, positive) and opens the device. Off the servo thread.
Result<std::unique_ptr<Device>> makeSimDevice(const DeviceOptions& options);

}  // namespace hapticd::device
