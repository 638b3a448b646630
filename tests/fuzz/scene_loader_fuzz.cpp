// libFuzzer target for the scene loader: any bytes, as .glb or .gltf, must load or be refused
// with problems, never crash, hang or leak (run under ASan+UBSan, tests/fuzz/CMakeLists.txt).
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/scene/loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapticd::scene::LoadOptions options;
  // small limits keep each input fast; the checks are the same at any limit
  options.limits.max_hull_input_points = 20000;
  options.limits.max_total_hull_input_points = 100000;
  options.limits.tessellation_tolerance = 1e-2;
  // and a non-convex mesh is decomposed into a few pieces within a short wall-clock limit (the
  // default's 5 s per mesh, slowed by the sanitizers, let one input of several meshes pass
  // libFuzzer's 10 s timeout); the decomposition has its own tests
  options.decomposition.max_pieces = 8;
  options.decomposition.time_limit_s = 0.5;
  const auto report = hapticd::scene::loadScene(std::span(data, size), "fuzz", options);
  if (report.ok() == report.problems.empty())
    return 0;
  __builtin_trap();  // the report must be a scene or problems, never both or neither
}
