#include "core/scene/decompose.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <system_error>

#include "core/decomp/decompose.h"
#include "core/scene/decomp_cache.h"
#include "core/scene/json_checker.h"

namespace hapticd::scene::detail {

struct Decomposer::Input {
  decomp::TriangleMesh mesh;
  decomp::DecompOptions options;
  std::string key;  // "" without a cache
};

Decomposer::Input Decomposer::input(std::span<const geom::Vec3> points,
                                    std::span<const std::uint32_t> triangles,
                                    double concavity) const {
  Input in;
  in.mesh.positions.assign(points.begin(), points.end());
  for (std::size_t i = 0; i + 2 < triangles.size(); i += 3)
    in.mesh.triangles.push_back({triangles[i], triangles[i + 1], triangles[i + 2]});
  const DecompositionOptions& knobs = options_.decomposition;
  in.options.concavity = concavity;
  in.options.max_pieces = knobs.max_pieces;
  in.options.time_limit_s = knobs.time_limit_s;
  in.options.threads = 1;  // the loader's own thread; the result is the same for any count
  // every piece must pass the loader's hull limit (core/decomp's least is 8)
  in.options.max_piece_vertices = std::max<std::size_t>(
      8, std::min<std::size_t>(in.options.max_piece_vertices, options_.limits.max_hull_vertices));
  if (!knobs.cache_dir.empty())
    in.key = decompCacheKey(in.mesh, in.options, options_.limits.max_hull_vertices);
  return in;
}

std::optional<ConvexPieces> Decomposer::lookup(const Input& in, const std::string& name) {
  if (in.key.empty())
    return std::nullopt;
  const DecompositionOptions& knobs = options_.decomposition;
  CacheLookup found = readCacheEntry(knobs.cache_dir, in.key, knobs.max_pieces);
  if (found.status == CacheLookup::Status::kHit) {
    ++counts_.cache_hits;
    return ConvexPieces{std::move(found.pieces.pieces), std::move(found.pieces.note)};
  }
  if (found.status == CacheLookup::Status::kRefused) {
    ++counts_.cache_refused;
    const std::filesystem::path path = cacheEntryPath(knobs.cache_dir, in.key);
    warnings_.push_back("decomposition cache: entry " + path.string() + " for " + name +
                        " refused (" + found.why + "); decomposing again");
    std::error_code ec;
    std::filesystem::remove(path, ec);  // rewritten after the decomposition
  }
  return std::nullopt;
}

std::optional<ConvexPieces> Decomposer::cachedPieces(std::span<const geom::Vec3> points,
                                                     std::span<const std::uint32_t> triangles,
                                                     double concavity,
                                                     const std::string& name) {
  if (options_.decomposition.cache_dir.empty())
    return std::nullopt;
  return lookup(input(points, triangles, concavity), name);
}

ConvexPieces Decomposer::convexPieces(std::span<const geom::Vec3> points,
                                      std::span<const std::uint32_t> triangles,
                                      double concavity,
                                      const std::string& name,
                                      const std::string& why) {
  Input in = input(points, triangles, concavity);
  // the cache first: an entry is used only when every check passes
  if (auto cached = lookup(in, name))
    return std::move(*cached);
  const decomp::TriangleMesh& mesh = in.mesh;
  const decomp::DecompOptions& options = in.options;
  const bool caching = !in.key.empty();
  const std::string& key = in.key;
  const DecompositionOptions& knobs = options_.decomposition;

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
    out.method = why +
                 ", touched through its convex hull (the convex decomposition could not run: " +
                 (result ? std::string("no piece") : result.error().message) +
                 "; dents, holes and hollows are filled)";
    return out;  // not cached: nothing was computed worth keeping
  }
  const decomp::DecompReport& report = result.value().report;
  for (decomp::ConvexPiece& piece : result.value().pieces)
    out.pieces.push_back(std::move(piece.vertices));
  out.method = why + ", touched through " + std::to_string(out.pieces.size()) +
               " convex pieces (convex decomposition, concavity " +
               formatNumber(std::round(report.concavity * 1e4) / 1e4) +
               " of its diagonal, target " + formatNumber(concavity) +
               (report.time_limit_hit ? "; stopped at its time limit" : "") +
               (report.max_pieces_hit ? "; stopped at its piece limit" : "") + ")";
  if (caching) {
    auto written = writeCacheEntry(knobs.cache_dir, key, {out.pieces, out.method});
    if (written) {
      ++counts_.cache_written;
      counts_.cache_evicted += evictCache(knobs.cache_dir, knobs.cache_max_bytes, key).entries;
    } else if (!write_warned_) {
      write_warned_ = true;
      warnings_.push_back("decomposition cache: " + written.error().message +
                          "; the pieces are not cached (the scene loads all the same)");
    }
  }
  return out;
}

}  // namespace hapticd::scene::detail
