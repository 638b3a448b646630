#pragma once
/// \file
/// Rotations as the whole project uses them: the rotation vector (axis * angle) and its
/// exponential, shortest-path slerp, and finiteness checks. Header-only, no allocation, any thread
/// (the servo thread included). This is the one copy; every layer above geometry includes it.

#include <bit>
#include <cmath>
#include <cstdint>

#include "core/geometry/pose.h"

namespace hapticd::geom {

/// True when every component of v is finite (no NaN, no infinity).
inline bool finite(const Vec3& v) noexcept {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// True when every component of q is finite.
inline bool finite(const Quat& q) noexcept {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

/// True when x and y are the same double bit for bit (not merely equal: -0 and 0 differ, a NaN
/// equals its own bits): a value computed from them is then the same too.
inline bool sameBits(double x, double y) noexcept {
  return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
}

/// sameBits for every component.
inline bool sameBits(const Vec3& a, const Vec3& b) noexcept {
  return sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z);
}
inline bool sameBits(const Quat& a, const Quat& b) noexcept {
  return sameBits(a.w, b.w) && sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z);
}
inline bool sameBits(const Mat3& a, const Mat3& b) noexcept {
  return sameBits(a[0], b[0]) && sameBits(a[1], b[1]) && sameBits(a[2], b[2]);
}

/// The rotation vector (axis * angle, radians, angle in [0, pi]) of a unit quaternion: the log
/// map, the shorter way round. Below 1e-12 of sin(angle/2) it is 2 * (x, y, z), exact to rounding.
inline Vec3 rotationVector(Quat q) noexcept {
  if (q.w < 0.0)
    q = -q;
  const Vec3 v{q.x, q.y, q.z};
  const double s = std::sqrt(glm::dot(v, v));
  if (s < 1e-12)
    return 2.0 * v;  // 2 * sin(a/2) * axis ~ a * axis
  return v * (2.0 * std::atan2(s, q.w) / s);
}

/// The unit quaternion of a rotation vector r (axis * angle, radians): the exponential map.
/// Below an angle of 1e-12 it is the normalised first-order quaternion.
inline Quat quatFromRotationVector(const Vec3& r) noexcept {
  const double angle = std::sqrt(glm::dot(r, r));
  if (angle < 1e-12)
    return glm::normalize(Quat(1.0, 0.5 * r.x, 0.5 * r.y, 0.5 * r.z));
  const double s = std::sin(0.5 * angle) / angle;
  return Quat(std::cos(0.5 * angle), r.x * s, r.y * s, r.z * s);
}

/// Shortest-path spherical interpolation between unit quaternions, s in [0, 1] (0: a, 1: b).
/// Near-parallel inputs (cos > 0.9999995) fall back to a normalised lerp.
inline Quat slerp(const Quat& a, Quat b, double s) noexcept {
  double c = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (c < 0.0) {
    b = -b;
    c = -c;
  }
  double wa = 1.0 - s;
  double wb = s;
  if (c < 0.9999995) {
    const double theta = std::acos(c);
    const double sin_theta = std::sin(theta);
    wa = std::sin((1.0 - s) * theta) / sin_theta;
    wb = std::sin(s * theta) / sin_theta;
  }
  const Quat q(wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z);
  return glm::normalize(q);
}

}  // namespace hapticd::geom
