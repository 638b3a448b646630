#pragma once
/// \file
/// The one place where a mesh that is not convex becomes convex pieces (internal to
/// hapticd_scene): a mesh collider without `convexHull`, an OMI `trimesh` shape and a plain model's
/// mesh all come here. The pieces are those of the approximate convex decomposition of
/// core/decomp/decompose.h (issue "Polygonal models"; docs/decomposition.md) with the load's
/// DecompositionOptions (config [scene] concavity, max_pieces, decompose_time_limit_s; the
/// node's `extras.haptic.concavity`), read from the decomposition cache (decomp_cache.h) when an
/// entry is there; when it cannot decompose the mesh (no usable triangle), the mesh is touched
/// through its convex hull. The builder makes one primitive (ShapeSource::kMeshPiece) per piece
/// and `hapticctl check` says how the mesh was made convex. Any thread but the servo thread
/// (allocates, reads and writes the cache folder).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/pose.h"
#include "core/scene/loader.h"

namespace hapticd::scene::detail {

/// The convex pieces standing for one mesh: each a point set whose convex hull is the piece.
struct ConvexPieces {
  std::vector<std::vector<geom::Vec3>> pieces;
  /// How they were made, for the note `check` prints ("touched through 5 convex pieces ...").
  std::string method;
};

/// The meshes of one load made convex: its options, the cache, progress, counts and warnings.
class Decomposer {
 public:
  explicit Decomposer(const LoadOptions& options) : options_(options) {}

  /// The pieces of the mesh `points` / `triangles` (3 indices each, into points; the mesh may be
  /// open, non-manifold, inconsistently wound), in the mesh's frame, decomposed to `concavity`
  /// (a fraction of its diagonal, in (0, 1)), from the cache when it has them. `name` names it in
  /// progress and warnings; `why` (why it is decomposed: "not convex") begins the method.
  ConvexPieces convexPieces(std::span<const geom::Vec3> points,
                            std::span<const std::uint32_t> triangles,
                            double concavity,
                            const std::string& name,
                            const std::string& why = "not convex");
  /// The same mesh's pieces from the cache only: nothing when there is no cache, no entry, or
  /// the entry is refused (then a warning, and the entry is removed so that convexPieces()
  /// decomposes and writes it again). An entry exists only for a mesh that was decomposed, so a
  /// hit also says the mesh needs its pieces.
  std::optional<ConvexPieces> cachedPieces(std::span<const geom::Vec3> points,
                                           std::span<const std::uint32_t> triangles,
                                           double concavity,
                                           const std::string& name);

  const DecompositionCounts& counts() const { return counts_; }
  std::vector<std::string> takeWarnings() { return std::move(warnings_); }

 private:
  // the mesh as core/decomp takes it, and its options
  struct Input;
  Input input(std::span<const geom::Vec3> points,
              std::span<const std::uint32_t> triangles,
              double concavity) const;
  std::optional<ConvexPieces> lookup(const Input& in, const std::string& name);

  const LoadOptions& options_;
  DecompositionCounts counts_;
  std::vector<std::string> warnings_;
  bool write_warned_ = false;  // one warning per load for a folder that cannot be written
};

}  // namespace hapticd::scene::detail
