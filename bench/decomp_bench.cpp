// Convex decomposition (core/decomp, docs/decomposition.md) beside the Debian peer HACD (Mamou and
// Ghorbel, "A simple and efficient approach for 3D mesh approximate convex decomposition", ICIP
// 2009; libbullet-extras-dev) on the same meshes in the same run:
//   Decompose/<model>/<concavity>            ours
//   Peer/HACD-decompose/<model>/<concavity>  HACD, its concavity measured by our metric
// Counters: pieces, concavity (fraction of the diagonal, our definition for both), volume_ratio
// and union_ratio (the pieces' volumes summed, and their union, over the model's; ours, closed
// models), seconds. One iteration each (a decomposition takes seconds). The real
// meshes of a shared/meshes/ folder are used when found (bench/README.md).
#include <HACD/hacdHACD.h>
#include <benchmark/benchmark.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>

#include "bench/decomp_meshes.h"
#include "core/decomp/decompose.h"
#include "tests/core/decomp/models.h"

namespace {

using hapticd::decomp::ConvexPiece;
using hapticd::decomp::TriangleMesh;
namespace models = hapticd::decomp::models;

constexpr double kConcavities[] = {0.05, 0.02, 0.01, 0.005};

const std::map<std::string, TriangleMesh>& meshes() {
  static const std::map<std::string, TriangleMesh> all = [] {
    std::map<std::string, TriangleMesh> m = hapticd::bench::decompMeshes();
    m["lblock"] = models::lBlock();
    return m;
  }();
  return all;
}

std::string label(double c) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", c);
  return buf;
}

void ours(benchmark::State& state, const std::string& model, double concavity) {
  const TriangleMesh& mesh = meshes().at(model);
  hapticd::decomp::DecompOptions o;
  o.concavity = concavity;
  hapticd::decomp::DecompReport report;
  for (auto _ : state) {
    auto r = hapticd::decomp::decompose(mesh, o);
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    report = r.value().report;
  }
  state.counters["pieces"] = static_cast<double>(report.pieces);
  state.counters["concavity"] = report.concavity;
  state.counters["concavity_bound"] = report.concavity_bound;
  state.counters["volume_ratio"] = report.volume_ratio;
  state.counters["union_ratio"] = report.union_ratio;
  state.counters["seconds"] = report.seconds;
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}

// HACD with its documented knobs: concavity in its normalised units (the model scaled to its
// scale factor, 1000), at least one cluster, 100 vertices per hull, Bullet's demo weights
void peerHacd(benchmark::State& state, const std::string& model, double concavity) {
  const TriangleMesh& mesh = meshes().at(model);
  // HACD had not finished after 10 minutes on the 70 000-triangle scan, nor after 5 on the CAD
  // part (bench/README.md); run those only when asked
  if ((mesh.triangles.size() > 20000 || model == "featuretype") &&
      std::getenv("HAPTICD_BENCH_SLOW_PEERS") == nullptr) {
    state.SkipWithError("HACD takes over 5 minutes here; set HAPTICD_BENCH_SLOW_PEERS=1 to run it");
    return;
  }
  std::vector<HACD::Vec3<HACD::Real>> points;
  std::vector<HACD::Vec3<long>> triangles;
  for (const auto& p : mesh.positions)
    points.emplace_back(p.x, p.y, p.z);
  for (const auto& t : mesh.triangles)
    triangles.emplace_back(static_cast<long>(t[0]), static_cast<long>(t[1]),
                           static_cast<long>(t[2]));
  std::vector<ConvexPiece> pieces;
  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    HACD::HACD h;
    h.SetPoints(points.data());
    h.SetNPoints(points.size());
    h.SetTriangles(triangles.data());
    h.SetNTriangles(triangles.size());
    h.SetCompacityWeight(0.1);
    h.SetVolumeWeight(0.0);
    h.SetNClusters(1);
    h.SetNVerticesPerCH(100);
    h.SetScaleFactor(1000.0);
    h.SetConcavity(concavity * 1000.0);
    h.SetAddExtraDistPoints(true);
    h.SetAddFacesPoints(true);
    h.SetAddNeighboursDistPoints(false);
    h.SetConnectDist(30.0);
    h.Compute();
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    pieces.clear();
    for (std::size_t i = 0; i < h.GetNClusters(); ++i) {
      std::vector<HACD::Vec3<HACD::Real>> cp(h.GetNPointsCH(i));
      std::vector<HACD::Vec3<long>> ct(h.GetNTrianglesCH(i));
      h.GetCH(i, cp.data(), ct.data());
      ConvexPiece piece;
      for (const auto& v : cp)
        piece.vertices.push_back({v.X(), v.Y(), v.Z()});
      pieces.push_back(std::move(piece));
    }
  }
  const auto measured = hapticd::decomp::measureConcavity(mesh, pieces, 1e-3);
  state.counters["pieces"] = static_cast<double>(pieces.size());
  state.counters["concavity"] = measured ? measured.value() : -1.0;
  state.counters["seconds"] = seconds;
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}

const bool registered = [] {
  for (const auto& [model, mesh] : meshes())
    for (double c : kConcavities) {
      const std::string name = model + "/" + label(c);
      benchmark::RegisterBenchmark(("Decompose/" + name).c_str(),
                                   [model = model, c](benchmark::State& s) { ours(s, model, c); })
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
      benchmark::RegisterBenchmark(
          ("Peer/HACD-decompose/" + name).c_str(),
          [model = model, c](benchmark::State& s) { peerHacd(s, model, c); })
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  return true;
}();

}  // namespace
