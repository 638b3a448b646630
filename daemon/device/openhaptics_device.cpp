#include "daemon/device/openhaptics_device.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace hapticd::device {

namespace {
// errors taken from HD's stack per call at most (it is bounded; a flood is not drained forever)
constexpr int kMaxErrorsPerDrain = 8;
// while lost, the callback probes the device every this many ticks
constexpr std::uint64_t kProbeEveryTicks = 100;

bool isLoss(unsigned int code) {
  return code == hd::kCommError || code == hd::kCommConfigError;
}

std::string hex(unsigned int code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", code);
  return buf;
}
}  // namespace

OpenHapticsDevice::OpenHapticsDevice(const hd::Api& api, const DeviceOptions& options)
    : api_(api), options_(options) {}

OpenHapticsDevice::~OpenHapticsDevice() {
  if (device_ != hd::kInvalidHandle)
    api_.disableDevice(device_);
}

Result<std::unique_ptr<OpenHapticsDevice>> OpenHapticsDevice::open(const hd::Api& api,
                                                                   const std::string& name,
                                                                   const DeviceOptions& options) {
  const std::string spec = name.empty() ? "openhaptics" : "openhaptics:" + name;
  const std::string what = "device '" + spec + "': ";
  std::unique_ptr<OpenHapticsDevice> dev(new OpenHapticsDevice(api, options));
  const hd::HHD h = api.initDevice(name.empty() ? nullptr : name.c_str());
  const hd::ErrorInfo e = api.getError();
  if (h == hd::kInvalidHandle || e.error_code != hd::kSuccess)
    return Error{what + "cannot initialise the device (HD error " + hex(e.error_code) +
                 "; is it plugged in, its driver installed and configured with the vendor's "
                 "setup tool" +
                 (name.empty() ? "" : ", and is '" + name + "' its configured name") + "?)"};
  dev->device_ = h;
  api.makeCurrentDevice(h);
  api.enable(hd::kForceOutput);
  DeviceInfo& info = dev->info_;
  const char* model = api.getString(hd::kDeviceModelType);
  const char* serial = api.getString(hd::kDeviceSerialNumber);
  info.model = model != nullptr && *model != '\0' ? model : "unknown model";
  info.serial = serial != nullptr ? serial : "";
  int in_dof = 0, out_dof = 0;
  api.getIntegerv(hd::kInputDof, &in_dof);
  api.getIntegerv(hd::kOutputDof, &out_dof);
  info.sensing_dof = in_dof;
  info.force_dof = out_dof;
  dev->torque_out_ = out_dof >= 6;
  info.name = spec + " " + info.model;
  info.capabilities = kCapPosition | kCapOrientation | kCapForce | kCapButtons |
                      (dev->torque_out_ ? kCapTorque : 0u);
  info.limits = options.limits;
  double max_force_n = 0.0, max_torque_mnm = 0.0;
  api.getDoublev(hd::kNominalMaxContinuousForce, &max_force_n);
  if (max_force_n > 0.0)
    info.limits.max_force_n = std::min(info.limits.max_force_n, max_force_n);
  if (dev->torque_out_) {
    api.getDoublev(hd::kNominalMaxTorqueContinuousForce, &max_torque_mnm);
    if (max_torque_mnm > 0.0)
      info.limits.max_torque_nm = std::min(info.limits.max_torque_nm, max_torque_mnm * 1e-3);
  } else {
    info.limits.max_torque_nm = 0.0;
  }
  if (const hd::ErrorInfo q = api.getError(); q.error_code != hd::kSuccess)
    return Error{what + "the device did not answer its queries (HD error " + hex(q.error_code) +
                 ")"};
  return dev;
}

DeviceStatus OpenHapticsDevice::drainErrors() noexcept {
  DeviceStatus s = DeviceStatus::kOk;
  for (int i = 0; i < kMaxErrorsPerDrain; ++i) {
    const hd::ErrorInfo e = api_.getError();
    if (e.error_code == hd::kSuccess)
      break;
    if (isLoss(e.error_code))
      s = DeviceStatus::kLost;
    else if (s == DeviceStatus::kOk)
      s = DeviceStatus::kFault;
  }
  if (s == DeviceStatus::kLost && link_.connected())
    link_.markLost();
  if (s == DeviceStatus::kFault)
    faults_.fetch_add(1, std::memory_order_relaxed);
  return s;
}

