#pragma once
/// \file
/// One call answering, for two convex polytopes: how far apart, where they touch, how deep they
/// overlap. Closest features (warm-started), then the manifold, then the depth when overlapping.

#include "core/collision/closest_features.h"
#include "core/collision/manifold.h"
#include "core/collision/penetration.h"

namespace hapticd::collision {

/// The caller's per-pair state between ticks.
struct PairCache {
  FeatureCache features;
  DepthCache depth;
  /// Overlapping at the last query: the next one computes the depth first and walks the
  /// features only if the pair has come apart.
  bool penetrating = false;
  /// When set (the caller owns it, DepthTracker::reserve'd for this pair), the depth is
  /// penetrationDepthCoherent's: last tick's candidates certify this tick's answer when they can.
  DepthTracker* tracker = nullptr;
};

/// Result of queryPair(), in A's frame.
struct PairResult {
  ContactStatus status = ContactStatus::kSeparated;
  /// > 0 gap; <= 0 minus the penetration depth (minimal translation distance).
  double distance = 0.0;
  /// Unit. Separated: from A's witness to B's. Penetrating: direction to move B out of A.
  Vec3 normal{0.0};
  Vec3 point_a{0.0};
  Vec3 point_b{0.0};
  Feature fa, fb;  ///< closest features (separated/touching) or the MTD's features (penetrating)
  Manifold manifold;
  std::uint32_t iterations = 0;  ///< walk iterations
};

/// The full pair query. No allocation when `scratch` holds the faces of both polytopes
/// (DepthScratch::reserve; a CollisionWorld sizes its own for every body it holds); any thread
/// that owns `scratch`, the servo thread included.
PairResult queryPair(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     PairCache& cache,
                     DepthScratch& scratch,
                     const QueryOptions& options = {});
/// The same written into `out`, every field of which it sets (the manifold's points beyond its
/// count are left as they were): a caller that keeps one result from query to query, as a
/// CollisionWorld does, saves building (zeroing) a 344-byte PairResult per query, a tenth of a
/// near-contact query (PairQuery/NearContact, bench/README.md).
void queryPair(const Polytope& a,
               const Polytope& b,
               const Transform& X_AB,
               PairCache& cache,
               DepthScratch& scratch,
               const QueryOptions& options,
               PairResult& out);
/// The same with the calling thread's scratch, which grows (allocates) the first time a larger
/// polytope comes (penetration.h): for tools and tests, not for the servo thread.
PairResult queryPair(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     PairCache& cache,
                     const QueryOptions& options = {});

}  // namespace hapticd::collision
