#pragma once
/// \file
/// Brute-force reference answers for the property tests and the benchmark's wrong-answer checks.
/// Slow on purpose: no coherence, no walk, nothing shared with the code under test except the
/// Polytope's vertex, edge and face lists.

#include <cstdint>
#include <random>
#include <vector>

#include "core/geometry/polytope.h"

namespace hapticd::reference {

using geom::Polytope;
using geom::Transform;
using geom::Vec3;

struct RefAnswer {
  /// true when the polytopes overlap with depth > 0 (no separating axis).
  bool overlapping = false;
  /// Separated: the distance (minimum over vertex-face and edge-edge pairs), >= 0.
  /// Overlapping: minus the penetration depth (minimum over separating-axis candidates: all face
  /// normals of A and B and all cross products of an edge of A with an edge of B).
  double signed_distance = 0.0;
  /// Separated: unit from A's witness to B's. Overlapping: direction to move B out of A.
  Vec3 normal{0.0};
  Vec3 point_a{0.0}, point_b{0.0};  ///< witnesses (separated only)
};

/// The reference answer for A and B, B placed in A's frame by X_AB. O(VA*FB + VB*FA + EA*EB).
RefAnswer bruteForce(const Polytope& a, const Polytope& b, const Transform& X_AB);

/// Distance of two polytopes known to be apart (vertex-face and edge-edge pairs only, no separating
/// axes): O(VA*FB + VB*FA + EA*EB), for hulls too large for bruteForce().
double bruteSeparatedDistance(const Polytope& a, const Polytope& b, const Transform& X_AB);

/// Penetration depth by separating axes restricted to the face normals and to the edge pairs whose
/// Gauss-map arcs cross (the Minkowski faces), each axis's depth from a scan of all vertices:
/// O(EA*EB + (F + K)*(VA + VB)); for hulls too large for bruteForce(). Positive when overlapping.
double bruteMinkowskiDepth(const Polytope& a,
                           const Polytope& b,
                           const Transform& X_AB,
                           Vec3* normal);

/// Depth along unit dir (A's frame): max_A dot(dir,x) - min_B dot(dir,x), by scanning all vertices.
double bruteDepthAlong(const Polytope& a,
                       const Polytope& b,
                       const Transform& X_AB,
                       const Vec3& dir);

/// Whether a penetration depth answer (B moved by `depth` along `normal`, A's frame) is as good as
/// the full method's (penetrationDepthExact's depth `full_depth`, the pair overlapping), to `tol`
/// (a length, for rounding): `normal` is unit, `depth` is the pair's overlap along it
/// (bruteDepthAlong, within tol), and it is not deeper than the full method's (within tol).
/// Comparing the depths alone (|depth - full_depth| <= tol) asks more than the full method gives:
/// its tie grid lets its own answer exceed the least overlap over all directions by up to a grid
/// step, 1e-12 of the coordinates' magnitude (docs/narrow-phase.md, "Ties"; on two resting
/// 50 mm prisms about 3.4 times 1e-12 of their radius), so a minimal answer can differ from it by
/// more than tol. This one still refuses every answer that is not a minimal translation: the
/// overlap along any unit direction is at least the least one, so a depth equal to its normal's
/// overlap is at least the least less tol, and one deeper than the full method's is above the
/// least; a depth that does not separate along its normal (too shallow) or that is not its
/// normal's overlap at all is refused by the first test.
bool depthAgreesWithFull(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         double depth,
                         const Vec3& normal,
                         double full_depth,
                         double tol);

/// n points on the ellipsoid with semi-axes (ax, ay, az), seeded (the benchmark's hulls).
std::vector<Vec3> ellipsoidPoints(std::size_t n,
                                  double ax,
                                  double ay,
                                  double az,
                                  std::uint64_t seed);

/// A random convex point set: n points, various shapes (ellipsoid, box corners, slivers),
/// roughly of radius `size`.
std::vector<Vec3> randomPointSet(std::mt19937_64& rng, std::size_t n, double size);

/// A uniformly random rotation.
geom::Quat randomRotation(std::mt19937_64& rng);

}  // namespace hapticd::reference
