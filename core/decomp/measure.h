#pragma once
/// \file
/// The concavity measure of decompose.h, evaluated by branch and bound over hull triangles.
/// The excess of a point q over the model, e(q) = d(q, M) (0 inside M), is 1-Lipschitz, and with
/// the signed distance s (negative inside) e = max(0, s); so over a triangle T with centroid m and
/// circumradius about m r, sup e <= max(0, s(m) + r); and e <= d(., t) for any surface triangle t,
/// which is convex, so its largest value over T is at a corner. Triangles are split in four,
/// largest bound first (Horst and Tuy, "Global Optimization", 1996, ch. 4, Lipschitz branch and
/// bound), until every bound is within `tolerance` of the largest excess found or the triangle's
/// radius is down to `resolution`, or `max_evaluations`: the answer (`lower`) is the largest excess
/// at the centroids visited, which sample the boundary at the radius `sampled_radius`; the true
/// supremum is at most `upper`.
/// Any thread; the context is read-only.

#include <limits>
#include <span>
#include <vector>

#include "core/decomp/bvh.h"
#include "core/decomp/quickhull.h"

namespace hapticd::decomp {

/// The model as the measure sees it.
struct ModelView {
  const TriangleBvh* bvh = nullptr;
};

/// A convex hull as half-spaces, for "strictly inside another piece".
struct HullPlanes {
  std::vector<Vec3> normal;  ///< outward unit normals
  std::vector<double> offset;
  Vec3 lo{0.0}, hi{0.0};  ///< bounding box
  /// Depth of q inside (> 0), or minus its plane distance outside.
  double depth(const Vec3& q) const;
  static HullPlanes of(const HullMesh& hull);
};

struct ExcessBound {
  /// The estimate: `lower` when the search converged, else (capped) the largest bound left.
  double upper = 0.0;
  double lower = 0.0;           ///< the largest excess found at a point
  Vec3 worst_q{0.0};            ///< that point
  Vec3 worst_p{0.0};            ///< its closest point on the model's surface
  bool aborted = false;         ///< lower exceeded `stop_above`
  bool capped = false;          ///< stopped at max_evaluations
  double sampled_radius = 0.0;  ///< largest radius of a triangle left unsplit (its centroid seen)
  std::size_t evaluations = 0;
};

struct ExcessOptions {
  double tolerance = 0.0;   ///< absolute: bounds within this of the largest excess are done
  double resolution = 0.0;  ///< absolute: triangles this small are not split
  /// absolute: bounds below this need no more work (when only "is it small?" matters)
  double floor = 0.0;
  double stop_above = std::numeric_limits<double>::infinity();  ///< abort when lower > this
  std::size_t max_evaluations = 20000;
  /// Other pieces: boundary points strictly inside one of them are not on the union's boundary.
  std::span<const HullPlanes> others = {};
};

/// Largest excess of the hull's boundary over the model (see the file comment).
ExcessBound hullExcess(const ModelView& model, const HullMesh& hull, const ExcessOptions& options);

/// Largest distance from the model's surface to the union of `hulls` (upper bound within
/// `tolerance`), by the same branch and bound: d(., H) is convex, so over a triangle it is at most
/// its largest value at the corners, for any one hull.
double surfaceCoverage(std::span<const Vec3> positions,
                       std::span<const Triangle> triangles,
                       std::span<const HullMesh> hulls,
                       std::span<const HullPlanes> planes,
                       double tolerance);

/// Distance from q to a convex hull (0 inside).
double distanceToHull(const Vec3& q, const HullMesh& hull, const HullPlanes& planes);

}  // namespace hapticd::decomp
