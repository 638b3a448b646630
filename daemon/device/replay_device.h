#pragma once
/// \file
/// The `replay:FILE` device: a pose stream (protocol/pose_stream.h, the strict dialect) read and
/// checked whole at open, then played back at the loop's tick times with the stream's one
/// interpolation (lerp of the position, slerp of the orientation between rows).

#include <string>
#include <string_view>
#include <vector>

#include "daemon/device/device.h"
#include "protocol/pose_stream.h"

namespace hapticd::device {

/// Plays rows back. Servo-thread calls allocate nothing.
class ReplayDevice final : public Device {
 public:
  /// rows: non-empty, checked by proto::parsePoseStream. Off the servo thread.
  ReplayDevice(std::string name,
               std::vector<proto::PoseStreamRow> rows,
               const DeviceOptions& options);

  const DeviceInfo& info() const override { return info_; }
  /// The stream at t_s: before the first row, the first row; between rows, lerp/slerp; exactly at
  /// the last row, the last row; after it, kEndOfStream (out unchanged). Buttons: those of the
  /// row at or before t_s. Velocities: backward difference with the previous read (zero at the
  /// first read and when t_s does not advance). Servo thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Ignored (a replay displays nothing). Servo thread.
  DeviceStatus write(const Vec3&, const Vec3&) noexcept override { return DeviceStatus::kOk; }

  /// The interpolated pose at t_s (clamped to the stream's span); moves the cursor. Servo thread.
  Pose poseAt(double t_s, std::uint32_t* buttons = nullptr) noexcept;
  const std::vector<proto::PoseStreamRow>& rows() const { return rows_; }

 private:
  DeviceInfo info_;
  std::vector<proto::PoseStreamRow> rows_;
  std::size_t cursor_ = 0;  ///< rows_[cursor_].t_s <= t < rows_[cursor_ + 1].t_s
  bool has_previous_ = false;
  double previous_t_s_ = 0.0;
  Pose previous_pose_;
};

/// Reads FILE (proto::readPoseStreamFile), parses it (proto::parsePoseStream, strict, within
/// options.replay_quat_tolerance) and opens the device. Errors start "device 'replay:FILE': ".
/// Off the servo thread.
Result<std::unique_ptr<Device>> makeReplayDevice(std::string_view file,
                                                 const DeviceOptions& options);

}  // namespace hapticd::device
