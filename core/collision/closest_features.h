#pragma once
/// \file
/// Closest-feature tracking between two convex polytopes in the manner of V-Clip
/// (B. Mirtich, "V-Clip: Fast and Robust Polyhedral Collision Detection", ACM TOG 17(3), 1998),
/// itself a robust form of Lin & Canny 1991 (§4.1 of Gregory et al. 2000). Features walk greedily
/// through the Voronoi regions from last tick's pair (warm start) or from the directional lookup
/// table (cold start); each update strictly lowers the distance between the features or keeps it
/// and lowers their dimension, so the walk cannot cycle. Penetration is detected, not cycled on.

#include <cstdint>

#include "core/geometry/polytope.h"

namespace hapticd::collision {

using geom::Feature;
using geom::FeatureType;
using geom::Polytope;
using geom::Transform;
using geom::Vec3;

/// How a pair stands.
enum class ContactStatus : std::uint8_t { kSeparated, kTouching, kPenetrating };

/// How the walk ended.
enum class WalkEnd : std::uint8_t {
  kConverged,     ///< a feature pair satisfying both Voronoi conditions (separated or touching)
  kPenetration,   ///< the features intersect: the polytopes overlap
  kIterationCap,  ///< the cap was reached (a bug if it ever happens; tests say it does not)
};

/// Tolerances, relative to the pair's size (the larger polytope radius). Any unit scale gives the
/// same relative answers.
struct QueryOptions {
  /// |distance| <= touch_tolerance * size is reported as touching.
  double touch_tolerance = 1e-10;
  /// Iteration cap of the walk; 0 picks 4 * (features of A + features of B) + 64.
  std::uint32_t max_iterations = 0;
};

/// The caller's per-pair state between ticks (Box2D style: the cache belongs to the caller).
/// A default-constructed cache means cold start.
struct FeatureCache {
  Feature a;  ///< last closest feature on A
  Feature b;  ///< last closest feature on B
};

/// Result of closestFeatures(), all in A's frame.
struct ClosestResult {
  ContactStatus status = ContactStatus::kSeparated;
  WalkEnd end = WalkEnd::kConverged;
  /// Separated or touching: the distance (>= 0). Penetrating: 0 (see penetration.h for depth).
  double distance = 0.0;
  Vec3 point_a{0.0};  ///< witness on A (separated/touching)
  Vec3 point_b{0.0};  ///< witness on B (separated/touching)
  Vec3 normal{
      0.0};        ///< unit, from A toward B (separated/touching; for touching, the best available)
  Feature fa, fb;  ///< the final feature pair
  std::uint32_t iterations = 0;
};

/// Walks to the closest features of A and B, B placed in A's frame by X_AB.
/// Updates `cache` with the final pair. No allocation; any thread, including the servo thread.
ClosestResult closestFeatures(const Polytope& a,
                              const Polytope& b,
                              const Transform& X_AB,
                              FeatureCache& cache,
                              const QueryOptions& options = {});

}  // namespace hapticd::collision
