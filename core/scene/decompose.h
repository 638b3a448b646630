#pragma once
/// \file
/// The one place where a mesh that is not convex becomes convex pieces (internal to
/// hapticd_scene): a mesh collider without `convexHull`, an OMI `trimesh` shape and a plain model's
/// mesh all come here. Today a mesh is touched through its convex hull: one piece, the mesh's
/// vertices. The convex decomposition of the issue "Polygonal models" (core/decomp/) replaces the
/// body of convexPieces() and nothing else; the builder makes one primitive
/// (ShapeSource::kMeshPiece) per piece and `hapticctl check` says how the mesh was made convex. Any
/// thread but the servo thread (allocates).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/pose.h"

namespace hapticd::scene::detail {

/// The convex pieces standing for one mesh: each a point set whose convex hull is the piece.
struct ConvexPieces {
  std::vector<std::vector<geom::Vec3>> pieces;
  /// How they were made, for the note `check` prints ("touched through its convex hull").
  std::string method;
};

/// The pieces of the mesh `points` / `triangles` (3 indices each, into points; the mesh may be
/// open, non-manifold, inconsistently wound), in the mesh's frame.
ConvexPieces convexPieces(std::span<const geom::Vec3> points,
                          std::span<const std::uint32_t> triangles);

}  // namespace hapticd::scene::detail
