// hapticbench, scene loading: SceneLoad/<name> loads and prepares each demo scene of scenes/
// (parse, validate, hulls, tessellation, mass properties, plan: everything loadScene does), from
// bytes already in memory; SceneLoad/10MB a generated ~10 MB .glb of 200 dynamic bodies with 10
// mesh-hull colliders of 400 points each. One iteration is one whole load.
#include <benchmark/benchmark.h>

#include <fstream>
#include <random>

#include "bench/scene_load.h"
#include "core/scene/loader.h"
#include "tests/core/scene/gltf_builder.h"

namespace hapticd::bench {
namespace {

std::vector<std::uint8_t> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return {};
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void demoScene(benchmark::State& state, const char* name) {
  const std::string path = std::string(HAPTICD_SOURCE_DIR "/scenes/") + name + ".glb";
  const auto bytes = readFile(path);
  if (bytes.empty()) {
    state.SkipWithError((path + " is absent (the scene generator writes it)").c_str());
    return;
  }
  loadSceneBytes(state, bytes, std::string(name) + ".glb");
}

std::vector<std::uint8_t> tenMegabyteScene() {
  using scene::testing::GltfBuilder;
  using scene::testing::json;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  GltfBuilder b;
  json floor = GltfBuilder::node("Floor", {0.0, -0.5, 0.0});
  GltfBuilder::physics(floor)["collider"] = GltfBuilder::shapeCollider(b.box({20.0, 1.0, 20.0}));
  b.addNode(floor);
  for (int body = 0; body < 200; ++body) {
    json n = GltfBuilder::node("Body" + std::to_string(body),
                               {0.5 * (body % 20) - 5.0, 1.0, 0.5 * (body / 20) - 5.0});
    GltfBuilder::physics(n)["motion"] = json::object();
    const int parent = b.addNode(n);
    for (int part = 0; part < 10; ++part) {
      scene::testing::Mesh mesh;
      for (int v = 0; v < 400; ++v) {
        const geom::Vec3 d = glm::normalize(geom::Vec3{g(rng), g(rng), g(rng)});
        mesh.vertices.push_back(0.04 * d * geom::Vec3{1.0, 0.6, 0.8});
      }
      json c = GltfBuilder::node("Part", {0.0, 0.03 * part, 0.0});
      c["mesh"] = b.addMesh(mesh);
      const int index = static_cast<int>(b.doc["nodes"].size());
      GltfBuilder::physics(c)["collider"] = {{"geometry", {{"node", index}, {"convexHull", true}}}};
      b.addNode(c, parent);
    }
  }
  return b.glb();
}

void BM_SceneLoad10MB(benchmark::State& state) {
  static const std::vector<std::uint8_t> bytes = tenMegabyteScene();
  loadSceneBytes(state, bytes, "10MB.glb");
}

void registerAll() {
  for (const char* scene : {"gears", "peg_in_hole", "dynamic", "stress"}) {
    benchmark::RegisterBenchmark(("SceneLoad/" + std::string(scene)).c_str(), demoScene, scene)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("SceneLoad/10MB", BM_SceneLoad10MB)->Unit(benchmark::kMillisecond);
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace hapticd::bench
