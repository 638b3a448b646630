#pragma once
/// \file
/// The `hid` device (hidapi, hidraw backend): the hapticd generic 6-DOF force-feedback report
/// layout (hid_reports.h) and 3Dconnexion SpaceMouse models as pose-only input. Report I/O goes
/// through HidTransport so that tests feed recorded or synthetic reports.

#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "daemon/device/connection.h"
#include "daemon/device/hid_reports.h"

namespace hapticd::device {

/// One HID interface found by enumeration.
struct HidDeviceEntry {
  std::string path;  ///< e.g. /dev/hidraw3
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::uint16_t usage_page = 0;
  std::uint16_t usage = 0;
  std::string product;  ///< the product string, may be empty
};

/// An open HID device: reports in and out. Closed by its destructor.
class HidTransport {
 public:
  virtual ~HidTransport() = default;
  /// One input report (its first byte the report id) into buf, without waiting. Returns its
  /// size, 0 when none is pending, < 0 on an I/O error (removed). Servo thread: no allocation.
  virtual int readReport(std::span<std::uint8_t> buf) noexcept = 0;
  /// Sends one output report (first byte the report id). Returns the bytes written, < 0 on an
  /// I/O error. Servo thread: no allocation.
  virtual int writeReport(std::span<const std::uint8_t> report) noexcept = 0;
};

/// Finds and opens HID devices. Normal thread only.
class HidBackend {
 public:
  virtual ~HidBackend() = default;
  virtual std::vector<HidDeviceEntry> enumerate() = 0;
  virtual Result<std::unique_ptr<HidTransport>> open(const std::string& path) = 0;
};

/// The hidapi (hidraw) backend. Normal thread.
std::unique_ptr<HidBackend> makeHidapiBackend();

/// Which report layout a device speaks, from its ids (SpaceMouse table) or its usage page
/// (kGenericUsagePage). nullopt: neither.
std::optional<HidModel> hidModelOf(const HidDeviceEntry& entry);

/// The HID device. read()/write() on the servo thread; service() reopens a lost device.
class HidDevice final : public HotplugDevice {
 public:
  /// path: the device to use ("" = the first SpaceMouse or generic device found). Off the servo
  /// thread; fails when nothing suitable is found or it cannot be opened.
  static Result<std::unique_ptr<HidDevice>> open(std::unique_ptr<HidBackend> backend,
                                                 std::string_view path,
                                                 const DeviceOptions& options);

  const DeviceInfo& info() const override { return info_; }
  /// Drains pending input reports (at most kMaxReportsPerRead) and reports the latest pose.
  /// Generic: the device's pose, velocities by finite difference between reads. SpaceMouse: the
  /// speed-like values integrated into a pose (docs/devices.md). kLost at once while lost.
  /// Servo thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Generic: one output report with force and torque; SpaceMouse: nothing. Servo thread.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  /// Reopens a lost device when it is back. Normal thread.
  bool service() override;

  /// Input reports refused (wrong size, bad quaternion, unknown id) since open. Any thread.
  std::uint64_t badReports() const noexcept { return bad_reports_.load(); }

  static constexpr int kMaxReportsPerRead = 32;

 private:
  HidDevice(std::unique_ptr<HidBackend> backend,
            const HidDeviceEntry& entry,
            HidModel model,
            bool explicit_path,
            const DeviceOptions& options);
  void markLost() noexcept;

  std::unique_ptr<HidBackend> backend_;
  std::unique_ptr<HidTransport> transport_;  // used by the servo thread only while connected
  HidDeviceEntry entry_;
  HidModel model_;
  bool explicit_path_;
  DeviceOptions options_;
  DeviceInfo info_;
  std::atomic<std::uint64_t> bad_reports_{0};
  // servo-thread state
  SpaceMouseState spacemouse_;
  GenericInputReport last_input_;
  bool has_input_ = false;
  bool has_previous_ = false;
  double previous_t_s_ = 0.0;
  Pose previous_pose_;
  Vec3 velocity_{0.0};
  Vec3 angular_velocity_{0.0};
  std::uint16_t out_sequence_ = 0;
};

/// makeDevice("hid") / makeDevice("hid:PATH") with the hidapi backend. Off the servo thread.
Result<std::unique_ptr<Device>> makeHidDevice(std::string_view path, const DeviceOptions& options);

}  // namespace hapticd::device
