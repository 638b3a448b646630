// The second load of a mesh that is not convex, from the decomposition cache (issue 16 item 3,
// docs/scenes.md "Decomposition at load"; target: <= 50 ms for a 70 000-triangle model):
//   Decompose/cached/<model>        the loader's Decomposer on a mesh whose entry is in the cache:
//                                   the key (SHA-256 over the mesh's bytes), the entry read, its
//                                   checksum and every check, the pieces
//   Decompose/cached_scene/<model>  a whole scene::loadScene of a one-mesh plain model (.glb) whose
//                                   entry is in the cache: parse, the mesh's own hull and convexity
//                                   test, the cache read, the pieces' hulls
// The models of bench/decomp_meshes.h (torus, gear, the 70 000-triangle scan, the shared dragon
// when found); the first decomposition fills a temporary cache folder before the timing, and
// every timed iteration must be a cache hit (else the benchmark fails).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench/decomp_meshes.h"
#include "core/scene/decompose.h"
#include "core/scene/loader.h"
#include "tests/core/scene/gltf_builder.h"

namespace {

namespace fs = std::filesystem;
using hapticd::decomp::TriangleMesh;
namespace scene = hapticd::scene;

// one folder for the run, removed at exit
const fs::path& cacheDir() {
  static const struct Dir {
    fs::path path =
        fs::temp_directory_path() / ("hapticbench_decomp_cache_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

const std::map<std::string, TriangleMesh>& meshes() {
  static const std::map<std::string, TriangleMesh> all = [] {
    std::map<std::string, TriangleMesh> m = hapticd::bench::decompMeshes();
    m.erase("featuretype");  // its first decomposition alone takes a minute here
    return m;
  }();
  return all;
}

std::vector<std::uint32_t> flat(const TriangleMesh& mesh) {
  std::vector<std::uint32_t> out;
  out.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    out.insert(out.end(), t.begin(), t.end());
  return out;
}

scene::LoadOptions cachedOptions() {
  scene::LoadOptions o;
  o.decomposition.cache_dir = cacheDir();
  return o;
}

void cachedPieces(benchmark::State& state, const std::string& model) {
  const TriangleMesh& mesh = meshes().at(model);
  const std::vector<std::uint32_t> triangles = flat(mesh);
  const scene::LoadOptions options = cachedOptions();
  const double concavity = options.decomposition.concavity;
  {
    scene::detail::Decomposer first(options);  // fills the cache (not timed)
    (void)first.convexPieces(mesh.positions, triangles, concavity, model);
  }
  std::size_t pieces = 0;
  for (auto _ : state) {
    scene::detail::Decomposer again(options);
    const auto out = again.convexPieces(mesh.positions, triangles, concavity, model);
    if (again.counts().cache_hits != 1) {
      state.SkipWithError("not read from the cache");
      return;
    }
    pieces = out.pieces.size();
    benchmark::DoNotOptimize(out.pieces.data());
  }
  state.counters["pieces"] = static_cast<double>(pieces);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}

void cachedScene(benchmark::State& state, const std::string& model) {
  const TriangleMesh& mesh = meshes().at(model);
  hapticd::scene::testing::GltfBuilder b;
  hapticd::scene::testing::Mesh m;
  m.vertices = mesh.positions;
  m.triangles = flat(mesh);
  auto node = hapticd::scene::testing::GltfBuilder::node(model);
  node["mesh"] = b.addMesh(m, model);
  b.addNode(node);
  const std::vector<std::uint8_t> glb = b.glb();
  const scene::LoadOptions options = cachedOptions();
  const scene::LoadReport first = scene::loadScene(glb, model, options);
  if (!first.ok()) {
    state.SkipWithError(("the scene does not load: " + first.message()).c_str());
    return;
  }
  std::size_t primitives = 0;
  bool decomposed = first.decomposition.decomposed + first.decomposition.cache_hits > 0;
  for (auto _ : state) {
    const scene::LoadReport r = scene::loadScene(glb, model, options);
    if (!r.ok() || r.decomposition.decomposed != 0) {
      state.SkipWithError("the second load did not come from the cache");
      return;
    }
    primitives = r.scene->plan.static_primitives;
    benchmark::DoNotOptimize(r.scene->bodies.data());
  }
  state.counters["primitives"] = static_cast<double>(primitives);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["bytes"] = static_cast<double>(glb.size());
  state.counters["decomposed"] = decomposed ? 1.0 : 0.0;  // 0: the mesh was convex
}

const bool registered = [] {
  for (const auto& [model, mesh] : meshes()) {
    benchmark::RegisterBenchmark(("Decompose/cached/" + model).c_str(),
                                 [model = model](benchmark::State& s) { cachedPieces(s, model); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("Decompose/cached_scene/" + model).c_str(),
                                 [model = model](benchmark::State& s) { cachedScene(s, model); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  return true;
}();

}  // namespace
