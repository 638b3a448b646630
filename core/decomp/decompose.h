#pragma once
/// \file
/// Approximate convex decomposition of a triangle mesh as real files have it
/// (docs/decomposition.md).
///
/// The method is a hierarchy of plane cuts chosen by a concavity measure, in the family of
/// Wei, Liu, Wang, Wang, Cai, Bai, "Approximate Convex Decomposition for 3D Meshes with
/// Collision-Aware Concavity and Tree Search" (CoACD), ACM TOG 41(4), SIGGRAPH 2022, §4-§5: a part
/// is cut where its hull strays farthest from the model; every candidate plane is scored by the
/// concavity of the two halves' hulls; parts are cut worst first until all are within the bound;
/// then neighbours are merged while the merged hull stays within it. The paper this product
/// implements decomposes its polygonal models as pre-computation (Gregory et al. 2000, §3.1,
/// [BD92]); here the pieces become `convexHull` colliders.
///
/// **Concavity** (the knob and the report), for the model's solid M (bounded by the repaired
/// surface S, holes filled; inside by the generalized winding number, see docs/decomposition.md)
/// and the union U of the pieces:
///
///     concavity = max( sup over q on the boundary of U of d(q, M),
///                      sup over p on S of d(p, U) )
///
/// the farthest the touchable boundary of the pieces strays from the model, and the farthest a
/// point of the model's surface lies outside every piece; divided by the diagonal of the model's
/// bounding box. It is a one-sided Hausdorff distance each way; it is zero only when U = M. Hulls
/// of parts cover S, so the second term is only the hull simplification tolerance; the first is
/// what cuts reduce. Surface that ends up strictly inside U (a slot narrower than the bound, a
/// sealed void) is not counted: no probe reaches it.
/// measureConcavity() evaluates it by branch and bound on the Lipschitz bound of the distance
/// (an upper bound within `measure_tolerance`), independently of the decomposition's choices.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/geometry/pose.h"

namespace hapticd::decomp {

using Vec3 = geom::Vec3;
using Triangle = std::array<std::uint32_t, 3>;

/// A triangle soup as a file gives it: any units, any defects (see RepairCounts).
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
};

/// Knobs of decompose(). Defaults are the ones `hapticctl import` uses.
struct DecompOptions {
  /// Target concavity, a fraction of the bounding-box diagonal, in (0, 1). Default 0.01.
  double concavity = 0.01;
  /// At most this many pieces (>= 1). Default 64.
  std::size_t max_pieces = 64;
  /// Wall-clock limit; when it passes, the best result so far is returned with a warning. 0: none.
  double time_limit_s = 0.0;
  /// Worker threads for the candidate cuts: 0 = the hardware's (at most 2), else 1..16. The
  /// result is the same bit for bit for every value.
  unsigned threads = 0;
  /// Inputs with more triangles than this are decimated (vertex clustering) to about
  /// `decimate_to` triangles, with a warning; above `refuse_triangles` they are refused.
  std::size_t max_triangles = 400'000;
  std::size_t decimate_to = 200'000;
  std::size_t refuse_triangles = 20'000'000;
  /// Vertices of one piece at most (a loader's hull limit is 4096); the hull keeps the farthest
  /// points first and the rest count in the concavity's coverage term.
  std::size_t max_piece_vertices = 512;
  /// Merge neighbouring pieces whose merged hull stays within the concavity.
  bool merge = true;
};

/// What the repair found and did. Every count is of the input as given.
struct RepairCounts {
  std::size_t input_vertices = 0;
  std::size_t input_triangles = 0;
  std::size_t non_finite_vertices = 0;     ///< NaN/Inf positions; their triangles dropped
  std::size_t bad_index_triangles = 0;     ///< an index past the vertex array: dropped
  std::size_t duplicate_vertices = 0;      ///< merged with an equal (or within 1e-9 diag) one
  std::size_t unreferenced_vertices = 0;   ///< used by no triangle: dropped
  std::size_t degenerate_triangles = 0;    ///< repeated vertex or zero area: dropped
  std::size_t duplicate_triangles = 0;     ///< same three vertices as another: dropped
  std::size_t boundary_edges = 0;          ///< edges of one triangle (holes, open parts)
  std::size_t holes_filled = 0;            ///< boundary loops closed by a fan about their centre
  std::size_t non_manifold_edges = 0;      ///< edges of three or more triangles
  std::size_t flipped_triangles = 0;       ///< re-wound to agree with their neighbours
  std::size_t inverted_components = 0;     ///< closed parts wound inside out: turned
  std::size_t components = 0;              ///< connected parts (over shared edges)
  std::size_t open_components = 0;         ///< parts with boundary edges
  std::size_t self_intersections = 0;      ///< pairs of crossing triangles (not adjacent)
  bool self_intersections_capped = false;  ///< counting stopped at its budget
  std::size_t decimated_from = 0;          ///< triangles before decimation (0: not decimated)
};

