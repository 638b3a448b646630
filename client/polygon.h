#pragma once
/// \file
/// Polygons of the model files that `hapticctl import` reads itself (PLY faces, OBJ faces read by
/// their v and f lines) turned into triangles without folding: a fan of a non-convex polygon from
/// the wrong corner covers its notch twice, once each way (a closed surface still, but one whose
/// caps reach over the notch: the decomposition's hulls take those points in).

#include <cstdint>
#include <span>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::client {

/// Appends the triangles of the polygon `poly` (indices into `positions`, in its winding order) to
/// `out`, in the same winding: a triangle as it is; a convex polygon fanned from its first
/// corner; a non-convex one ear-clipped in the plane of its Newell normal (an ear is a strictly
/// convex corner whose triangle holds no other corner, on its edges included). What ears cannot
/// finish (a polygon that crosses itself or is far from planar) is fanned; so is a polygon of more
/// than 256 corners, and one with an index outside `positions` (the decomposition's repair drops
/// those triangles and counts them).
void triangulatePolygon(std::span<const decomp::Vec3> positions,
                        std::span<const std::uint32_t> poly,
                        std::vector<decomp::Triangle>& out);

}  // namespace hapticd::client
