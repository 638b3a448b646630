#pragma once
/// \file
/// A bounding-volume hierarchy of axis-aligned boxes over a triangle mesh: the closest point of the
/// surface (Ericson, "Real-Time Collision Detection", 2005, §5.1.5 for a point and a triangle,
/// §6 for the tree), ray crossings (Möller and Trumbore, JGT 2(1) 1997) for the inside test, and
/// the crossing triangle pairs that repair counts. Immutable after construction; any thread may
/// query it concurrently.

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::decomp {

class TriangleBvh {
 public:
  TriangleBvh(std::span<const Vec3> positions, std::span<const Triangle> triangles);

  struct Closest {
    double distance = std::numeric_limits<double>::infinity();
    Vec3 point{0.0};
    std::uint32_t triangle = 0;
  };
  /// The closest point of the surface to `p`, searched only within `max_distance` (farther: the
  /// returned distance is infinite).
  Closest closest(const Vec3& p, double max_distance = std::numeric_limits<double>::infinity()) const;
  /// Exits minus entries of the ray p + t·dir, t > 0, through the outward-wound surface.
  int windingAlongRay(const Vec3& p, const Vec3& dir) const;
  /// Inside the solid: a positive crossing count on at least two of three fixed rays (robust to a
  /// ray grazing an edge and to a hole on one of them).
  bool inside(const Vec3& p) const;
  /// Pairs of triangles that cross (an edge of one through the other), sharing no vertex; counting
  /// stops after `max_pairs_tested` box-overlapping pairs (then *capped is set).
  std::size_t countCrossingPairs(std::size_t max_pairs_tested, bool* capped) const;

  std::size_t triangleCount() const { return tris_.size(); }
  /// Largest distance from the points to triangle `index` of the tree's order (Closest::triangle):
  /// an upper bound of the distance to the surface over their convex hull (distance to one
  /// triangle is convex).
  double farthestFrom(std::uint32_t index, std::span<const Vec3> points) const;

 private:
  struct Node {
    Vec3 lo, hi;
    std::uint32_t first = 0;  // leaf: first triangle; inner: left child (right = first + 1)
    std::uint32_t count = 0;  // leaf: triangles; inner: 0
  };
  struct Tri {
    Vec3 a, b, c;
    std::array<std::uint32_t, 3> v;  // vertex indices, for adjacency
  };
  void build(std::uint32_t index, std::uint32_t first, std::uint32_t count,
             std::vector<Vec3>& centroids);

  std::vector<Node> nodes_;
  std::vector<Tri> tris_;
};

/// The closest point of triangle abc to p.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace hapticd::decomp
