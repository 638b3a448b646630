#pragma once
/// \file
/// Convex meshes for the demo scenes: boxes, icospheres (320 faces after two subdivisions, as in
/// the paper's dynamic scene, §6.2), prisms of convex polygons, and involute spur-gear teeth.
/// Metres; every mesh closed, triangles counter-clockwise seen from outside. Any thread.

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scenes/glb_builder.h"

namespace hapticd::scenes {

using Vec2 = glm::dvec2;

/// An axis-aligned box centred at the origin: 8 vertices, 12 triangles.
MeshData boxMesh(const Vec3& size);

/// An icosahedron subdivided `levels` times, projected onto the unit sphere, then scaled by
/// `radii` (an ellipsoid when they differ): 20 * 4^levels triangles (320 for levels = 2),
/// 10 * 4^levels + 2 vertices (162).
MeshData icosphereMesh(const Vec3& radii, int levels);

/// A right prism of a convex polygon in the XY plane (counter-clockwise), from z = -width/2 to
/// +width/2: 2n vertices, 4n - 4 triangles (fans on the caps).
MeshData prismMesh(const std::vector<Vec2>& polygon_ccw, double width);

/// A closed mesh of the union of a slab and a narrower bar under it, for the "decomposed" scene's
/// non-convex cells (docs/demo-scenes.md); every face axis-aligned, no T-junction.
/// A pin cell: a square tile (`tile_side` in X and Z, from y = 0 up to `tile_thickness`) with a
/// square pin (`pin_side`) under its centre, from y = -pin_length to 0. 16 vertices, 28 triangles.
MeshData pinCellMesh(double tile_side, double tile_thickness, double pin_side, double pin_length);
/// A ridge cell: a base slab `cell` wide (X) and long (Z) from y = -(ridge_height + base_thickness)
/// to -ridge_height, and a ridge `ridge_width` wide along the whole Z length on its centre, up to
/// y = 0: a bar of T section. Side by side, cells make a plate of grooves along Z.
MeshData ridgeCellMesh(double cell, double ridge_width, double ridge_height, double base_thickness);

/// A standard involute spur gear (pressure angle 20°, addendum = module, dedendum = 1.25 module),
/// teeth thinned at the pitch circle by half the pair's backlash.
struct SpurGear {
  int teeth = 19;
  double module_m = 0.005;
  double pressure_angle_rad = 0.3490658503988659;  // 20 degrees
  double backlash_m = 0.001;  ///< circumferential backlash of the pair at the pitch circle
  double face_width_m = 0.015;
  int flank_samples = 3;        ///< involute points per flank above the base circle
  double root_inset_m = 0.001;  ///< teeth reach this far inside the root circle into the hub

  double pitchRadius() const { return 0.5 * module_m * teeth; }
  double baseRadius() const;
  double tipRadius() const { return pitchRadius() + module_m; }
  double rootRadius() const { return pitchRadius() - 1.25 * module_m; }
  /// Half the angular thickness of a tooth at radius r (r >= base radius: on the involute).
  double toothHalfAngle(double r) const;
  /// One tooth's cross-section, centred on angle `centre_rad`: radial flank from the inset root up
  /// to the base circle, involute flank up to the tip circle; convex, counter-clockwise.
  std::vector<Vec2> toothPolygon(double centre_rad) const;
  /// The hub: a polygon with one vertex on the root circle at the centre of every gap
  /// (`first_tooth_rad` + (k + 1/2) * pitch angle), counter-clockwise.
  std::vector<Vec2> hubPolygon(double first_tooth_rad) const;
};

}  // namespace hapticd::scenes
