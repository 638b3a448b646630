#pragma once
/// \file
/// Force shading (§5.3 of Gregory et al. 2000, after Ruspini, Kolarov & Khatib 1997 and Phong
/// shading in graphics): contact normals interpolated across the faces of a faceted convex
/// primitive so that a tessellated curved shape (a cylinder, a sphere) feels smooth, while true
/// creases (a box's edges) stay sharp.
///
/// An edge is smooth when the angle between its two faces' normals is below the crease angle.
/// For a point x on face f, each smooth edge e of f (to the neighbour g) adds the weight
///   w_e = 1/2 (1 - clamp(s_e(x) / s_e(centroid_f), 0, 1))
/// of g's normal, s_e being the distance from the edge inside the face: n = normalise(n_f +
/// sum_e w_e (n_g - n_f)). On the edge both sides give (n_f + n_g)/2, so the normal is continuous
/// across every smooth edge; at the face's centre it is the face normal. Built once per shape off
/// the servo thread; shadedNormal() is a servo-thread call (no allocation).

#include <cstdint>
#include <vector>

#include "core/geometry/polytope.h"

namespace hapticd::response {

using geom::Feature;
using geom::Polytope;

class ShadingTable {
 public:
  /// `crease_angle_rad`: edges between faces bent by less than this are smoothed. Off the servo
  /// thread (allocates).
  ShadingTable(const Polytope& shape, double crease_angle_rad);

  /// The shaded outward normal at x_P (the shape's frame) for a contact whose geometric outward
  /// normal is n_P and whose feature on this shape is `feature` (Feature{} if unknown). Returns
  /// n_P unchanged when no smooth edge is near, and when the feature is a crease edge or a
  /// vertex on one: there n_P (between the faces) is the true one, and a face's normal in its
  /// place tells the proxy that the crease is a face (issue 16: a piece's edge read as the face
  /// under it, 46 degrees off, held the probe under a seam of two pieces of a wall).
  geom::Vec3 shadedNormal(const Polytope& shape,
                          const geom::Vec3& x_P,
                          const geom::Vec3& n_P,
                          Feature feature) const;

  /// The same on a known face f of the shape.
  geom::Vec3 shadedNormalOnFace(const Polytope& shape,
                                std::uint32_t f,
                                const geom::Vec3& x_P) const;

  /// Edges of this shape that are smoothed.
  std::uint32_t smoothEdges() const { return smooth_edges_; }

 private:
  struct EdgeInfo {
    std::uint32_t neighbour = 0;  // face across the edge
    double inset = 0.0;           // distance of the face's centroid from the edge (> 0)
    bool smooth = false;
  };
  std::vector<EdgeInfo> face_edges_;      // parallel to Polytope's face-edge array
  std::vector<std::uint32_t> first_;      // per face: its first entry in face_edges_
  std::vector<std::uint8_t> any_smooth_;  // per face
  std::vector<std::uint8_t>
      edge_smooth_;  // per edge of the shape: its faces bend less than the crease
  std::uint32_t smooth_edges_ = 0;
};

}  // namespace hapticd::response
