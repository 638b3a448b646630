#include "core/scene/decompose.h"

#include <algorithm>
#include <cmath>

#include "core/decomp/decompose.h"
#include "core/scene/decomp_cache.h"
#include "core/scene/json_checker.h"

namespace hapticd::scene::detail {

ConvexPieces Decomposer::convexPieces(std::span<const geom::Vec3> points,
                                      std::span<const std::uint32_t> triangles,
                                      double concavity,
                                      const std::string& name) {
  decomp::TriangleMesh mesh;
  mesh.positions.assign(points.begin(), points.end());
  for (std::size_t i = 0; i + 2 < triangles.size(); i += 3)
    mesh.triangles.push_back({triangles[i], triangles[i + 1], triangles[i + 2]});
  const DecompositionOptions& knobs = options_.decomposition;
  decomp::DecompOptions options;
  options.concavity = concavity;
  options.max_pieces = knobs.max_pieces;
  options.time_limit_s = knobs.time_limit_s;
  options.threads = 1;  // the loader's own thread; the result is the same for any count
  // every piece must pass the loader's hull limit (core/decomp's least is 8)
  options.max_piece_vertices = std::max<std::size_t>(
      8, std::min<std::size_t>(options.max_piece_vertices, options_.limits.max_hull_vertices));

  // the cache first: an entry is used only when every check passes
  const bool cached = !knobs.cache_dir.empty();
  std::string key;
  if (cached) {
    key = decompCacheKey(mesh, options);
    CacheLookup found = readCacheEntry(knobs.cache_dir, key, knobs.max_pieces);
    if (found.status == CacheLookup::Status::kHit) {
      ++counts_.cache_hits;
      return {std::move(found.pieces.pieces), std::move(found.pieces.note)};
    }
    if (found.status == CacheLookup::Status::kRefused) {
      ++counts_.cache_refused;
      warnings_.push_back("decomposition cache: entry " +
                          cacheEntryPath(knobs.cache_dir, key).string() + " for " + name +
                          " refused (" + found.why + "); decomposing again");
    }
  }

  ++counts_.decomposed;
  decomp::ProgressFn progress;
  if (options_.progress) {
    progress = [&](const decomp::Progress& p) {
      LoadProgress lp;
      lp.mesh = counts_.decomposed;
      lp.mesh_name = name;
      lp.pieces = p.pieces;
      lp.elapsed_s = p.elapsed_s;
      lp.stage = p.stage;
      options_.progress(lp);
    };
  }
  auto result = decomp::decompose(mesh, options, progress);
  ConvexPieces out;
  if (!result || result.value().pieces.empty()) {
    out.pieces.emplace_back(points.begin(), points.end());
    out.method = "touched through its convex hull (the convex decomposition could not run: " +
                 (result ? std::string("no piece") : result.error().message) +
                 "; dents, holes and hollows are filled)";
    return out;  // not cached: nothing was computed worth keeping
  }
  const decomp::DecompReport& report = result.value().report;
  for (decomp::ConvexPiece& piece : result.value().pieces)
    out.pieces.push_back(std::move(piece.vertices));
  out.method = "touched through " + std::to_string(out.pieces.size()) +
               " convex pieces (convex decomposition, concavity " +
               formatNumber(std::round(report.concavity * 1e4) / 1e4) +
               " of its diagonal, target " + formatNumber(concavity) +
               (report.time_limit_hit ? "; stopped at its time limit" : "") +
               (report.max_pieces_hit ? "; stopped at its piece limit" : "") + ")";
  if (cached) {
    auto written = writeCacheEntry(knobs.cache_dir, key, {out.pieces, out.method});
    if (written) {
      ++counts_.cache_written;
    } else if (!write_warned_) {
      write_warned_ = true;
      warnings_.push_back("decomposition cache: " + written.error().message +
                          "; the pieces are not cached (the scene loads all the same)");
    }
  }
  return out;
}

}  // namespace hapticd::scene::detail
