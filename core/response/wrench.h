#pragma once
/// \file
/// A force and a torque together (a wrench), and the small vector helpers of the response.

#include <cmath>

#include "core/geometry/pose.h"

namespace hapticd::response {

using geom::Quat;
using geom::Vec3;

/// A force (N) and a torque (N m) in one frame, the torque about a point the user names.
struct Wrench {
  Vec3 force_n{0.0};
  Vec3 torque_nm{0.0};
};

/// The rotation vector (axis * angle, radians, |angle| <= pi) of a unit quaternion. Any thread.
inline Vec3 rotationVector(const Quat& q_in) {
  const Quat q = q_in.w < 0.0 ? -q_in : q_in;  // the shorter way round
  const Vec3 v{q.x, q.y, q.z};
  const double s = std::sqrt(glm::dot(v, v));
  if (s < 1e-12)
    return 2.0 * v;  // small angles: 2 * sin(a/2) * axis ~ a * axis
  const double angle = 2.0 * std::atan2(s, q.w);
  return v * (angle / s);
}

/// The unit quaternion of a rotation vector (axis * angle). Any thread.
inline Quat quatFromRotationVector(const Vec3& w) {
  const double angle = std::sqrt(glm::dot(w, w));
  if (angle < 1e-12)
    return glm::normalize(Quat(1.0, 0.5 * w.x, 0.5 * w.y, 0.5 * w.z));
  const double s = std::sin(0.5 * angle) / angle;
  return Quat(std::cos(0.5 * angle), w.x * s, w.y * s, w.z * s);
}

inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace hapticd::response
