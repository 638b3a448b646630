#include "core/scene/decompose.h"

namespace hapticd::scene::detail {

ConvexPieces convexPieces(std::span<const geom::Vec3> points,
                          std::span<const std::uint32_t> /*triangles*/) {
  // until the convex decomposition lands (issue "Polygonal models"): the convex hull, one piece
  ConvexPieces out;
  out.pieces.emplace_back(points.begin(), points.end());
  out.method =
      "touched through its convex hull (convex decomposition is not built yet: dents, holes and "
      "hollows are filled)";
  return out;
}

}  // namespace hapticd::scene::detail
