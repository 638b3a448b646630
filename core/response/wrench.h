#pragma once
/// \file
/// A force and a torque together (a wrench). Rotations (rotation vector, exponential map) and
/// finiteness checks are core/geometry/rotation.h's.

#include "core/geometry/pose.h"
#include "core/geometry/rotation.h"

namespace hapticd::response {

using geom::Quat;
using geom::Vec3;

/// A force (N) and a torque (N m) in one frame, the torque about a point the user names.
struct Wrench {
  Vec3 force_n{0.0};
  Vec3 torque_nm{0.0};
};

/// geom::finite under the name the output stage uses. Any thread.
inline bool isFinite(const Vec3& v) {
  return geom::finite(v);
}

}  // namespace hapticd::response
