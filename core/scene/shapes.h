#pragma once
/// \file
/// Collider geometry for the scene loader: tessellation of the curved KHR_implicit_shapes into
/// point sets whose hull stays within a relative tolerance of the true surface, the convexity test
/// of mesh colliders (mass properties are core/geometry/mass_properties.h's).
/// Any thread but the servo thread (allocates).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/geometry/mass_properties.h"
#include "core/geometry/polytope.h"
#include "core/geometry/pose.h"

namespace hapticd::scene::detail {

using geom::Mat3;
using geom::Polytope;
using geom::Transform;
using geom::Vec3;

/// Resolution of the latitude-longitude sphere grid used for spheres and capsule caps.
struct SphereGrid {
  std::uint32_t bands = 4;  ///< latitude bands (pole to pole); longitude segments = 2 * bands
  /// Largest distance of the unit sphere from the inscribed grid polytope (a fraction of radius).
  double inscribed_deviation = 0.0;
};

/// The coarsest grid whose hull, scaled out so it straddles the sphere, deviates from the sphere by
/// at most `tolerance` * radius; an error when that needs more than `max_vertices` vertices.
Result<SphereGrid> sphereGridFor(double tolerance, std::uint32_t max_vertices);

/// Segments of a circle so that the straddling polygon deviates by at most `tolerance` * radius.
Result<std::uint32_t> circleSegmentsFor(double tolerance, std::uint32_t max_vertices);

/// Points (in the shape frame, Y axis up) of each implicit shape. Curved shapes are tessellated
/// with the grids above; the hull of the points is within tolerance of the surface.
std::vector<Vec3> boxPoints(const Vec3& size);
std::vector<Vec3> spherePoints(double radius, const SphereGrid& grid);
/// Capsule: the hull of two spheres at y = +-height/2 (radii may differ, one may be 0).
std::vector<Vec3> capsulePoints(double height,
                                double radius_top,
                                double radius_bottom,
                                const SphereGrid& grid);
/// Cylinder (a cone when one radius is 0), y in [-height/2, height/2].
std::vector<Vec3> cylinderPoints(double height,
                                 double radius_top,
                                 double radius_bottom,
                                 std::uint32_t segments);

/// Mass properties: the one routine (core/geometry/mass_properties.h), under the names the loader
/// uses.
using geom::massFromIntegrals;
using geom::MassProperties;
using geom::polytopeIntegrals;
using geom::VolumeIntegrals;

/// Largest amount by which a triangle's plane has hull vertices in front of it, over all
/// triangles, each triangle taken with whichever orientation suits it better (so the winding
/// does not matter). 0 for a convex mesh (up to rounding); positive when some triangle's plane cuts
/// the hull, i.e. the mesh is not convex. `triangles` index `points`; the hull is of `points`.
double convexityViolation(const Polytope& hull,
                          std::span<const Vec3> points,
                          std::span<const std::uint32_t> triangles);

/// The diagonal of the points' bounding box (0 for none).
double boundingDiagonal(std::span<const Vec3> points);

/// The unit normal of the plane the points lie in, within `relative_tolerance` * their bounding
/// diagonal, turned to the side the triangles face (their area-weighted normal; either side when
/// they face both ways); nullopt when the points are not flat or are collinear.
std::optional<Vec3> flatNormal(std::span<const Vec3> points,
                               std::span<const std::uint32_t> triangles,
                               double relative_tolerance);

/// Gives a flat surface a `thickness` behind it: a copy of every point moved by -thickness *
/// normal, the triangles repeated on it reversed. Returns the area of the original triangles.
double thickenFlat(const Vec3& normal,
                   double thickness,
                   std::vector<Vec3>* points,
                   std::vector<std::uint32_t>* triangles);

/// The rigid part of an affine map (Gram-Schmidt on the columns, always a proper rotation) and the
/// remaining linear part: A = R * S with S upper triangular. Degenerate columns get any
/// orthonormal completion.
void splitRigid(const Mat3& A, Mat3* R, Mat3* S);

}  // namespace hapticd::scene::detail