DeviceStatus OpenHapticsDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  if (rearm_pending_.exchange(false, std::memory_order_acq_rel)) {
    velocity_.reset();
    fault_pending_ = true;  // back after a loss: the loop latches a fault...
    held_ = true;           // ...and nothing is displayed until it is re-armed
  }
  double m[16];
  int buttons = 0;
  api_.getDoublev(hd::kCurrentTransform, m);
  api_.getIntegerv(hd::kCurrentButtons, &buttons);
  const int calibration = api_.checkCalibration();
  DeviceStatus status = drainErrors();
  if (status == DeviceStatus::kLost)
    return status;
  if (status == DeviceStatus::kOk) {
    // column-major 4x4 (as OpenGL), translation in millimetres
    geom::Mat3 R(1.0);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        R[c][r] = m[4 * c + r];
    last_X_ = Pose{Vec3(m[12], m[13], m[14]) * 1e-3, glm::normalize(glm::quat_cast(R))};
    buttons_ = static_cast<std::uint32_t>(buttons);
  }
  calibration_.store(calibration, std::memory_order_relaxed);
  if (calibration != hd::kCalibrationOk) {
    uncalibrated_.fetch_add(1, std::memory_order_relaxed);
    status = DeviceStatus::kFault;
  }
  if (fault_pending_) {
    fault_pending_ = false;
    status = DeviceStatus::kFault;
  }
  velocity_.update(t_s, last_X_, out.linear_velocity, out.angular_velocity);
  out.X_WD = last_X_;
  out.buttons = buttons_;
  return status;
}

DeviceStatus OpenHapticsDevice::write(const Vec3& force_n, const Vec3& torque_nm) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  double f[3] = {0.0, 0.0, 0.0};
  double t[3] = {0.0, 0.0, 0.0};
  if (!held_) {
    f[0] = force_n.x;
    f[1] = force_n.y;
    f[2] = force_n.z;
    if (torque_out_) {
      t[0] = torque_nm.x * 1e3;  // the API's gimbal torque is in mN m
      t[1] = torque_nm.y * 1e3;
      t[2] = torque_nm.z * 1e3;
    } else if (torque_nm != Vec3(0.0)) {
      torque_dropped_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  api_.setDoublev(hd::kCurrentForce, f);
  if (torque_out_)
    api_.setDoublev(hd::kCurrentGimbalTorque, t);
  const DeviceStatus s = drainErrors();
  if (s == DeviceStatus::kFault)
    fault_pending_ = true;
  return s;
}

unsigned int OpenHapticsDevice::callback(void* self) noexcept {
  auto* d = static_cast<OpenHapticsDevice*>(self);
  d->api_.beginFrame(d->device_);
  const bool more = d->tick_(d->tick_context_);
  if (!d->link_.connected()) {
    // lost: nothing is displayed, the errors that brings are taken off HD's stack, and now and
    // then the device is asked whether it answers again
    const double zero[3] = {0.0, 0.0, 0.0};
    d->api_.setDoublev(hd::kCurrentForce, zero);
    bool answered = true;
    if (++d->lost_ticks_ % kProbeEveryTicks == 0) {
      double m[16];
      d->api_.getDoublev(hd::kCurrentTransform, m);
    } else {
      answered = false;
    }
    for (int i = 0; i < kMaxErrorsPerDrain && d->api_.getError().error_code != hd::kSuccess; ++i)
      answered = false;
    if (answered)
      d->probe_ok_.store(true, std::memory_order_release);
  }
  d->api_.endFrame(d->device_);
  if (d->link_.connected() && d->drainErrors() == DeviceStatus::kFault)
    d->fault_pending_ = true;
  if (!more) {
    d->done_.store(true, std::memory_order_release);
    return hd::kCallbackDone;
  }
  return hd::kCallbackContinue;
}

bool OpenHapticsDevice::runClocked(ClockedTick tick, void* context) noexcept {
  tick_ = tick;
  tick_context_ = context;
  done_.store(false, std::memory_order_relaxed);
  const unsigned long handle =
      api_.scheduleAsynchronous(&callback, this, hd::kMaxSchedulerPriority);
  api_.startScheduler();
  if (api_.getError().error_code != hd::kSuccess) {
    // the scheduler did not start: the loop runs on its own clock with the device lost
    api_.unschedule(handle);
    link_.markLost();
    return false;
  }
  while (!done_.load(std::memory_order_acquire))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  api_.stopScheduler();
  api_.unschedule(handle);
  return true;
}

bool OpenHapticsDevice::service() {
  if (link_.connected())
    return true;
  if (!probe_ok_.exchange(false, std::memory_order_acq_rel))
    return false;
  rearm_pending_.store(true, std::memory_order_relaxed);
  link_.markConnected();
  return true;
}

Result<std::unique_ptr<Device>> makeOpenHapticsDevice(const std::string& name,
                                                      const DeviceOptions& options) {
  auto api = hd::loadApi(options.openhaptics_library);
  if (!api)
    return Error{"device '" + std::string(name.empty() ? "openhaptics" : "openhaptics:" + name) +
                 "': " + api.error().message};
  auto d = OpenHapticsDevice::open(api.value(), name, options);
  if (!d)
    return d.error();
  return std::unique_ptr<Device>(std::move(d).value());
}

}  // namespace hapticd::device
