#include "daemon/device/replay_device.h"

#include <cmath>

#include "core/geometry/rotation.h"

namespace hapticd::device {

ReplayDevice::ReplayDevice(std::string name,
                           std::vector<proto::PoseStreamRow> rows,
                           const DeviceOptions& options)
    : rows_(std::move(rows)) {
  info_.name = std::move(name);
  info_.capabilities = kCapPosition | kCapOrientation | kCapButtons | kCapEndOfStream;
  info_.limits = options.limits;
}

Pose ReplayDevice::poseAt(double t_s, std::uint32_t* buttons) noexcept {
  const proto::PoseStreamRow s = proto::samplePoseStream(rows_, t_s, cursor_);
  if (buttons)
    *buttons = s.buttons;
  return s.X_WD;
}

DeviceStatus ReplayDevice::read(double t_s, DeviceSample& out) noexcept {
  if (t_s > rows_.back().t_s)
    return DeviceStatus::kEndOfStream;
  if (std::isnan(t_s))
    t_s = has_previous_ ? previous_t_s_ : rows_.front().t_s;  // bad clock
  std::uint32_t buttons = 0;
  const Pose X = poseAt(t_s, &buttons);
  out.X_WD = X;
  out.buttons = buttons;
  if (has_previous_ && t_s > previous_t_s_) {
    const double dt = t_s - previous_t_s_;
    out.linear_velocity = (X.translation - previous_pose_.translation) / dt;
    out.angular_velocity =
        geom::rotationVector(X.rotation * glm::conjugate(previous_pose_.rotation)) / dt;
  } else {
    out.linear_velocity = Vec3(0.0);
    out.angular_velocity = Vec3(0.0);
  }
  has_previous_ = true;
  previous_t_s_ = t_s;
  previous_pose_ = X;
  return DeviceStatus::kOk;
}

Result<std::unique_ptr<Device>> makeReplayDevice(std::string_view file,
                                                 const DeviceOptions& options) {
  const std::string name = "replay:" + std::string(file);
  if (!(options.replay_quat_tolerance >= 0.0 && options.replay_quat_tolerance < 1.0))
    return Error{"device '" + name + "': replay_quat_tolerance must be in [0, 1)"};
  auto text = proto::readPoseStreamFile(std::string(file));
  if (!text)
    return Error{"device '" + name + "': " + text.error().message};
  auto rows = proto::parsePoseStream(text.value(), name, options.replay_quat_tolerance,
                                     proto::PoseStreamDialect::kStrict);
  if (!rows)
    return rows.error();
  return std::unique_ptr<Device>(
      std::make_unique<ReplayDevice>(name, std::move(rows).value(), options));
}

}  // namespace hapticd::device
