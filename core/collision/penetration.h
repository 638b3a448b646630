#pragma once
/// \file
/// Penetration depth of two overlapping convex polytopes: the minimal translation distance (MTD),
/// the shortest translation of B that leaves A and B touching. The Minkowski difference A - B has
/// three kinds of faces (face of A, face of B, edge of A x edge of B with intersecting Gauss-map
/// arcs); the MTD is the distance from the origin to the nearest of their planes.
///
/// Two methods, one answer:
/// - exact (penetrationDepthExact, penetration.cpp): separating axes over both face sets and the
///   edge pairs whose Gauss-map arcs cross (Gregorius, "The Separating Axis Test between Convex
///   Polyhedra", GDC 2013), B's regions found by walking its vertex graph;
/// - warm-started EPA (penetrationDepthEpa, epa.cpp): GJK then the expanding polytope on A - B,
///   started from last tick's direction and from the vertex pairs of last tick's polytope nearest
///   its answer (DepthCache), its answer certified or refused.
/// penetrationDepth, the one the pair query calls, takes EPA's certified answer for larger hulls
/// and the exact method otherwise or when EPA refuses.
/// - coherent exact (penetrationDepthCoherent, DepthTracker): the exact method's answer proven
///   from lower bounds on every candidate kept since its last evaluation, the full method only
///   when the proof fails; the pair query uses it when PairCache::tracker is set.
///
/// Memory: EPA works in fixed arrays on the stack. The exact method needs per-face scratch; the
/// caller owns it (DepthScratch), sized before the first query for the largest polytope it will
/// meet (a CollisionWorld keeps one, sized as bodies are added), after which no query allocates.
/// Called without a scratch they use the calling thread's (DepthScratch::forThisThread), which
/// grows, allocating, the first time a larger polytope comes: for tools and tests, not for the
/// servo thread.

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/collision/closest_features.h"
#include "core/common/reserved_vector.h"

