#include "daemon/device/forcedimension_device.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hapticd::device {

namespace {

// The nominal continuous force and torque of each model, from Force Dimension's published
// product specifications (not measured here); 0 torque: no active wrist. Unknown models keep the
// configured limits.
struct ModelLimits {
  int type;
  double force_n;
  double torque_nm;
};
constexpr ModelLimits kModelLimits[] = {
    {dhd::kFalcon, 8.9, 0.0},       {dhd::kDelta3, 20.0, 0.0},       {dhd::kDelta6, 20.0, 0.15},
    {dhd::kOmega3, 12.0, 0.0},      {dhd::kOmega33, 12.0, 0.0},      {dhd::kOmega33Left, 12.0, 0.0},
    {dhd::kOmega331, 12.0, 0.0},    {dhd::kOmega331Left, 12.0, 0.0}, {dhd::kSigma331, 20.0, 0.4},
    {dhd::kSigma331Left, 20.0, 0.4}};

// hapticd's device frame (x right, y up, z toward the user) from the SDK's base frame (x toward
// the user, y right, z up): a cyclic permutation of the axes, a proper rotation
Vec3 fromDhd(double x, double y, double z) noexcept {
  return Vec3(y, z, x);
}

geom::Quat orientationFromDhd(const double m[3][3]) noexcept {
  // R_D = P R P^T with P the permutation above; glm matrices are indexed [column][row]
  constexpr int kFrom[3] = {1, 2, 0};  // device axis i is SDK axis kFrom[i]
  geom::Mat3 R(1.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      R[c][r] = m[kFrom[r]][kFrom[c]];
  return glm::normalize(glm::quat_cast(R));
}

}  // namespace

ForceDimensionDevice::ForceDimensionDevice(const dhd::Api& api,
                                           int index,
                                           const DeviceOptions& options)
    : api_(api), index_(index), options_(options) {}

ForceDimensionDevice::~ForceDimensionDevice() {
  if (link_.connected() && id_ >= 0) {
    api_.setBrakes(dhd::kOn, id_);
    api_.close(id_);
  }
}

Result<std::unique_ptr<ForceDimensionDevice>>
ForceDimensionDevice::open(const dhd::Api& api, int index, const DeviceOptions& options) {
  const std::string what = "device 'forcedimension:" + std::to_string(index) + "': ";
  const int count = api.getDeviceCount();
  if (count <= index)
    return Error{what + "no device found at index " + std::to_string(index) + " (the SDK sees " +
                 std::to_string(std::max(count, 0)) +
                 "; is it plugged in, powered and allowed by udev?)"};
  std::unique_ptr<ForceDimensionDevice> dev(new ForceDimensionDevice(api, index, options));
  dev->link_.markClosed();
  std::string error;
  if (!dev->reopen(error, false))
    return Error{what + error};
  // what the device is: asked once (the same device comes back after a reconnection)
  const char id = dev->id_;
  const int type = api.getSystemType(id);
  const char* name = api.getSystemName(id);
  unsigned short serial = 0;
  DeviceInfo& info = dev->info_;
  info.model = name != nullptr && *name != '\0' ? name : "type " + std::to_string(type);
  if (api.isLeftHanded(id))
    info.model += " (left-handed)";
  info.serial = api.getSerialNumber(&serial, id) >= 0 ? std::to_string(serial) : "";
  info.name = "forcedimension:" + std::to_string(index) + " " + info.model;
  dev->has_wrist_ = api.hasWrist(id);
  dev->active_wrist_ = api.hasActiveWrist(id);
  dev->has_gripper_ = api.hasGripper(id);
  dev->active_gripper_ = api.hasActiveGripper(id);
  info.sensing_dof = 3 + (dev->has_wrist_ ? 3 : 0) + (dev->has_gripper_ ? 1 : 0);
  info.force_dof = 3 + (dev->active_wrist_ ? 3 : 0) + (dev->active_gripper_ ? 1 : 0);
  info.capabilities = kCapPosition | kCapForce | kCapButtons |
                      (dev->has_wrist_ ? kCapOrientation : 0u) |
                      (dev->active_wrist_ ? kCapTorque : 0u);
  info.limits = options.limits;
  for (const ModelLimits& m : kModelLimits) {
    if (m.type != type)
      continue;
    info.limits.max_force_n = std::min(info.limits.max_force_n, m.force_n);
    info.limits.max_torque_nm = std::min(info.limits.max_torque_nm, m.torque_nm);
  }
  if (!dev->active_wrist_)
    info.limits.max_torque_nm = 0.0;
  return dev;
}

bool ForceDimensionDevice::reopen(std::string& error, bool after_loss) {
  const int id = api_.openID(static_cast<char>(index_));
  if (id < 0) {
    const char* e = api_.errorGetLastStr();
    error = "cannot open the device: " + std::string(e != nullptr ? e : "unknown error");
    return false;
  }
  id_ = static_cast<char>(id);
  // the SDK's gravity compensation, and its brakes until the loop's output goes live
  if (api_.setGravityCompensation(dhd::kOn, id_) < 0 || api_.setBrakes(dhd::kOn, id_) < 0) {
    const char* e = api_.errorGetLastStr();
    error = "cannot set gravity compensation and brakes: " +
            std::string(e != nullptr ? e : "unknown error");
    api_.close(id_);
    return false;
  }
  forces_on_.store(false, std::memory_order_relaxed);
  fault_pending_ = false;
  velocity_.reset();
  // back after a loss: braked until the loop is re-armed (the first read reports a fault)
  rearm_pending_.store(after_loss, std::memory_order_relaxed);
  link_.markConnected();
  return true;
}

DeviceStatus ForceDimensionDevice::failure() noexcept {
  if (dhd::isLoss(api_.errorGetLast())) {
    forces_on_.store(false, std::memory_order_relaxed);
    link_.markLost();
    return DeviceStatus::kLost;
  }
  faults_.fetch_add(1, std::memory_order_relaxed);
  return DeviceStatus::kFault;
}

DeviceStatus ForceDimensionDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  DeviceStatus status = DeviceStatus::kOk;
  double x = 0.0, y = 0.0, z = 0.0;
  double frame[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  double gripper = gripper_rad_;
  if (api_.getPosition(&x, &y, &z, id_) < 0 ||
      (has_wrist_ && api_.getOrientationFrame(frame, id_) < 0) ||
      (has_gripper_ && api_.getGripperAngleRad(&gripper, id_) < 0)) {
    status = failure();
    if (status == DeviceStatus::kLost)
      return status;
  } else {
    last_X_ = Pose{fromDhd(x, y, z), orientationFromDhd(frame)};
    gripper_rad_ = gripper;
    buttons_ = api_.getButtonMask(id_);
  }
  if (fault_pending_ || rearm_pending_.exchange(false, std::memory_order_acq_rel)) {
    fault_pending_ = false;
    status = DeviceStatus::kFault;
  }
  velocity_.update(t_s, last_X_, out.linear_velocity, out.angular_velocity);
  out.X_WD = last_X_;
  out.buttons = buttons_;
  out.gripper_rad = gripper_rad_;
  return status;
}

DeviceStatus ForceDimensionDevice::write(const Vec3& force_n, const Vec3& torque_nm) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  if (!forces_on_.load(std::memory_order_relaxed))
    return DeviceStatus::kOk;  // braked: nothing to display
  Vec3 torque = torque_nm;
  if (!active_wrist_) {
    if (torque != Vec3(0.0))
      torque_dropped_.fetch_add(1, std::memory_order_relaxed);
    torque = Vec3(0.0);
  }
  // back to the SDK's frame: (x, y, z)_SDK = (z, x, y)_device; no gripper force (the simulation
  // has no gripper degree of freedom)
  const int r = api_.setForceAndTorqueAndGripperForce(force_n.z, force_n.x, force_n.y, torque.z,
                                                      torque.x, torque.y, 0.0, id_);
  if (r == dhd::kMotorSaturated)
    saturations_.fetch_add(1, std::memory_order_relaxed);
  if (r >= 0)
    return DeviceStatus::kOk;
  const DeviceStatus s = failure();
  if (s == DeviceStatus::kFault)
    fault_pending_ = true;
  return s;
}

