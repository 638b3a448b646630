#pragma once
/// \file
/// Contact manifold from the closest features (§4.1 of Gregory et al. 2000): vertex cases give a
/// point pair; non-parallel edges their closest points; parallel edges the overlap segment;
/// edge-face and face-face by clipping. At most 4 well-spread points, the deepest always kept.

#include <array>
#include <cstdint>

#include "core/collision/closest_features.h"
#include "core/collision/penetration.h"

namespace hapticd::collision {

struct ContactPoint {
  Vec3 point{0.0};     ///< A's frame: midway between the two surfaces
  Vec3 normal{0.0};    ///< unit, from A toward B
  double depth = 0.0;  ///< > 0 overlap along normal, < 0 gap
};

struct Manifold {
  static constexpr std::size_t kMaxPoints = 4;
  std::array<ContactPoint, kMaxPoints> points{};
  std::uint8_t count = 0;
  /// A face of more than 256 vertices took part and only its first 256 were clipped: the contact
  /// region is then a part of the true one (the deepest point is still exact).
  bool truncated = false;
};

/// Options of manifold building, relative to the pair's size.
struct ManifoldOptions {
  /// Two features count as parallel when the sine of their angle is below this.
  double parallel_tolerance = 1e-6;
  /// manifoldFromDepth: the pair overlaps by no more than the touch tolerance (the query calls it
  /// touching). Its points whose gap is within parallel_tolerance of the pair's size are kept
  /// too, as manifoldFromClosest keeps the points of a face parallel within that tolerance;
  /// otherwise only penetrating points are. A box sliding onto the next of two flush tiles, its
  /// face on the tile's tilted by rounding, was held by the one corner that touched and tipped
  /// over it (docs/collision-pipeline.md "Flush seams").
  bool touching = false;
};

/// Manifold of a separated or touching pair, from its closest features (A's frame).
Manifold manifoldFromClosest(const Polytope& a,
                             const Polytope& b,
                             const Transform& X_AB,
                             const ClosestResult& closest,
                             const ManifoldOptions& options = {});

/// The same written into `out` (count, truncated and the points in use; the others are left as
/// they were): a near-contact query mostly ends with one point, and building a whole Manifold to
/// copy it cost more than the point itself (PairQuery/NearContact, bench/README.md).
void manifoldFromClosest(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         const ClosestResult& closest,
                         Manifold& out,
                         const ManifoldOptions& options = {});

/// Manifold of an overlapping pair from its MTD (A's frame): the faces of A and B most aligned
/// with the normal are clipped against each other; edge-edge MTDs give one point.
Manifold manifoldFromDepth(const Polytope& a,
                           const Polytope& b,
                           const Transform& X_AB,
                           const DepthResult& depth,
                           const ManifoldOptions& options = {});

}  // namespace hapticd::collision
