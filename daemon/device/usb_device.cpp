#include "daemon/device/usb_device.h"

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "daemon/device/falcon_firmware.h"

namespace hapticd::device {

namespace {
// how long a Falcon has to answer a probe at open
constexpr auto kProbeTimeout = std::chrono::milliseconds(100);
}  // namespace

FalconDevice::FalconDevice(std::unique_ptr<UsbBackend> backend, const DeviceOptions& options)
    : backend_(std::move(backend)), options_(options) {
  info_.name = "usb 0403:cb48 Novint Falcon";
  info_.capabilities = kCapPosition | kCapForce | kCapButtons;
  info_.limits = options.limits;
  home_F_ = falcon::homePosition(geometry_);
  p_F_ = home_F_;
  falcon::inverseKinematics(geometry_, p_F_, theta_);
}

FalconDevice::~FalconDevice() = default;

Result<std::unique_ptr<FalconDevice>> FalconDevice::open(std::unique_ptr<UsbBackend> backend,
                                                         const DeviceOptions& options) {
  if (!(std::isfinite(options.usb_silence_lost_s) && options.usb_silence_lost_s > 0.0))
    return Error{"device 'usb:falcon': usb_silence_lost_s must be a finite number > 0"};
  if (options.usb_falcon_max_motor_command < 0 || options.usb_falcon_max_motor_command > 32767)
    return Error{"device 'usb:falcon': usb_falcon_max_motor_command must be in [0, 32767]"};
  std::vector<std::uint8_t> firmware;
  if (!options.usb_falcon_firmware.empty()) {
    const std::string& path = options.usb_falcon_firmware;
    const std::string what = "device 'usb:falcon': usb_falcon_firmware '" + path + "': ";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      return Error{what + "not a regular file (missing?)"};
    const auto size = std::filesystem::file_size(path, ec);
    if (ec || size == 0 || size > falcon::kMaxFirmwareBytes)
      return Error{what + "empty, unreadable, or larger than 1 MiB"};
    std::ifstream in(path, std::ios::binary);
    firmware.resize(static_cast<std::size_t>(size));
    if (!in.read(reinterpret_cast<char*>(firmware.data()), static_cast<std::streamsize>(size)))
      return Error{what + "cannot read the file"};
  }
  if (backend->countFalcons() == 0)
    return Error{
        "device 'usb:falcon': no device found (no USB device 0403:cb48; is the Falcon "
        "plugged in and powered?)"};
  std::unique_ptr<FalconDevice> dev(new FalconDevice(std::move(backend), options));
  dev->firmware_ = std::move(firmware);
  FalconDevice* self = dev.get();
  dev->hotplug_ = dev->backend_->startHotplug([self](UsbHotplugEvent e) {
    if (e == UsbHotplugEvent::kLeft)
      self->removal_requested_.store(true);
    else
      self->arrival_seen_.store(true);
  });
  dev->link_.markClosed();
  if (!dev->reopen())
    return Error{"device 'usb:falcon': " + dev->last_error_};
  return dev;
}

void FalconDevice::markLost() noexcept {
  link_.markLost();
  homed_.store(false, std::memory_order_relaxed);
}

bool FalconDevice::probe() {
  // a zero command; the firmware answers each command with one packet
  falcon::OutPacket zero;
  zero.homing_mode = true;
  zero.leds = falcon::kLedRed;
  std::array<std::uint8_t, falcon::kPacketSize> bytes{};
  falcon::encodeOut(zero, bytes);
  if (transport_->write(bytes) < 0)
    return false;
  falcon::PacketReader reader;
  std::array<std::uint8_t, 64> buf{};
  const auto deadline = std::chrono::steady_clock::now() + kProbeTimeout;
  while (std::chrono::steady_clock::now() < deadline) {
    const int n = transport_->read(buf);
    if (n < 0)
      return false;
    if (n == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    if (reader.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n))) > 0)
      return true;
  }
  return false;
}

FalconDevice::Probe FalconDevice::openAndProbe() {
  transport_.reset();
  auto t = backend_->open();
  if (!t) {
    last_error_ = "cannot open the Falcon: " + t.error().message +
                  " (permissions? see docs/devices.md, udev)";
    return Probe::kOpenFailed;
  }
  transport_ = std::move(t).value();
  if (probe())
    return Probe::kAnswered;
  transport_.reset();
  return Probe::kSilent;
}