namespace hapticd::collision {

/// Which Minkowski-difference face gives the MTD.
enum class DepthFeature : std::uint8_t { kNone, kFaceA, kFaceB, kEdgeEdge };

/// The caller's per-pair state for depth tracking between ticks.
struct DepthCache {
  DepthFeature kind = DepthFeature::kNone;
  std::uint32_t ia = 0;         ///< face or edge of A
  std::uint32_t ib = 0;         ///< face or edge of B
  std::uint32_t support_a = 0;  ///< last support vertex hints
  std::uint32_t support_b = 0;
  Vec3 normal{0.0};  ///< last tick's minimal translation direction (a start for the next)
  /// Vertex pairs (a of A, b of B) of last tick's EPA polytope nearest its answer; EPA starts
  /// from them again (their points a - b are still points of A - B at the new pose).
  static constexpr int kWarm = 16;
  std::array<std::uint32_t, kWarm> warm_a{};
  std::array<std::uint32_t, kWarm> warm_b{};
  std::uint8_t warm_count = 0;
};

/// Scratch of the exact method for polytopes of up to `faces()` faces. Off the servo thread:
/// reserve() allocates; then any thread that owns it.
struct DepthScratch {
  std::vector<std::uint32_t> support_of_face;  ///< per face of A: B's support vertex against it
  std::vector<Vec3> neg_normal_b;              ///< per face of B: minus its normal in A's frame
  /// Room for polytopes of up to `faces` faces (grows only).
  void reserve(std::size_t faces);
  std::size_t faces() const { return std::min(support_of_face.size(), neg_normal_b.size()); }
  /// The calling thread's scratch (the default of the queries' `scratch`): it grows to the largest
  /// polytope this thread has queried, allocating when it grows.
  static DepthScratch& forThisThread();
};

/// Result of penetrationDepth(), in A's frame.
struct DepthResult {
  /// The MTD: >= 0 when the polytopes overlap; < 0 (minus a separating gap along `normal`, not
  /// the distance) when a separating axis was found.
  double depth = 0.0;
  Vec3 normal{0.0};   ///< unit: translating B by depth * normal separates (points from A toward B)
  Vec3 point_a{0.0};  ///< deepest point of A along normal (on A's surface)
  Vec3 point_b{0.0};  ///< deepest point of B against normal (point_b = point_a - depth * normal, up
                      ///< to the feature's extent)
  DepthFeature kind = DepthFeature::kNone;
  std::uint32_t ia = 0, ib = 0;
  /// Hints: a vertex of A extreme along normal, a vertex of B extreme against it (or near them).
  std::uint32_t support_a = 0, support_b = 0;
};

/// Exact MTD by separating axes. O(FA + FB + EA * EB) worst case. Updates `cache`. No
/// allocation when `scratch` holds the faces of both polytopes (else it grows: allocates); any
/// thread that owns `scratch` (by default the calling thread's: not for the servo thread).
DepthResult penetrationDepthExact(const Polytope& a,
                                  const Polytope& b,
                                  const Transform& X_AB,
                                  DepthCache& cache,
                                  DepthScratch& scratch = DepthScratch::forThisThread());

/// The MTD by GJK and EPA on A - B with climbed supports, started from last tick's direction.
/// Returns false, changing nothing the caller relies on, when it cannot certify its answer (the
/// final polytope must be convex, hold the origin, and its nearest face's support must meet that
/// face within 1e-11 of the size); then use penetrationDepthExact. No allocation; any thread.
bool penetrationDepthEpa(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         DepthCache& cache,
                         DepthResult& out);

/// The MTD: penetrationDepthEpa when it certifies its answer (hulls with more than 4096 edge
/// pairs), else penetrationDepthExact with `scratch`. No allocation when `scratch` holds the faces
/// of both polytopes; any thread that owns it (by default the calling thread's: not for the servo
/// thread).
DepthResult penetrationDepth(const Polytope& a,
                             const Polytope& b,
                             const Transform& X_AB,
                             DepthCache& cache,
                             DepthScratch& scratch = DepthScratch::forThisThread());

/// Per-pair state of the coherent exact depth (penetrationDepthCoherent): every candidate of the
/// exact method (face of B; edge of A with its arc's ends, faces of A, and crossings) with a lower
/// bound of its depth, in a min-heap. Sized off the servo thread by reserve(); then no query
/// allocates.
struct DepthTracker {
  /// One candidate: its depth is at least key - drift at the current pose.
  struct Entry {
    double key = 0.0;
    std::uint32_t code = 0;  ///< kind (kCodeFaceB, kCodeEdgeA) << 30 | index
    std::uint32_t hint = 0;  ///< a face of B's support hint (A's vertex)
  };
  static constexpr std::uint32_t kCodeFaceB = 1, kCodeEdgeA = 2;
  /// Counters since construction (a full solve is a fallback when a tracked state existed).
  struct Stats {
    std::uint64_t queries = 0;    ///< penetrationDepthCoherent calls
    std::uint64_t certified = 0;  ///< answered from the tracked state
    std::uint64_t fallbacks = 0;  ///< the certificate failed: the full method ran
    std::uint64_t cold = 0;       ///< no tracked state (first query, apart, or other polytopes)
    std::uint64_t evaluated = 0;  ///< candidates evaluated by certified queries
    /// certified queries at the last answer's pose bit for bit (that answer again, no candidate
    /// evaluated: a pair at rest, whose certificate may fail at that pose every time)
    std::uint64_t repeated = 0;
  } stats;

