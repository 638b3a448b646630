#pragma once
/// \file
/// Penetration depth of two overlapping convex polytopes: the minimal translation distance (MTD),
/// the shortest translation of B that leaves A and B touching. The Minkowski difference A - B has
/// three kinds of faces (face of A, face of B, edge of A x edge of B with intersecting Gauss-map
/// arcs); the MTD is the distance from the origin to the nearest of their planes.
/// Exact method: separating axes over both face sets and the Gauss-map-tested edge pairs.
/// Tracked method: a walk over the Minkowski faces from last tick's one (see penetration.cpp).

#include <array>
#include <cstdint>

#include "core/collision/closest_features.h"

namespace hapticd::collision {

/// Which Minkowski-difference face gives the MTD.
enum class DepthFeature : std::uint8_t { kNone, kFaceA, kFaceB, kEdgeEdge };

/// The caller's per-pair state for depth tracking between ticks.
struct DepthCache {
  DepthFeature kind = DepthFeature::kNone;
  std::uint32_t ia = 0;  ///< face or edge of A
  std::uint32_t ib = 0;  ///< face or edge of B
  std::uint32_t support_a = 0;  ///< last support vertex hints
  std::uint32_t support_b = 0;
  Vec3 normal{0.0};  ///< last tick's minimal translation direction (a start for the next)
  /// Vertex pairs (a of A, b of B) of last tick's EPA polytope nearest its answer; EPA starts
  /// from them again (their points a - b are still points of A - B at the new pose).
  static constexpr int kWarm = 16;
  std::array<std::uint32_t, kWarm> warm_a{};
  std::array<std::uint32_t, kWarm> warm_b{};
  std::uint8_t warm_count = 0;
};

/// Result of penetrationDepth(), in A's frame.
struct DepthResult {
  /// The MTD: >= 0 when the polytopes overlap; < 0 (minus a separating gap along `normal`, not
  /// the distance) when a separating axis was found.
  double depth = 0.0;
  Vec3 normal{0.0};   ///< unit: translating B by depth * normal separates (points from A toward B)
  Vec3 point_a{0.0};  ///< deepest point of A along normal (on A's surface)
  Vec3 point_b{0.0};  ///< deepest point of B against normal (point_b = point_a - depth * normal, up to the feature's extent)
  DepthFeature kind = DepthFeature::kNone;
  std::uint32_t ia = 0, ib = 0;
  /// Hints: a vertex of A extreme along normal, a vertex of B extreme against it (or near them).
  std::uint32_t support_a = 0, support_b = 0;
};

/// Exact MTD by separating axes. O(FA + FB + EA * EB) worst case. Updates `cache`.
/// No allocation; any thread.
DepthResult penetrationDepthExact(const Polytope& a, const Polytope& b, const Transform& X_AB,
                                  DepthCache& cache);

/// The MTD by GJK and EPA on A - B with climbed supports, started from last tick's direction.
/// Returns false, changing nothing the caller relies on, when it cannot certify its answer (the
/// final polytope must be convex, hold the origin, and its nearest face's support must meet that
/// face within 1e-11 of the size); then use penetrationDepthExact. No allocation; any thread.
bool penetrationDepthEpa(const Polytope& a, const Polytope& b, const Transform& X_AB,
                         DepthCache& cache, DepthResult& out);

/// The MTD: penetrationDepthEpa when it certifies its answer, else penetrationDepthExact.
DepthResult penetrationDepth(const Polytope& a, const Polytope& b, const Transform& X_AB,
                             DepthCache& cache);

/// Translation distance along unit `dir` (A's frame) that B must move so the pair stops
/// overlapping: max over A of dot(dir, x) - min over B of dot(dir, x) (negative when already
/// separated along dir). `hint_a`, `hint_b`: support hints, updated.
double depthAlong(const Polytope& a, const Polytope& b, const Transform& X_AB, const Vec3& dir,
                  std::uint32_t& hint_a, std::uint32_t& hint_b);

}  // namespace hapticd::collision
