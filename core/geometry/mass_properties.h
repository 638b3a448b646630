#pragma once
/// \file
/// Exact mass properties of convex polytopes, the one routine of the project (the scene loader
/// and the dynamics both use it): the divergence theorem over the hull's faces, as tetrahedra
/// from a point inside (Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in
/// terms of its vertex coordinates", J. Math. Stat. 1(1) 2004; the same integrals as Mirtich,
/// "Fast and accurate computation of polyhedral mass properties", JGT 1(2) 1996). Coordinates are
/// taken relative to each polytope's centroid, so that a body far from the origin loses no digits.
/// No allocation; any thread.

#include "core/geometry/polytope.h"
#include "core/geometry/pose.h"

namespace hapticd::geom {

/// Volume integrals of a solid: volume, first moment and second moment about the frame origin.
struct VolumeIntegrals {
  double volume = 0.0;  ///< m^3 (scene units cubed)
  Vec3 first{0.0};      ///< integral of x dV
  Mat3 second{0.0};     ///< integral of x x^T dV
  /// The integrals of the union of two solids that do not overlap.
  void add(const VolumeIntegrals& o) {
    volume += o.volume;
    first += o.first;
    second += o.second;
  }
};

/// The exact integrals of the convex polytope `shape` placed by X_BP, in frame B.
VolumeIntegrals polytopeIntegrals(const Polytope& shape, const Transform& X_BP);

/// Mass, centre of mass and inertia of a solid in its frame B.
struct MassProperties {
  double mass = 0.0;    ///< kg (0: no volume)
  Vec3 com_B{0.0};      ///< centre of mass, frame B
  Mat3 inertia_B{0.0};  ///< about com_B, axes of B (kg m^2), exactly symmetric
};

/// The mass properties of integrals `v` at `density` (kg/m^3); all zero when v has no volume.
MassProperties massFromIntegrals(const VolumeIntegrals& v, double density);

}  // namespace hapticd::geom