bool FalconDevice::reopen() {
  Probe p = openAndProbe();
  if (p == Probe::kOpenFailed)
    return false;
  if (p == Probe::kSilent) {
    if (firmware_.empty()) {
      last_error_ =
          "the Falcon does not answer: its firmware is not loaded (set usb_falcon_firmware to the "
          "Novint firmware file, or load it with another tool)";
      return false;
    }
    if (auto loaded = backend_->loadFirmware(firmware_); !loaded) {
      last_error_ = loaded.error().message;
      return false;
    }
    p = openAndProbe();
    if (p == Probe::kOpenFailed)
      return false;
    if (p == Probe::kSilent) {
      last_error_ = "the Falcon does not answer after its firmware was loaded";
      return false;
    }
  }
  last_error_.clear();
  // prime: the first servo read then has a packet
  falcon::OutPacket zero;
  zero.homing_mode = true;
  zero.leds = falcon::kLedRed;
  std::array<std::uint8_t, falcon::kPacketSize> bytes{};
  falcon::encodeOut(zero, bytes);
  if (transport_->write(bytes) < 0) {
    transport_.reset();
    last_error_ = "write to the Falcon failed";
    return false;
  }
  reader_ = falcon::PacketReader{};
  fresh_ = true;
  has_previous_ = false;
  velocity_ = Vec3(0.0);
  removal_requested_.store(false);
  arrival_seen_.store(false);
  link_.markConnected();
  return true;
}

DeviceStatus FalconDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  if (removal_requested_.load(std::memory_order_acquire)) {
    markLost();
    return DeviceStatus::kLost;
  }
  if (fresh_) {
    fresh_ = false;
    last_packet_t_s_ = t_s;
  }
  std::array<std::uint8_t, 64> buf{};
  int packets = 0;
  // drain what is there (a few chunks at most per tick)
  for (int i = 0; i < 4; ++i) {
    const int n = transport_->read(buf);
    if (n < 0) {
      markLost();
      return DeviceStatus::kLost;
    }
    if (n == 0)
      break;
    const std::uint64_t bad_before = reader_.malformed();
    packets += reader_.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    malformed_.fetch_add(reader_.malformed() - bad_before, std::memory_order_relaxed);
  }
  if (packets > 0) {
    last_packet_t_s_ = t_s;
    const falcon::InPacket& p = reader_.latest();
    const Vec3 theta(falcon::encoderToAngle(p.encoders[0]), falcon::encoderToAngle(p.encoders[1]),
                     falcon::encoderToAngle(p.encoders[2]));
    Vec3 pos;
    if (falcon::forwardKinematics(geometry_, theta, p_F_, pos) == falcon::FkStatus::kConverged) {
      p_F_ = pos;
      theta_ = theta;
    } else {
      fk_failures_.fetch_add(1, std::memory_order_relaxed);
    }
    buttons_ = p.buttons;
    homed_.store(p.homing_status == 7, std::memory_order_relaxed);
  } else if (t_s - last_packet_t_s_ > options_.usb_silence_lost_s) {
    markLost();
    return DeviceStatus::kLost;
  }
  if (has_previous_ && t_s > previous_t_s_) {
    velocity_ = (p_F_ - previous_p_F_) / (t_s - previous_t_s_);
  }
  has_previous_ = true;
  previous_t_s_ = t_s;
  previous_p_F_ = p_F_;
  out.X_WD = Pose{p_F_ - home_F_, geom::Quat(1.0, 0.0, 0.0, 0.0)};
  out.linear_velocity = velocity_;
  out.angular_velocity = Vec3(0.0);
  out.buttons = buttons_;
  return DeviceStatus::kOk;
}

DeviceStatus FalconDevice::write(const Vec3& force_n, const Vec3& /*torque_nm*/) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  falcon::OutPacket cmd;
  const bool homed = homed_.load(std::memory_order_relaxed);
  if (homed) {
    cmd.motor = falcon::motorCommands(geometry_, p_F_, theta_, force_n,
                                      options_.usb_falcon_max_motor_command);
    cmd.leds = falcon::kLedGreen;
  } else {
    cmd.homing_mode = true;
    cmd.leds = falcon::kLedRed;
  }
  last_motor_ = cmd.motor;
  std::array<std::uint8_t, falcon::kPacketSize> bytes{};
  falcon::encodeOut(cmd, bytes);
  if (transport_->write(bytes) < 0) {
    markLost();
    return DeviceStatus::kLost;
  }
  return DeviceStatus::kOk;
}

bool FalconDevice::service() {
  backend_->handleEvents();
  if (!hotplug_ && link_.connected() && backend_->countFalcons() == 0)
    removal_requested_.store(true);  // polling stands in for the removal event
  if (link_.connected())
    return true;
  // lost: the servo thread no longer touches the transport
  transport_.reset();
  const bool present = hotplug_ ? (arrival_seen_.load() || backend_->countFalcons() > 0)
                                : backend_->countFalcons() > 0;
  if (!present)
    return false;
  return reopen();
}

Result<std::unique_ptr<Device>> makeUsbDevice(const DeviceOptions& options) {
  auto backend = makeLibusbBackend();
  if (!backend)
    return Error{"device 'usb:falcon': " + backend.error().message};
  auto d = FalconDevice::open(std::move(backend).value(), options);
  if (!d)
    return d.error();
  return std::unique_ptr<Device>(std::move(d).value());
}

}  // namespace hapticd::device
