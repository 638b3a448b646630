#pragma once
/// \file
/// Closest points between points, segments and convex polygons (Ericson, "Real-Time Collision
/// Detection", 2005, §5.1). Internal to core/collision.

#include <algorithm>
#include <cmath>

#include "core/geometry/pose.h"

namespace hapticd::collision::detail {

using geom::Vec3;

/// Parameter in [0, 1] of the point of segment [p, q] closest to x.
inline double closestOnSegment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double dd = glm::dot(d, d);
  if (dd <= 0.0)
    return 0.0;
  return std::clamp(glm::dot(x - p, d) / dd, 0.0, 1.0);
}

struct SegmentPair {
  double s = 0.0, t = 0.0;  ///< parameters on the first and second segment
  Vec3 c1{0.0}, c2{0.0};    ///< the closest points
  double dist2 = 0.0;
};

/// Closest points of segments [p1, q1] and [p2, q2]; parallel segments give one of the pairs.
inline SegmentPair closestSegments(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  SegmentPair out;
  if (a <= 0.0 && e <= 0.0) {
    out.c1 = p1, out.c2 = p2;
  } else if (a <= 0.0) {
    out.t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = glm::dot(d1, r);
    if (e <= 0.0) {
      out.s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = glm::dot(d1, d2);
      const double denom = a * e - b * b;
      out.s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      out.t = (b * out.s + f) / e;
      if (out.t < 0.0) {
        out.t = 0.0;
        out.s = std::clamp(-c / a, 0.0, 1.0);
      } else if (out.t > 1.0) {
        out.t = 1.0;
        out.s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  out.c1 = p1 + d1 * out.s;
  out.c2 = p2 + d2 * out.t;
  const Vec3 diff = out.c1 - out.c2;
  out.dist2 = glm::dot(diff, diff);
  return out;
}

}  // namespace hapticd::collision::detail
