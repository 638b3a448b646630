#pragma once
// The demo scenes that have a recorded pose stream (scenes/NAME.glb, tests/streams/NAME.csv), as
// the parameters of the tests that replay each (demo_scenes_test.cpp, determinism_test.cpp), and
// the one loader of a committed demo scene the tests of core/sim share (targets that include this
// header link hapticd_scene and define HAPTICD_SOURCE_DIR).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/scene/glb.h"
#include "core/scene/loader.h"

namespace hapticd::simtest {

/// The names, as test parameters.
inline auto demoStreams() {
  return ::testing::Values("peg_in_hole", "gears", "dynamic", "stress", "decomposed");
}

/// A parameterised test's name suffix: the scene's name.
inline std::string demoStreamName(const ::testing::TestParamInfo<const char*>& info) {
  return info.param;
}

/// The committed scenes/NAME.glb, loaded; a load that fails fails the test (with its problems)
/// and gives nullptr.
inline std::shared_ptr<const scene::SceneModel> loadDemo(const std::string& name) {
  auto report = scene::loadSceneFile(std::string(HAPTICD_SOURCE_DIR) + "/scenes/" + name + ".glb");
  if (!report.ok()) {
    ADD_FAILURE() << name << ": " << report.message();
    return nullptr;
  }
  return std::make_shared<const scene::SceneModel>(std::move(*report.scene));
}

/// The committed scenes/NAME.glb with its geometry scaled by s, as a user gets it who wraps the
/// scene in a root node of scale s (a scene authored in mm is s = 1e3 in the scene's metres): the
/// glTF changed only by that node, and the scene's gravity (a length per s^2) times s. Declared
/// masses, inertias and stiffnesses are the file's (kg, kg m^2, N per scene unit): not scaled.
inline std::shared_ptr<const scene::SceneModel> loadDemoScaled(const std::string& name, double s) {
  const std::string file = std::string(HAPTICD_SOURCE_DIR) + "/scenes/" + name + ".glb";
  std::ifstream in(file, std::ios::binary);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                        std::istreambuf_iterator<char>()};
  auto chunks = scene::splitGlb(bytes);
  if (!chunks.ok()) {
    ADD_FAILURE() << file << ": " << chunks.error().message;
    return nullptr;
  }
  nlohmann::json doc = nlohmann::json::parse(chunks.value().json);
  nlohmann::json& sc = doc["scenes"][doc.value("scene", std::size_t{0})];
  nlohmann::json& nodes = doc["nodes"];
  nodes.push_back({{"name", "ScaleRoot"}, {"scale", {s, s, s}}, {"children", sc["nodes"]}});
  sc["nodes"] = nlohmann::json::array({nodes.size() - 1});
  if (sc.contains("extras") && sc["extras"].contains("haptic") &&
      sc["extras"]["haptic"].contains("gravity")) {
    for (auto& g : sc["extras"]["haptic"]["gravity"])
      g = g.get<double>() * s;
  }
  const std::vector<std::uint8_t> scaled = scene::packGlb(doc.dump(), chunks.value().bin);
  auto report = scene::loadScene(scaled, name);
  if (!report.ok()) {
    ADD_FAILURE() << name << " scaled by " << s << ": " << report.message();
    return nullptr;
  }
  return std::make_shared<const scene::SceneModel>(std::move(*report.scene));
}

}  // namespace hapticd::simtest
