// hapticbench, scene loading of compressed geometry: SceneLoad/quantized5MB a generated ~5 MB
// .glb of 640 static mesh-hull colliders whose 1 024 positions each are KHR_mesh_quantization
// SHORT normalized; SceneLoad/draco and SceneLoad/meshopt 200 icospheres of 642 vertices (1 280
// triangles) as KHR_draco_mesh_compression streams and as EXT_meshopt_compression views. One
// iteration is one whole loadScene from bytes in memory (parse, validate, decode, hulls, plan).
#include <benchmark/benchmark.h>

#include <random>

#include "bench/scene_load.h"
#include "core/scene/loader.h"
#include "scenes/meshes.h"
#include "tests/core/scene/encoded_mesh.h"

namespace hapticd::bench {
namespace {

using scene::testing::GltfBuilder;
using scene::testing::json;

/// A static node at (x, 0, z) whose collider is the convex hull of its own mesh, scaled by `s`.
void hullNode(GltfBuilder& b, int mesh, int i, double s) {
  json n = GltfBuilder::node("Part" + std::to_string(i), {0.2 * (i % 32), 0.0, 0.2 * (i / 32)});
  n["mesh"] = mesh;
  n["scale"] = {s, s, s};
  GltfBuilder::physics(n)["collider"] = {
      {"geometry", {{"node", b.doc["nodes"].size()}, {"convexHull", true}}}};
  b.addNode(n);
}

std::vector<std::uint8_t> quantizedScene() {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  GltfBuilder b;
  for (int i = 0; i < 640; ++i) {
    scene::testing::Mesh mesh;
    for (int v = 0; v < 1024; ++v)
      mesh.vertices.push_back(0.9 * glm::normalize(geom::Vec3{g(rng), g(rng), g(rng)}));
    mesh.triangles = {0, 1, 2};  // a hull needs only the vertices
    hullNode(b, scene::testing::addQuantizedMesh(b, mesh, 5122, true), i, 0.05);
  }
  return b.glb();
}

scene::testing::Mesh icosphere() {
  const scenes::MeshData m = scenes::icosphereMesh(geom::Vec3{1.0}, 3);
  scene::testing::Mesh out;
  out.vertices = m.positions;
  for (const auto& t : m.triangles)
    out.triangles.insert(out.triangles.end(), t.begin(), t.end());
  return out;
}

std::vector<std::uint8_t> compressedScene(bool draco) {
  const scene::testing::Mesh sphere = icosphere();
  GltfBuilder b;
  for (int i = 0; i < 200; ++i) {
    const int mesh = draco ? scene::testing::addDracoMesh(b, sphere, "Sphere")
                           : scene::testing::addMeshoptMesh(b, sphere, "Sphere", "EXPONENTIAL");
    hullNode(b, mesh, i, 0.05);
  }
  return b.glb();
}

void BM_Quantized5MB(benchmark::State& state) {
  static const std::vector<std::uint8_t> bytes = quantizedScene();
  loadSceneBytes(state, bytes, "quantized5MB.glb");
}
void BM_Draco(benchmark::State& state) {
  static const std::vector<std::uint8_t> bytes = compressedScene(true);
  loadSceneBytes(state, bytes, "draco.glb");
}
void BM_Meshopt(benchmark::State& state) {
  static const std::vector<std::uint8_t> bytes = compressedScene(false);
  loadSceneBytes(state, bytes, "meshopt.glb");
}

BENCHMARK(BM_Quantized5MB)->Name("SceneLoad/quantized5MB")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Draco)->Name("SceneLoad/draco")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Meshopt)->Name("SceneLoad/meshopt")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hapticd::bench