  /// Room for the pair (a, b) (allocates; off the servo thread). A tracker too small for a pair
  /// answers it by the full method (no allocation) and keeps no state.
  void reserve(const Polytope& a, const Polytope& b);
  /// Room for any pair whose polytopes have at most `faces` faces and `edges` edges each (a pool
  /// of trackers shared by many pairs, CollisionWorld). Allocates; off the servo thread.
  void reserve(std::size_t faces, std::size_t edges);
  /// Whether the reserved room holds the pair (a, b): then a query tracks it without allocating.
  bool fits(const Polytope& a, const Polytope& b) const;
  /// Bytes this tracker has reserved (its vectors' capacities).
  std::size_t reservedBytes() const;
  /// Bytes a tracker reserved by reserve(faces, edges) holds.
  static std::size_t bytesFor(std::size_t faces, std::size_t edges);
  /// Forget the tracked state (the next query solves in full).
  void reset() { valid = false; }
  /// Whether tracking is expected to beat penetrationDepth's warm-started EPA for this pair: up to
  /// 2^19 edge pairs (two 128-vertex hulls have about 1.4e5; two of 512, 2.3e6). Measured on the
  /// benchmark path (bench/README.md): 2x faster at 128 vertices, 1.4x slower at 512, where the
  /// per-query motion bound leaves about 60 candidates to evaluate. No lower bound: resting boxes
  /// track cheaper than the full method (Depth/Resting/4); resting prisms of 24 sides and more do
  /// not (k + 1 near-tied cap candidates), which this rule does not see (docs/narrow-phase.md).
  static bool pays(const Polytope& a, const Polytope& b) {
    return a.edges().size() * b.edges().size() <= (std::size_t{1} << 19);
  }

  // the tracked state (penetration.cpp); the heap's and popped's room is their capacity, which
  // a copy keeps (ReservedVector), so that a copied tracker tracks without allocating
  ReservedVector<Entry> heap;                      ///< min-heap on key
  ReservedVector<Entry> popped;                    ///< this query's evaluated entries
  std::vector<double> value_a, value_b, edge_min;  ///< the full solve's record
  std::vector<std::uint32_t> support_b;
  /// Per face of A: B's support vertex against it (the climbs' hints) and the query that last
  /// evaluated it (its depth is then value_a's); per face of B: minus its normal in A's frame and
  /// the query that computed it.
  std::vector<std::uint32_t> face_support_a;
  std::vector<std::uint64_t> stamp_a, stamp_b;
  std::vector<Vec3> neg_normal_b;
  std::uint64_t tick = 0;
  const Polytope* a = nullptr;
  const Polytope* b = nullptr;
  Transform last;      ///< the pose of the last answer
  DepthResult answer;  ///< the last answer (certified or the full method's)
  double drift =
      0.0;  ///< sum of the per-query bounds on the change of any depth since the full solve
  double limit = 0.0;  ///< drift at which a full solve is forced (keys lose no precision)
  bool valid = false;
};

/// The exact MTD (penetrationDepthExact's answer: same depth, normal, features and witnesses, up
/// to the rounding of tied support vertices), proven from the tracked state when it can be: the
/// candidates whose lower bound (last evaluated depth minus the pose change's Lipschitz bound
/// since) does not exceed the best depth found are evaluated exactly, nearest first; the answer
/// is certified when every other bound exceeds it and it is unique (docs/narrow-phase.md,
/// "Coherent exact depth"); at the last answer's pose, bit for bit, it is that answer. Else, or
/// without a state, penetrationDepthExact runs in full and rebuilds the state. No allocation once
/// `tracker` and `scratch` are reserved for the pair; any thread that owns them.
DepthResult penetrationDepthCoherent(const Polytope& a,
                                     const Polytope& b,
                                     const Transform& X_AB,
                                     DepthTracker& tracker,
                                     DepthCache& cache,
                                     DepthScratch& scratch = DepthScratch::forThisThread());

/// Translation distance along unit `dir` (A's frame) that B must move so the pair stops
/// overlapping: max over A of dot(dir, x) - min over B of dot(dir, x) (negative when already
/// separated along dir). `hint_a`, `hint_b`: support hints, updated.
double depthAlong(const Polytope& a,
                  const Polytope& b,
                  const Transform& X_AB,
                  const Vec3& dir,
                  std::uint32_t& hint_a,
                  std::uint32_t& hint_b);

}  // namespace hapticd::collision
