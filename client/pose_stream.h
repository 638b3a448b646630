#pragma once
/// \file
/// Pose streams (../shared/DESIGN.md "Pose streams"): the CSV `t,px,py,pz,qx,qy,qz,qw,buttons`
/// (t in seconds, metres, scene frame, glTF quaternion order, buttons a bit mask), parsed with
/// errors that name file, line and what is wrong, and sampled at any time: position by linear
/// interpolation, rotation by spherical linear interpolation along the shorter arc, buttons of
/// the row at or before the time. Used by `hapticctl replay`. Any thread; no state.

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"

namespace hapticd::client {

/// One row of a pose stream, or a sample between rows.
struct PoseSample {
  double t_s = 0.0;                               ///< seconds (stream time)
  std::array<double, 3> p_W{0.0, 0.0, 0.0};       ///< position, metres, scene frame
  std::array<double, 4> q_W{0.0, 0.0, 0.0, 1.0};  ///< unit quaternion x, y, z, w
  std::uint32_t buttons = 0;                      ///< bit mask
  std::array<double, 3> v_W{0.0, 0.0, 0.0};       ///< sample(): segment velocity, m/s
  std::array<double, 3> w_W{0.0, 0.0, 0.0};       ///< sample(): segment angular velocity, rad/s
};

/// A quaternion whose norm differs from 1 by more than this is refused (the protocol's bound).
inline constexpr double kPoseStreamQuatTolerance = 1e-3;

/// Parses a pose stream. `name` is used in errors ("NAME:LINE: what"). Blank lines and lines
/// starting with '#' are skipped; a header line (first field "t") must be exactly
/// `t,px,py,pz,qx,qy,qz,qw,buttons` (or without `,buttons`); buttons may be omitted per row (0).
/// Errors: a field that is not a finite number (or buttons not an unsigned 32-bit integer),
/// a wrong column count, t not strictly increasing, a quaternion whose norm is not 1 within
/// kPoseStreamQuatTolerance, no rows. Quaternions are renormalised to unit length.
Result<std::vector<PoseSample>> parsePoseStream(std::istream& in, const std::string& name);

/// q0 → q1 by the fraction u ∈ [0, 1] along the shorter great arc (q1 is negated when q0·q1 < 0;
/// nearly parallel quaternions fall back to normalised lerp). Unit input, unit output.
std::array<double, 4> slerp(const std::array<double, 4>& q0,
                            const std::array<double, 4>& q1,
                            double u);

/// The stream at time t_s (clamped to the first and last rows): exact at the rows; between rows
/// i and i+1 the lerp of p and slerp of q at u = (t − t_i)/(t_{i+1} − t_i), the buttons of row
/// i, and the segment's velocities (zero at and after the last row). `rows` non-empty, t strictly
/// increasing. `hint` (optional) keeps the segment index between calls with increasing t.
PoseSample samplePoseStream(std::span<const PoseSample> rows,
                            double t_s,
                            std::size_t* hint = nullptr);

}  // namespace hapticd::client
