#pragma once
/// \file
/// A small 3-D quickhull (Barber, Dobkin, Huhdanpaa, "The Quickhull Algorithm for Convex Hulls",
/// ACM TOMS 22(4) 1996, §3) with a distance tolerance, for the thousands of throwaway hulls a
/// decomposition scores. The hulls that leave the decomposition are checked again by the loader's
/// own Qhull-based geom::Polytope. Deterministic (ties by point index); any thread.

#include <cstdint>
#include <span>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::decomp {

/// A closed triangulated convex hull.
struct HullMesh {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;  ///< counter-clockwise from outside
  /// Largest distance of an input point outside the hull (points within `tolerance` are
  /// dropped; the vertex cap may leave farther ones).
  double max_outside = 0.0;
  bool valid() const { return triangles.size() >= 4; }
};

/// Convex hull of `points`. Points closer than `tolerance` to the growing hull are dropped (so the
/// hull is an inner approximation within `tolerance` up to the vertex cap). At most `max_vertices`
/// vertices: the point farthest outside the hull so far goes in first, so a capped hull is the
/// greedy farthest-point approximation and `max_outside` its error. Fewer than 4 points, or all
/// within `tolerance` of a plane: an empty (invalid) hull.
HullMesh quickHull(std::span<const Vec3> points, double tolerance, std::size_t max_vertices);

/// Volume of a closed, outward-wound triangle mesh (signed; positive for outward winding).
double meshVolume(std::span<const Vec3> vertices, std::span<const Triangle> triangles);

}  // namespace hapticd::decomp
