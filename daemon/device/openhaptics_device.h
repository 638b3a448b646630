#pragma once
/// \file
/// The `openhaptics[:NAME]` device: a 3D Systems Touch / Touch X / Phantom Premium through the
/// OpenHaptics HD API (hd_api.h), loaded at run time. The HD API runs its own servo scheduler,
/// so this device owns the clock: ServoLoop::run() hands it its tick (runClocked()), and each
/// tick runs inside the HD scheduler callback, between hdBeginFrame() and hdEndFrame().
/// Pose (the stylus transform) and the stylus buttons in; force out, and gimbal torque on a device
/// with 6 output DOF (else the torque is dropped and counted). docs/devices.md.
///
/// Threads: open() and service() off the servo thread; runClocked() on the servo thread, which
/// waits in it; read(), write() and setOutputHeld() on the HD scheduler thread (inside the frame;
/// no allocation, lock or log in hapticd's code).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/device/connection.h"
#include "daemon/device/hd_api.h"
#include "daemon/device/pose_velocity.h"

namespace hapticd::device {

class OpenHapticsDevice final : public HotplugDevice {
 public:
  /// Initialises the device named `name` ("" the default device) through `api`, force output
  /// enabled. Off the servo thread. Fails when the HD API cannot initialise it.
  static Result<std::unique_ptr<OpenHapticsDevice>> open(const hd::Api& api,
                                                         const std::string& name,
                                                         const DeviceOptions& options);
  /// The device disabled.
  ~OpenHapticsDevice() override;

  const DeviceInfo& info() const override { return info_; }
  /// The stylus transform (millimetres to metres) and buttons; kLost on a communication error,
  /// kFault on another HD error, a calibration that is not ok, and once after a reconnection.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Force, and gimbal torque (N m to the API's mN m) on a 6-DOF force device; zero while held.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  void setOutputHeld(bool held) noexcept override { held_ = held; }
  bool ownsClock() const noexcept override { return true; }
  /// Schedules `tick` as an asynchronous HD callback at the highest priority, starts the HD
  /// scheduler, and waits (sleeping 1 ms at a time) until `tick` returns false; then stops it.
  bool runClocked(ClockedTick tick, void* context) noexcept override;
  /// After a loss: connected again once the callback's probe of the device succeeded.
  bool service() override;

  /// Counters (any thread): torques dropped, HD errors reported as faults, ticks whose
  /// calibration was not ok.
  std::uint64_t torquesDropped() const noexcept { return torque_dropped_.load(); }
  std::uint64_t faults() const noexcept { return faults_.load(); }
  std::uint64_t uncalibratedTicks() const noexcept { return uncalibrated_.load(); }
  /// The last hdCheckCalibration() answer (HD_CALIBRATION_OK, ...). Any thread.
  int calibration() const noexcept { return calibration_.load(std::memory_order_relaxed); }

 private:
  OpenHapticsDevice(const hd::Api& api, const DeviceOptions& options);
  static unsigned int callback(void* self) noexcept;
  // the errors on HD's stack: kLost on a communication error, else kFault, else kOk
  DeviceStatus drainErrors() noexcept;

  hd::Api api_;
  hd::HHD device_ = hd::kInvalidHandle;
  DeviceOptions options_;
  DeviceInfo info_;
  bool torque_out_ = false;
  ClockedTick tick_ = nullptr;
  void* tick_context_ = nullptr;
  std::atomic<bool> done_{false};
  std::atomic<bool> probe_ok_{false};  // lost, and the device answered a probe since
  std::atomic<bool> rearm_pending_{false};
  std::atomic<int> calibration_{hd::kCalibrationOk};
  std::atomic<std::uint64_t> torque_dropped_{0};
  std::atomic<std::uint64_t> faults_{0};
  std::atomic<std::uint64_t> uncalibrated_{0};
  // scheduler-thread state
  bool held_ = false;
  bool fault_pending_ = false;
  std::uint64_t lost_ticks_ = 0;
  PoseVelocity velocity_;
  Pose last_X_{};
  std::uint32_t buttons_ = 0;
};

/// makeDevice("openhaptics[:NAME]"): loads libHD (options.openhaptics_library) and initialises
/// the device. Off the servo thread.
Result<std::unique_ptr<Device>> makeOpenHapticsDevice(const std::string& name,
                                                      const DeviceOptions& options);

}  // namespace hapticd::device
