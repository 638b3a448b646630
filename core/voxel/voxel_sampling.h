#pragma once
/// \file
/// Voxel sampling in the manner of McNeely, Puterbaugh and Troy, "Six Degree-of-Freedom Haptic
/// Rendering Using Voxel Sampling", SIGGRAPH 1999, written here from the paper's description: the
/// static scene becomes a voxel map (each voxel free, surface or interior; a surface voxel carries
/// the scene's outward surface normal), the held body a point shell (points on its surface at the
/// voxel spacing with inward normals); every tick each shell point is looked up in the map, and a
/// point in a surface voxel below that voxel's tangent plane (the plane through the voxel centre
/// with the voxel's normal, §4 of McNeely et al.) gets a force proportional to its depth below it,
/// along the normal. Points in interior voxels get no force, as in the original.
///
/// This is the approximate method our exact contact is compared with in the accuracy study
/// (docs/accuracy.md): constant time per point, accuracy set by the voxel size.
///
/// Threads: build() and makePointShell() off the servo thread (they allocate); force() on any
/// thread, the servo thread included (no allocation).

#include <cstdint>
#include <span>
#include <vector>

#include "core/common/result.h"
#include "core/geometry/polytope.h"
#include "core/geometry/pose.h"

namespace hapticd::voxel {

using geom::Polytope;
using geom::Transform;
using geom::Vec3;

/// A convex polytope placed in the scene: points p_W = X_WP.apply(p_P).
struct PlacedShape {
  const Polytope* shape = nullptr;
  Transform X_WP;
};

/// Signed distance from p_W to the union of the shapes (> 0 outside all, < 0 inside one) and the
/// outward unit normal of the nearest surface: the smallest of the shapes' signed distances (the
/// CSG union). Exact outside; inside, minus the depth below the nearest face of a shape holding
/// the point, which near a seam between two touching shapes is much less than the depth in the
/// union (the voxel map does not use it there). Any thread.
struct SignedDistance {
  double distance = 0.0;
  Vec3 normal_W{0.0};
};
SignedDistance signedDistance(std::span<const PlacedShape> shapes, const Vec3& p_W);

/// The voxel map of a static scene.
class VoxelMap {
 public:
  enum class Cell : std::uint8_t { kFree, kSurface, kInterior };

  /// Voxelises the union of `shapes` on a grid of cubes of side `voxel_size` covering their
  /// bounding box plus one voxel. A voxel is a surface voxel when an exposed surface point lies
  /// within half a voxel diagonal of its centre (a point of a face not covered by another shape,
  /// so seams between touching shapes are never surfaces; each face is represented by its point
  /// nearest the centre), with that face's outward normal (the nearest one's); interior when its
  /// centre is inside the union otherwise; free otherwise. Errors: no shape,
  /// a voxel size that is not positive and finite, more than `max_voxels` voxels.
  static Result<VoxelMap> build(std::span<const PlacedShape> shapes,
                                double voxel_size,
                                std::uint64_t max_voxels = 64ull << 20);

  std::uint64_t voxelCount() const { return cells_.size(); }
  std::uint64_t surfaceVoxelCount() const { return normals_.size(); }

  /// The cell holding p_W (free outside the grid); for a surface voxel also its centre and the
  /// scene's outward normal there. Any thread, no allocation.
  Cell lookup(const Vec3& p_W, Vec3* centre_W = nullptr, Vec3* normal_W = nullptr) const;

 private:
  Vec3 origin_{0.0};  // corner of voxel (0, 0, 0)
  double h_ = 0.0;
  std::uint32_t nx_ = 0, ny_ = 0, nz_ = 0;
  // 0 free, 1 interior, k + 2: surface voxel with normal normals_[k]
  std::vector<std::uint32_t> cells_;
  std::vector<Vec3> normals_;
};

/// The held body as points on its surface, in the body frame B.
struct PointShell {
  std::vector<Vec3> p_B;
  std::vector<Vec3> inward_B;  ///< unit inward surface normal at each point
};

/// Samples the surface of the union of `shapes` (each placed in the body frame, X_BP in
/// PlacedShape::X_WP) on a grid of spacing `spacing` on every face, plus every vertex; points
/// inside another shape of the body are dropped. Errors: no shape, a non-positive spacing, more
/// than `max_points` points.
Result<PointShell> makePointShell(std::span<const PlacedShape> shapes,
                                  double spacing,
                                  std::size_t max_points = 1u << 22);

/// The force of one tick on the held body, in the scene frame.
struct VoxelForce {
  Vec3 force_W{0.0};   ///< N (stiffness units times scene units)
  Vec3 torque_W{0.0};  ///< about com_W
  std::uint32_t points_in_contact = 0;
  std::uint32_t points_interior =
      0;                   ///< shell points in interior voxels (no force: original method)
  double max_depth = 0.0;  ///< deepest point below its tangent plane
};

/// McNeely's tangent-plane force: Σ k·dᵢ·nᵢ over shell points in surface voxels below the voxel's
/// tangent plane, torques about com_W. X_WB places the shell in the scene. Any thread, no
/// allocation.
VoxelForce force(const VoxelMap& map,
                 const PointShell& shell,
                 const Transform& X_WB,
                 const Vec3& com_W,
                 double stiffness_per_point);

}  // namespace hapticd::voxel
