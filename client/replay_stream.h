#pragma once
/// \file
/// `hapticctl replay`'s view of a pose stream: the file read in the lenient dialect of
/// protocol/pose_stream.h (comments, blank lines, optional header and buttons; errors that name
/// file, line and what is wrong) and sampled with the stream's one interpolation, plus the
/// segment's velocities that a pose command carries. Any thread; no state.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "protocol/pose_stream.h"

namespace hapticd::client {

/// The stream at one time, with the velocities of its segment.
struct ReplaySample {
  double t_s = 0.0;           ///< seconds (stream time)
  geom::Pose X_WD;            ///< metres, scene frame, unit rotation
  std::uint32_t buttons = 0;  ///< bit mask
  geom::Vec3 v_W{0.0};        ///< segment velocity, m/s, scene frame
  geom::Vec3 w_W{0.0};        ///< segment angular velocity, rad/s, scene frame
};

/// A quaternion whose norm differs from 1 by more than this is refused (the protocol's bound).
inline constexpr double kPoseStreamQuatTolerance = 1e-3;

/// Parses `text` in the lenient dialect within kPoseStreamQuatTolerance; `name` is used in errors
/// ("NAME:LINE: what", "NAME: no rows").
Result<std::vector<proto::PoseStreamRow>> parseReplayStream(const std::string& text,
                                                            const std::string& name);

/// The stream at time t_s (proto::samplePoseStream: clamped to the first and last rows, lerp and
/// slerp between), and the velocities of the segment [i, i+1] that holds t_s (zero before the
/// first row and at and after the last). `hint` (optional) keeps the segment between calls.
ReplaySample sampleReplayStream(std::span<const proto::PoseStreamRow> rows,
                                double t_s,
                                std::size_t* hint = nullptr);

}  // namespace hapticd::client
