#pragma once
// hapticbench helper: the meshes the decomposition benchmarks run on (bench/decomp_bench.cpp,
// bench/hull_bench.cpp): the generated torus, gear and 70 000-triangle scan of the decomposition
// tests, and the real meshes of a shared/meshes/ folder when found (bench/README.md).
#include <map>
#include <string>

#include "core/decomp/decompose.h"
#include "tests/core/decomp/models.h"

namespace hapticd::bench {

/// The models by name; built on each call (callers keep them in a function-local static).
inline std::map<std::string, decomp::TriangleMesh> decompMeshes() {
  namespace models = decomp::models;
  std::map<std::string, decomp::TriangleMesh> m;
  m["torus"] = models::torus();
  m["gear"] = models::gear();
  m["scan70k"] = models::noisySphere(0.1, 70000, 0.002, 5, 0.06);
  if (auto d = models::sharedMesh("dragon_lowres.obj"))
    m["dragon"] = *d;
  if (auto f = models::sharedMesh("featuretype.STL"))
    m["featuretype"] = *f;
  return m;
}

}  // namespace hapticd::bench
