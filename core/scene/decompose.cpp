#include "core/scene/decompose.h"

#include <cmath>

#include "core/decomp/decompose.h"
#include "core/scene/json_checker.h"

namespace hapticd::scene::detail {

ConvexPieces convexPieces(std::span<const geom::Vec3> points,
                          std::span<const std::uint32_t> triangles) {
  decomp::TriangleMesh mesh;
  mesh.positions.assign(points.begin(), points.end());
  for (std::size_t i = 0; i + 2 < triangles.size(); i += 3)
    mesh.triangles.push_back({triangles[i], triangles[i + 1], triangles[i + 2]});
  decomp::DecompOptions options;
  options.concavity = kDecompConcavity;
  options.max_pieces = kDecompMaxPieces;
  options.time_limit_s = kDecompTimeLimitS;
  options.threads = 1;  // the loader's own thread; the result is the same for any count
  auto result = decomp::decompose(mesh, options);
  ConvexPieces out;
  if (!result || result.value().pieces.empty()) {
    out.pieces.emplace_back(points.begin(), points.end());
    out.method = "touched through its convex hull (the convex decomposition could not run: " +
                 (result ? std::string("no piece") : result.error().message) +
                 "; dents, holes and hollows are filled)";
    return out;
  }
  const decomp::DecompReport& report = result.value().report;
  for (decomp::ConvexPiece& piece : result.value().pieces)
    out.pieces.push_back(std::move(piece.vertices));
  out.method = "touched through " + std::to_string(out.pieces.size()) +
               " convex pieces (convex decomposition, concavity " +
               formatNumber(std::round(report.concavity * 1e4) / 1e4) +
               " of its diagonal, target " + formatNumber(kDecompConcavity) +
               (report.time_limit_hit ? "; stopped at its time limit" : "") +
               (report.max_pieces_hit ? "; stopped at its piece limit" : "") + ")";
  return out;
}

}  // namespace hapticd::scene::detail
