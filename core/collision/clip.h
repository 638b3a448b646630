#pragma once
/// \file
/// Sutherland-Hodgman clipping of a convex polygon or a segment against one plane (Sutherland and
/// Hodgman, "Reentrant Polygon Clipping", CACM 1974), shared by the contact manifold and the
/// penetration depth's witness search. Internal to core/collision.

#include <algorithm>
#include <cstddef>

#include "core/geometry/pose.h"

namespace hapticd::collision::detail {

/// Appends to `out` (by out.push) the part of `in` with (x - o)·m >= -tol: `in` (a type with
/// points p[0..n) and push) is a closed polygon, or a segment when it has 2 points, or a point
/// when it has 1. The tolerance keeps an overlap that has no area (two faces meeting along an
/// edge): rounding would put its points on either side of the plane. A vertex within the
/// tolerance outside is kept where it is; an edge that crosses the plane is cut where it crosses
/// the plane itself (not the plane moved out by the tolerance), at an end when it does not cross
/// it within the edge. `out` is not cleared. No allocation; any thread.
template <class Polygon>
inline void clipAgainstPlane(const Polygon& in,
                             const geom::Vec3& o,
                             const geom::Vec3& m,
                             double tol,
                             Polygon& out) {
  if (in.n == 0)
    return;
  const std::size_t edges = in.n == 2 ? 1 : in.n;  // a segment is not closed
  double da = glm::dot(in.p[0] - o, m);            // each vertex's distance, once
  for (std::size_t k = 0; k < edges; ++k) {
    const geom::Vec3& a = in.p[k];
    const geom::Vec3& b = in.p[(k + 1) % in.n];
    const double db = glm::dot(b - o, m);
    if (da + tol >= 0.0)
      out.push(a);
    if ((da + tol >= 0.0) != (db + tol >= 0.0))
      out.push(a + (b - a) * std::clamp(da / (da - db), 0.0, 1.0));
    da = db;
  }
  if (in.n == 2 && da + tol >= 0.0)  // the segment's far end (its distance is da now)
    out.push(in.p[1]);
}

}  // namespace hapticd::collision::detail