/// One convex piece: its hull's vertices in the input's frame and units. Any 4 of them are not
/// coplanar; the hull has volume. `triangles` index `vertices`, counter-clockwise from outside.
struct ConvexPiece {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
};

/// What decompose() reports.
struct DecompReport {
  std::size_t pieces = 0;
  /// Reached, fraction of the diagonal: the largest excess found on the union's boundary, sampled
  /// at triangles of radius 0.1 x the target or finer where the evaluation budget allowed.
  double concavity = 0.0;
  /// A rigorous upper bound of the same (Lipschitz bound over the unsampled remainder).
  double concavity_bound = 0.0;
  double concavity_target = 0.0;  ///< the option
  double diagonal = 0.0;          ///< bounding-box diagonal, input units
  double volume_ratio = 0.0;  ///< sum of piece volumes / model volume; 0 for open or flat models
                              ///< (volume under 1e-9 of the diagonal cubed)
  /// The volume of the union of the pieces (each point once: merged hulls overlap their
  /// neighbours), input units cubed; what a body of these pieces weighs (unionIntegrals).
  double union_volume = 0.0;
  double union_ratio = 0.0;  ///< union_volume / model volume; 0 where volume_ratio is
  bool closed = false;       ///< closed after repair (holes filled, no non-manifold edge)
  double seconds = 0.0;
  std::size_t cuts = 0;    ///< planes cut
  std::size_t merges = 0;  ///< pairs merged
  bool time_limit_hit = false;
  bool max_pieces_hit = false;  ///< stopped at max_pieces above the target concavity
  RepairCounts repairs;
  std::vector<std::string> warnings;  ///< each a sentence (time limit, decimation, ...)
};

struct DecompResult {
  std::vector<ConvexPiece> pieces;
  DecompReport report;
};

/// Progress of a running decomposition.
struct Progress {
  std::size_t pieces = 0;
  double concavity = 0.0;  ///< the worst piece's, fraction of the diagonal
  double elapsed_s = 0.0;
  const char* stage = "";  ///< "repair", "cut", "merge", "finish"
};
/// Called on the calling thread after each step (often: throttle printing yourself).
using ProgressFn = std::function<void(const Progress&)>;

/// Decomposes `mesh` into convex pieces. Pure: no globals, no I/O; any thread, concurrently with
/// other calls. Deterministic: the same mesh and options give the same pieces bit for bit for any
/// `threads`, unless the time limit cuts it short (then report.time_limit_hit and a warning).
/// Errors: no usable triangle (empty, all degenerate, all non-finite), bad options, or more than
/// options.refuse_triangles triangles.
Result<DecompResult> decompose(const TriangleMesh& mesh,
                               const DecompOptions& options = {},
                               const ProgressFn& progress = {});

/// The concavity of `pieces` against `mesh` as defined in this header (fraction of the mesh's
/// diagonal; an upper bound within `tolerance` of the diagonal). The mesh is repaired as
/// decompose() does. Used on the peers' pieces in the benchmarks with the same definition. Any
/// thread.
Result<double> measureConcavity(const TriangleMesh& mesh,
                                std::span<const ConvexPiece> pieces,
                                double tolerance = 1e-3);

/// A stable 256-bit content hash (SHA-256, hex) of the mesh's bytes (positions as IEEE doubles,
/// little-endian, then triangles as uint32) and of every option that changes the pieces (not
/// `threads`, not `time_limit_s`): a cache key. Any thread.
std::string contentHash(const TriangleMesh& mesh, const DecompOptions& options);

/// The report as text lines (for hapticctl import), e.g. "pieces 12, concavity 0.0087 of the
/// diagonal (target 0.01), ...".
std::string describe(const DecompReport& report);

}  // namespace hapticd::decomp
