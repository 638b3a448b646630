#pragma once
/// \file
/// Pose streams, the CSV `t,px,py,pz,qx,qy,qz,qw,buttons` (t in seconds from 0, metres, scene
/// frame, glTF quaternion order, buttons a bit mask; docs/devices.md "replay:FILE"): the one
/// reader and the one interpolation of the project. The daemon's `replay:FILE` device,
/// `hapticctl replay`, the simulation's test harness and the tick benchmark all read and sample
/// their streams here, so a stream plays back the same everywhere.
///
/// Sampling: before (or at) the first row, the first row; between rows i and i+1 the position by
/// linear interpolation and the rotation by geom::slerp (shortest path) at
/// s = (t − t_i)/(t_{i+1} − t_i); at or after the last row, the last row. Buttons are those of the
/// row at or before t.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/result.h"
#include "core/geometry/pose.h"

namespace hapticd::proto {

/// One row of a pose stream, or a sample between rows.
struct PoseStreamRow {
  double t_s = 0.0;           ///< stream time, seconds
  geom::Pose X_WD;            ///< device pose: metres, scene frame, unit rotation (normalised)
  std::uint32_t buttons = 0;  ///< bit mask
};

/// The two grammars a stream is read with. Both check the same things (finite numbers, unit
/// quaternions within a tolerance, strictly increasing t, 32-bit buttons, at least one row) and
/// name the source and the line (from 1) in every error.
enum class PoseStreamDialect {
  /// The interface format, for the `replay:FILE` device, tests and benchmarks: the header exactly
  /// `t,px,py,pz,qx,qy,qz,qw,buttons`; 9 fields per row, no spaces; a leading `+` accepted on
  /// numbers; t ≥ 0; CRLF and trailing empty lines accepted, an empty line inside refused. Errors
  /// "SOURCE: line L, column C (name): what".
  kStrict,
  /// `hapticctl replay`: also '#' comments, blank lines, spaces around fields, no header (or one
  /// without `,buttons`), rows of 8 fields (buttons 0), any t. Errors "SOURCE:L: what".
  kLenient,
};

/// A larger stream is refused before it is read (about 15 million rows).
inline constexpr std::uintmax_t kMaxPoseStreamBytes = std::uintmax_t{1} << 30;

/// Parses a whole stream. `quat_tolerance`: a quaternion whose norm differs from 1 by more is
/// refused (the others are normalised). Any thread; allocates.
Result<std::vector<PoseStreamRow>> parsePoseStream(std::string_view text,
                                                   std::string_view source,
                                                   double quat_tolerance,
                                                   PoseStreamDialect dialect);

/// Reads a stream file whole. Errors (without the path; the caller names it): "cannot open the
/// file (missing or unreadable)", "not a regular file" (a directory, a device or a FIFO is
/// refused without reading it), "file larger than 1 GiB", "cannot read the file". Any thread.
Result<std::string> readPoseStreamFile(const std::string& path);

/// The stream at t_s (see the file comment); a NaN t_s reads as the first row. `cursor` (the
/// segment of the previous call, 0 at first) moves forward a few rows per call; a jump back or
/// far ahead falls back to a binary search. On return it is the segment i with
/// t_i ≤ t_s < t_{i+1}, or 0 before the first row and n − 1 at or after the last. `rows`
/// non-empty with t strictly increasing. No allocation: servo-thread safe.
PoseStreamRow samplePoseStream(std::span<const PoseStreamRow> rows,
                               double t_s,
                               std::size_t& cursor) noexcept;

}  // namespace hapticd::proto
