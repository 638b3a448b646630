#pragma once
/// \file
/// The one place where a mesh that is not convex becomes convex pieces (internal to
/// hapticd_scene): a mesh collider without `convexHull`, an OMI `trimesh` shape and a plain model's
/// mesh all come here. The pieces are those of the approximate convex decomposition of
/// core/decomp/decompose.h (issue "Polygonal models"; docs/decomposition.md); when it cannot
/// decompose the mesh (no usable triangle), the mesh is touched through its convex hull. The
/// builder makes one primitive (ShapeSource::kMeshPiece) per piece and `hapticctl check` says how
/// the mesh was made convex. Any thread but the servo thread (allocates).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/pose.h"

namespace hapticd::scene::detail {

/// The convex pieces standing for one mesh: each a point set whose convex hull is the piece.
struct ConvexPieces {
  std::vector<std::vector<geom::Vec3>> pieces;
  /// How they were made, for the note `check` prints ("touched through 5 convex pieces ...").
  std::string method;
};

/// Target concavity of the decomposition: 1 % of the mesh's bounding-box diagonal (the default
/// of core/decomp, what `hapticctl import` uses).
inline constexpr double kDecompConcavity = 0.01;
/// At most this many pieces per mesh (each a primitive, counted against max_primitives).
inline constexpr std::size_t kDecompMaxPieces = 64;
/// Wall-clock limit of one mesh's decomposition, seconds: past it the best pieces so far are used
/// and the note says so (a load never hangs on a large mesh).
inline constexpr double kDecompTimeLimitS = 5.0;

/// The pieces of the mesh `points` / `triangles` (3 indices each, into points; the mesh may be
/// open, non-manifold, inconsistently wound), in the mesh's frame.
ConvexPieces convexPieces(std::span<const geom::Vec3> points,
                          std::span<const std::uint32_t> triangles);

}  // namespace hapticd::scene::detail
