#pragma once
/// \file
/// Meshes the decomposition tests and benchmarks generate (issue 16): an L-block, a torus, a
/// spur gear, a noisy sphere with holes standing in for a scan, a mesh with every defect a file can
/// have, and the shared real meshes when present. Deterministic; metres-sized (about 0.1-1).

#include <optional>
#include <string>

#include "core/decomp/decompose.h"

namespace hapticd::decomp::models {

/// An L-shaped block: 2 x 2 x 1 cubes of size `cell` with one quarter removed, as a closed
/// manifold voxel surface (each cube face split into 2 x `sub` x `sub` triangles).
TriangleMesh lBlock(double cell = 0.1, int sub = 2);
/// A torus, major radius R, minor r, `nu` x `nv` quads.
TriangleMesh torus(double R = 0.1, double r = 0.03, int nu = 48, int nv = 24);
/// A spur gear: `teeth` trapezoid teeth on a hub with an axial bore, extruded; closed.
TriangleMesh gear(int teeth = 12, double radius = 0.05, double width = 0.02);
/// A sphere of radius `radius` as a latitude-longitude grid of about `triangles` triangles,
/// radially perturbed by noise of amplitude `noise` (a fraction of the radius), with `holes`
/// round holes of angular radius `hole_rad` removed: an open mesh, like a scan.
TriangleMesh noisySphere(double radius = 0.1,
                         std::size_t triangles = 70000,
                         double noise = 0.002,
                         int holes = 5,
                         double hole_rad = 0.06);
/// Two closed parts, each with a known defect added: duplicate and unreferenced vertices, a
/// degenerate (zero-area) and a repeated-index triangle, a duplicate triangle, a flipped triangle,
/// a part wound inside out, a non-manifold fin, a hole, a non-finite vertex, an out-of-range index,
/// and a crossing (self-intersecting) third part.
TriangleMesh defective();
/// A box as 12 triangles.
TriangleMesh box(const Vec3& lo, const Vec3& hi);
/// Appends b to a.
void append(TriangleMesh& a, const TriangleMesh& b);

/// A real mesh by file name from $HAPTICD_MESHES_DIR, or else from a folder shared/meshes/ found
/// by walking up from the working directory or the source folder (the development meshes are not
/// in the repository): nullopt when absent. OBJ (v, f) and binary STL.
std::optional<TriangleMesh> sharedMesh(const std::string& file);
/// Reads a Wavefront OBJ's v and f lines (polygons fanned), or a binary STL. nullopt on failure.
std::optional<TriangleMesh> readSimple(const std::string& path);

}  // namespace hapticd::decomp::models
