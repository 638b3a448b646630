#pragma once
/// \file
/// Test helpers of the scene loader's tests: load a GltfBuilder's scene, find a body, look for a
/// problem or a note, add shape bodies. Header-only, test code.

#include <gtest/gtest.h>

#include <string>

#include "core/scene/loader.h"
#include "tests/core/scene/gltf_builder.h"

namespace hapticd::scene::testing {

/// Loads the builder's scene as .gltf text.
inline LoadReport load(const GltfBuilder& b, const LoadOptions& options = {}) {
  const std::string text = b.gltf();
  return loadScene(bytesOf(text), "test.gltf", options);
}

inline const Body& bodyNamed(const SceneModel& s, const std::string& name) {
  for (const Body& b : s.bodies) {
    if (b.name == name)
      return b;
  }
  ADD_FAILURE() << "no body " << name;
  return s.bodies.front();
}

/// A dynamic body node with a collider of `shape`.
inline int dynamicShape(GltfBuilder& b,
                        const std::string& name,
                        int shape,
                        Vec3 t,
                        json motion = json::object()) {
  json n = GltfBuilder::node(name, t);
  GltfBuilder::physics(n)["motion"] = motion;
  GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(shape);
  return b.addNode(n);
}

inline int staticShape(GltfBuilder& b,
                       const std::string& name,
                       int shape,
                       Vec3 t,
                       int parent = -1) {
  json n = GltfBuilder::node(name, t);
  GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(shape);
  return b.addNode(n, parent);
}

inline bool hasProblem(const LoadReport& r, const std::string& what) {
  return r.message().find(what) != std::string::npos;
}

/// The plan's notes, one per line.
inline std::string notesOf(const SceneModel& s) {
  std::string out;
  for (const std::string& n : s.plan.notes)
    out += n + "\n";
  return out;
}

}  // namespace hapticd::scene::testing
