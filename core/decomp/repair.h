#pragma once
/// \file
/// Repair of a triangle soup as files have it, before decomposition: non-finite and out-of-range
/// data dropped, equal vertices welded, degenerate and duplicate triangles dropped, unreferenced
/// vertices dropped, winding made consistent across manifold edges (breadth first from each part's
/// first triangle), each part turned to enclose positive volume (a sealed inner shell is turned
/// too, so the void it bounds counts as inside: docs/decomposition.md), holes (boundary loops)
/// closed by a fan about their centre, edges and crossings counted. Inputs above a triangle limit
/// are decimated by vertex clustering (Rossignac and Borrel, "Multi-resolution 3D approximations
/// for rendering complex scenes", 1993). Any thread.

#include <cstdint>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::decomp {

struct RepairedMesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  Vec3 lo{0.0}, hi{0.0};         ///< bounding box
  double diagonal = 0.0;         ///< |hi - lo|
  bool closed = false;           ///< no boundary and no non-manifold edge
  double volume = 0.0;           ///< enclosed volume when closed, else 0
  double decimation_cell = 0.0;  ///< vertex-clustering cell size, 0 when not decimated
};

struct RepairLimits {
  std::size_t max_triangles = 400'000;
  std::size_t decimate_to = 200'000;
  std::size_t refuse_triangles = 20'000'000;
  std::size_t max_crossing_pairs_tested = 4'000'000;
};

/// Repairs `mesh`, filling `counts`. Errors: more triangles than limits.refuse_triangles, or no
/// usable triangle left.
Result<RepairedMesh> repairMesh(const TriangleMesh& mesh,
                                const RepairLimits& limits,
                                RepairCounts& counts);

}  // namespace hapticd::decomp
