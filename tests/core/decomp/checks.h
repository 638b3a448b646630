#pragma once
/// \file
/// Independent checks of a decomposition for the tests: brute force over every triangle, hulls
/// rebuilt by the loader's Qhull-based geom::Polytope, the model's inside by the exact generalized
/// winding number (sum of solid angles). Nothing here uses core/decomp's own geometry.

#include <cstdint>
#include <span>

#include "core/decomp/decompose.h"

namespace hapticd::decomp::checks {

struct UnionCheck {
  double surface_to_union = 0.0;   ///< largest distance of a surface sample to the union (abs)
  double boundary_to_model = 0.0;  ///< largest distance of a union-boundary sample to the model
  std::size_t surface_samples = 0;
  std::size_t boundary_samples = 0;
  bool hulls_valid = true;  ///< every piece builds a geom::Polytope
};

/// Samples the mesh's surface (area-weighted, seeded) and every piece's boundary (faces,
/// area-weighted), skipping boundary samples strictly inside another piece or inside the model.
UnionCheck checkUnion(const TriangleMesh& mesh,
                      std::span<const ConvexPiece> pieces,
                      std::size_t surface_samples,
                      std::size_t boundary_samples_per_piece,
                      std::uint64_t seed);

/// Distance from p to triangle abc (by projection and the three edges).
double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
/// The exact generalized winding number of the mesh at p.
double windingNumber(const TriangleMesh& mesh, const Vec3& p);
/// The bounding-box diagonal of the mesh's finite vertices.
double diagonal(const TriangleMesh& mesh);

}  // namespace hapticd::decomp::checks
