#pragma once
/// \file
/// The `forcedimension[:INDEX]` device: a Force Dimension omega / sigma / lambda / delta (or a
/// Falcon through Force Dimension's SDK) driven through the DHD API (dhd_api.h), loaded at run
/// time. Position, orientation frame (devices with a wrist) and gripper angle in; force, torque
/// (devices with an active wrist; else dropped and counted) and zero gripper force out. The SDK's
/// gravity compensation is on from the start; its brakes are on at open, after every
/// reconnection and whenever the loop holds its output at zero (a fault after its fade, a
/// disarm, a stop), and released when the loop's output goes live. docs/devices.md.
///
/// Threads: open() and service() off the servo thread; read(), write() and setOutputHeld() on the
/// servo thread (function-pointer calls into the SDK only; no allocation, lock or log in
/// hapticd's code).

#include <atomic>
#include <cstdint>
#include <memory>

#include "daemon/device/connection.h"
#include "daemon/device/dhd_api.h"
#include "daemon/device/pose_velocity.h"

namespace hapticd::device {

class ForceDimensionDevice final : public HotplugDevice {
 public:
  /// Opens device `index` (0-based, in the SDK's order) through `api`. Off the servo thread.
  /// Fails when the SDK finds no such device or cannot open it.
  static Result<std::unique_ptr<ForceDimensionDevice>> open(const dhd::Api& api,
                                                            int index,
                                                            const DeviceOptions& options);
  /// Brakes on and the device closed.
  ~ForceDimensionDevice() override;

  const DeviceInfo& info() const override { return info_; }
  /// Position (and orientation frame, gripper angle, buttons), converted from the SDK's base
  /// frame (x toward the user, y right, z up) to hapticd's device frame (x right, y up, z toward
  /// the user). kLost on a communication error (the SDK's COM, TIMEOUT, NO_DEVICE_FOUND, ...);
  /// kFault on any other error, and once after a reconnection. Servo thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Force and torque (device frame) to the SDK, while the brakes are off. Servo thread.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  /// Brakes on (held) or forces on (live). Servo thread.
  void setOutputHeld(bool held) noexcept override;
  /// After a loss: closes and reopens the device when the SDK sees it again. Normal thread.
  bool service() override;

  /// Counters (any thread): torques dropped (a device without an active wrist), force commands
  /// the SDK reported as saturating its motors, errors reported as faults.
  std::uint64_t torquesDropped() const noexcept { return torque_dropped_.load(); }
  std::uint64_t saturations() const noexcept { return saturations_.load(); }
  std::uint64_t faults() const noexcept { return faults_.load(); }
  /// Whether the brakes are on (the servo thread's view). Any thread.
  bool braked() const noexcept { return !forces_on_.load(std::memory_order_relaxed); }

 private:
  ForceDimensionDevice(const dhd::Api& api, int index, const DeviceOptions& options);
  // opens the device, gravity compensation and brakes on; then connected
  bool reopen(std::string& error, bool after_loss);
  // the error of the call that just failed: lost or a fault
  DeviceStatus failure() noexcept;

  dhd::Api api_;
  int index_;
  char id_ = -1;  // the SDK's ID of the open device; the service thread's while lost
  DeviceOptions options_;
  DeviceInfo info_;
  bool has_wrist_ = false;
  bool active_wrist_ = false;
  bool has_gripper_ = false;
  bool active_gripper_ = false;
  std::atomic<bool> forces_on_{false};
  std::atomic<bool> rearm_pending_{false};  // reconnected: report one kFault
  std::atomic<std::uint64_t> torque_dropped_{0};
  std::atomic<std::uint64_t> saturations_{0};
  std::atomic<std::uint64_t> faults_{0};
  // servo-thread state
  bool fault_pending_ = false;  // a write failed with a non-loss error: the next read says so
  PoseVelocity velocity_;
  Pose last_X_{};
  std::uint32_t buttons_ = 0;
  double gripper_rad_ = 0.0;
};

/// makeDevice("forcedimension[:INDEX]"): loads the SDK (options.forcedimension_library) and
/// opens the device. Off the servo thread.
Result<std::unique_ptr<Device>> makeForceDimensionDevice(int index, const DeviceOptions& options);

}  // namespace hapticd::device
