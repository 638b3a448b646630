#pragma once
/// \file
/// The exact geometry of a plane cut: a part's surface as convex polygons (mesh triangles clipped
/// by the planes of its cell, Sutherland and Hodgman, CACM 17(1) 1974) and its cell as a convex
/// polyhedron (face loops). The vertices of (model ∩ cell) are the polygons' vertices and the
/// cell's vertices inside the model, so a piece is the hull of those. An edge's crossing is
/// computed from its lexicographically smaller end, so two polygons sharing an edge get the same
/// bits. Any thread.

#include <cstdint>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::decomp {

/// The plane n·x = d; "below" is n·x <= d.
struct Plane {
  Vec3 n{1.0, 0.0, 0.0};
  double d = 0.0;
  double signedDistance(const Vec3& x) const { return glm::dot(n, x) - d; }
};

/// Convex polygons packed in one array: polygon k is pts[start[k], start[k + 1]).
struct Polygons {
  std::vector<Vec3> pts;
  std::vector<std::uint32_t> start{0};
  std::size_t size() const { return start.size() - 1; }
  void add(const std::vector<Vec3>& loop);
};

/// A convex polyhedron as its faces' vertex loops.
using Cell = std::vector<std::vector<Vec3>>;

/// The box [lo, hi] as a cell.
Cell boxCell(const Vec3& lo, const Vec3& hi);

/// Splits every polygon by the plane. Points within `eps` of the plane count as on it; a vertex on
/// the plane goes to both sides, a polygon lying in the plane to the side its normal faces away
/// from (the model is behind its surface).
void splitPolygons(const Polygons& in,
                   const Plane& plane,
                   double eps,
                   Polygons& below,
                   Polygons& above);
/// The vertices on the plane (within eps) and the points where edges cross it, each with the side
/// it belongs to: `both` for the section of the surface, `below` or `above` for the vertices of
/// polygons lying in the plane. Shared edges are reported once per polygon; callers deduplicate.
void sectionPoints(const Polygons& in,
                   const Plane& plane,
                   double eps,
                   std::vector<Vec3>& both,
                   std::vector<Vec3>& below,
                   std::vector<Vec3>& above);
/// Splits a cell by the plane; `section` gets the vertices of the new face.
void splitCell(const Cell& in,
               const Plane& plane,
               Cell& below,
               Cell& above,
               std::vector<Vec3>& section);
/// The new face's vertices only (what splitCell puts in `section`).
std::vector<Vec3> cellSection(const Cell& in, const Plane& plane);
/// Sorted, deduplicated (bitwise) points.
void sortUnique(std::vector<Vec3>& pts);

}  // namespace hapticd::decomp
