#pragma once
// hapticbench helper: one whole scene::loadScene per iteration from bytes in memory, with the
// bytes and primitive counters (bench/scene_load_bench.cpp, bench/scene_load_decoders_bench.cpp).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "core/scene/loader.h"

namespace hapticd::bench {

inline void loadSceneBytes(benchmark::State& state,
                           const std::vector<std::uint8_t>& bytes,
                           const std::string& name) {
  std::size_t primitives = 0;
  for (auto _ : state) {
    const scene::LoadReport r = scene::loadScene(bytes, name);
    if (!r.ok()) {
      state.SkipWithError(("the scene does not load: " + r.message()).c_str());
      return;
    }
    primitives = r.scene->plan.static_primitives + r.scene->plan.moving_primitives;
    benchmark::DoNotOptimize(r.scene->bodies.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes.size()));
  state.counters["bytes"] = static_cast<double>(bytes.size());
  state.counters["primitives"] = static_cast<double>(primitives);
}

}  // namespace hapticd::bench
