#pragma once
/// \file
/// The `replay:FILE` device: a pose stream (../shared/DESIGN.md "Pose streams") read and checked
/// whole at open, then played back at the loop's tick times with lerp (position) and slerp
/// (orientation) between rows.

#include <string>
#include <string_view>
#include <vector>

#include "daemon/device/device.h"

namespace hapticd::device {

/// One row of a pose stream.
struct PoseStreamRow {
  double t_s = 0.0;
  Pose X_WD;  ///< rotation normalised
  std::uint32_t buttons = 0;
};

/// Parses a whole pose stream CSV. The header must be exactly `t,px,py,pz,qx,qy,qz,qw,buttons`;
/// every field a finite number; t >= 0 and strictly increasing; quaternions within
/// quat_tolerance of unit length (normalised); buttons an unsigned 32-bit integer; at least one
/// row. CRLF line ends and a final newline are accepted. Errors name `source`, the line (from 1)
/// and the column (from 1, with its name). Any thread; allocates.
Result<std::vector<PoseStreamRow>> parsePoseStream(std::string_view text,
                                                   std::string_view source,
                                                   double quat_tolerance);

/// Plays rows back. Servo-thread calls allocate nothing.
class ReplayDevice final : public Device {
 public:
  /// rows: non-empty, checked by parsePoseStream. Off the servo thread.
  ReplayDevice(std::string name, std::vector<PoseStreamRow> rows, const DeviceOptions& options);

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
  const std::vector<PoseStreamRow>& rows() const { return rows_; }

 private:
  DeviceInfo info_;
  std::vector<PoseStreamRow> rows_;
  std::size_t cursor_ = 0;  ///< rows_[cursor_].t_s <= t < rows_[cursor_ + 1].t_s
  bool has_previous_ = false;
  double previous_t_s_ = 0.0;
  Pose previous_pose_;
};

/// Reads FILE, parses it (parsePoseStream) and opens the device. Off the servo thread.
Result<std::unique_ptr<Device>> makeReplayDevice(std::string_view file,
                                                 const DeviceOptions& options);

}  // namespace hapticd::device