void ForceDimensionDevice::setOutputHeld(bool held) noexcept {
  if (!link_.connected())
    return;
  const bool on = forces_on_.load(std::memory_order_relaxed);
  if (held && on) {
    forces_on_.store(false, std::memory_order_relaxed);
    if (api_.setBrakes(dhd::kOn, id_) < 0 && failure() == DeviceStatus::kFault)
      fault_pending_ = true;
  } else if (!held && !on) {
    if (api_.enableForce(static_cast<unsigned char>(dhd::kOn), id_) < 0) {
      if (failure() == DeviceStatus::kFault)
        fault_pending_ = true;
      return;
    }
    forces_on_.store(true, std::memory_order_relaxed);
  }
}

bool ForceDimensionDevice::service() {
  if (link_.connected())
    return true;
  // lost: the servo thread no longer calls the SDK for this device
  if (id_ >= 0) {
    api_.close(id_);
    id_ = -1;
  }
  if (api_.getDeviceCount() <= index_)
    return false;
  std::string error;
  return reopen(error, true);
}

Result<std::unique_ptr<Device>> makeForceDimensionDevice(int index, const DeviceOptions& options) {
  auto api = dhd::loadApi(options.forcedimension_library);
  if (!api)
    return Error{"device 'forcedimension:" + std::to_string(index) + "': " + api.error().message};
  auto d = ForceDimensionDevice::open(api.value(), index, options);
  if (!d)
    return d.error();
  return std::unique_ptr<Device>(std::move(d).value());
}

}  // namespace hapticd::device
