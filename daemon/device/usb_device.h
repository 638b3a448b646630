#pragma once
/// \file
/// The `usb` device (libusb): the Novint Falcon (FTDI 0403:cb48) as a 3-DOF force device, with
/// hotplug arrival and removal. Bulk I/O goes through UsbTransport and device discovery through
/// UsbBackend so that tests drive a fake Falcon. Protocol and kinematics: falcon.h.

#include <atomic>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "daemon/device/connection.h"
#include "daemon/device/falcon.h"

namespace hapticd::device {

/// An open, configured Falcon: the FTDI's bulk endpoints with its modem status bytes removed.
/// Closed by its destructor.
class UsbTransport {
 public:
  virtual ~UsbTransport() = default;
  /// Bytes the Falcon sent since the last call, waiting at most the transport's short timeout
  /// (1 ms for libusb). Returns the count (0: none), < 0 on an I/O error (removed). Servo thread.
  virtual int read(std::span<std::uint8_t> buf) noexcept = 0;
  /// Sends bytes. Returns the count, < 0 on an I/O error. Servo thread.
  virtual int write(std::span<const std::uint8_t> bytes) noexcept = 0;
};

enum class UsbHotplugEvent : std::uint8_t { kArrived, kLeft };

/// Finds and opens Falcons and reports hotplug events. Normal thread only.
class UsbBackend {
 public:
  virtual ~UsbBackend() = default;
  /// Registers for arrival and removal of 0403:cb48; the callback runs inside handleEvents().
  /// false when the platform has no hotplug support (the device then polls countFalcons()).
  virtual bool startHotplug(std::function<void(UsbHotplugEvent)> callback) = 0;
  /// Dispatches pending events without waiting.
  virtual void handleEvents() = 0;
  /// How many Falcons are plugged in.
  virtual int countFalcons() = 0;
  /// Opens the first Falcon and configures its FTDI (docs/devices.md "usb").
  virtual Result<std::unique_ptr<UsbTransport>> open() = 0;
  /// Loads firmware into the first Falcon (falcon_firmware.h); no transport may be open.
  virtual Result<bool> loadFirmware(std::span<const std::uint8_t> firmware) = 0;
};

/// The libusb backend (own libusb context). Fails when libusb cannot initialise.
Result<std::unique_ptr<UsbBackend>> makeLibusbBackend();

/// The Falcon. read()/write() on the servo thread; service() handles hotplug and reconnects.
/// Opening (and every reconnection) probes the Falcon with a zero command; one that does not
/// answer within 100 ms gets usb_falcon_firmware loaded when it is set, else the open fails.
/// Pose: position in the device frame (origin at falcon::homePosition, x right, y up, z toward
/// the user), identity orientation; force only (torque ignored). Until the firmware reports all
/// three axes homed, forces are zero and the homing mode is on (the user moves the grip through
/// its range to home; the LED is red, then green).
class FalconDevice final : public HotplugDevice {
 public:
  /// Opens the Falcon through backend. Off the servo thread; fails when none is plugged in or
  /// it cannot be opened.
  static Result<std::unique_ptr<FalconDevice>> open(std::unique_ptr<UsbBackend> backend,
                                                    const DeviceOptions& options);
  ~FalconDevice() override;

  const DeviceInfo& info() const override { return info_; }
  /// Takes the Falcon's latest packet: encoders -> arm angles -> forward kinematics (warm-started).
  /// kLost at once after a removal, an I/O error, or no packet for usb_silence_lost_s. Servo
  /// thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Sends the motor commands for force_n (tau = J^T F; torque ignored). Servo thread.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  /// Hotplug events; reopens the Falcon when it is back. Normal thread.
  bool service() override;

  /// Whether the firmware reports every axis homed (servo thread's view). Any thread.
  bool homed() const noexcept { return homed_.load(std::memory_order_relaxed); }
  /// Malformed packets seen and forward kinematics solves that failed. Any thread.
  std::uint64_t malformedPackets() const noexcept { return malformed_.load(); }
  std::uint64_t kinematicsFailures() const noexcept { return fk_failures_.load(); }
  /// The last motor commands sent (servo thread's view; for tests).
  const std::array<std::int16_t, 3>& lastMotorCommands() const noexcept { return last_motor_; }

 private:
  FalconDevice(std::unique_ptr<UsbBackend> backend, const DeviceOptions& options);
  void markLost() noexcept;
  enum class Probe : std::uint8_t { kAnswered, kSilent, kOpenFailed };
  bool reopen();
  Probe openAndProbe();
  bool probe();

  std::unique_ptr<UsbBackend> backend_;
  std::unique_ptr<UsbTransport> transport_;  // servo thread only while connected
  DeviceOptions options_;
  DeviceInfo info_;
  falcon::Geometry geometry_;
  Vec3 home_F_;  // the workspace middle, Falcon frame
  bool hotplug_ = false;
  std::vector<std::uint8_t> firmware_;          // empty: never load
  std::string last_error_;                      // why the last reopen failed (normal thread)
  std::atomic<bool> removal_requested_{false};  // set by the hotplug callback
  std::atomic<bool> arrival_seen_{false};
  std::atomic<std::uint64_t> malformed_{0};
  std::atomic<std::uint64_t> fk_failures_{0};
  std::atomic<bool> homed_{false};
  // servo-thread state
  falcon::PacketReader reader_;
  bool fresh_ = true;  // no read since (re)connection
  double last_packet_t_s_ = 0.0;
  Vec3 p_F_;         // effector, Falcon frame
  Vec3 theta_{0.0};  // arm angles
  std::uint32_t buttons_ = 0;
  bool has_previous_ = false;
  double previous_t_s_ = 0.0;
  Vec3 previous_p_F_{0.0};
  Vec3 velocity_{0.0};
  std::array<std::int16_t, 3> last_motor_{};
};

/// makeDevice("usb") / makeDevice("usb:falcon") with the libusb backend. Off the servo thread.
Result<std::unique_ptr<Device>> makeUsbDevice(const DeviceOptions& options);

}  // namespace hapticd::device
