// hapticctl check's text report (client/check.h): the pairs that collision filters keep apart are
// named up to a bound, then counted, so a scene with thousands of such pairs stays readable; the
// bodies that start overlapping are named with their depth.
#include "client/check.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/core/scene/gltf_builder.h"

namespace hapticd::client {
namespace {

using scene::testing::GltfBuilder;
using scene::testing::json;

/// The loader's report of glTF `text`.
scene::LoadReport loadText(const std::string& text, const char* name) {
  return scene::loadScene(
      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), name);
}

/// `n` dynamic boxes in one collision system that never collides with itself: every pair of
/// them is kept apart, n (n - 1) / 2 pairs.
std::string reportOfApartBodies(int n) {
  GltfBuilder b;
  b.doc["extensions"]["KHR_physics_rigid_bodies"]["collisionFilters"] =
      json::array({{{"collisionSystems", {"crates"}}, {"notCollideWithSystems", {"crates"}}}});
  const int box = b.box({0.1, 0.1, 0.1});
  for (int i = 0; i < n; ++i) {
    json node = GltfBuilder::node("Crate" + std::to_string(i), {0.2 * i, 0.0, 0.0});
    GltfBuilder::physics(node)["motion"] = json::object();
    GltfBuilder::physics(node)["collider"] =
        GltfBuilder::shapeCollider(box, {{"collisionFilter", 0}});
    b.addNode(node);
  }
  const std::string text = b.gltf();
  const scene::LoadReport r = loadText(text, "crates.gltf");
  EXPECT_TRUE(r.ok()) << r.message();
  return r.ok() ? describeScene(*r.scene) : std::string();
}

std::size_t countOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

TEST(CheckReport, KeptApartPairsAreListedThenSummarised) {
  // 10 bodies: 45 pairs, every one named
  const std::string few = reportOfApartBodies(10);
  EXPECT_NE(few.find("collision filters keep apart:\n  'Crate0' and 'Crate1'\n"), std::string::npos)
      << few;
  EXPECT_EQ(countOf(few, "' and '"), 45u);
  EXPECT_EQ(few.find("more pairs"), std::string::npos);

  // 80 bodies: 3160 pairs, 50 named and the rest counted
  const std::string many = reportOfApartBodies(80);
  EXPECT_EQ(countOf(many, "' and '"), 50u);
  EXPECT_NE(many.find("  ... and 3110 more pairs\n"), std::string::npos) << many;
}

// A floor, a crate of edge 0.1 `unit` placed `sink` of its edge into it, and a second crate
// resting on it (placed touching), as glTF text.
std::string sunkCrate(double unit, double sink) {
  GltfBuilder b;
  const int floor = b.box({4.0 * unit, 0.2 * unit, 4.0 * unit});
  const int crate = b.box({0.1 * unit, 0.1 * unit, 0.1 * unit});
  json f = GltfBuilder::node("Floor", {0.0, -0.1 * unit, 0.0});
  GltfBuilder::physics(f)["collider"] = GltfBuilder::shapeCollider(floor);
  b.addNode(f);
  const double ys[] = {0.05 * unit - sink * 0.1 * unit, 0.05 * unit};
  for (int i = 0; i < 2; ++i) {
    json node = GltfBuilder::node(i == 0 ? "Sunk" : "Resting", {0.5 * unit * i, ys[i], 0.0});
    GltfBuilder::physics(node)["motion"] = json::object();
    GltfBuilder::physics(node)["collider"] = GltfBuilder::shapeCollider(crate);
    b.addNode(node);
  }
  return b.gltf();
}

// A part placed into the floor (as `hapticctl import --at` places a model's origin, not its
// bottom) is named with its depth, in text and JSON; a body resting on the floor is not, nor one
// sunk by less than 1e-3 of its size; the same in mm, m and km
TEST(CheckReport, BodiesThatStartOverlappingAreNamedWithTheirDepth) {
  for (const double unit : {1e-3, 1.0, 1e3}) {
    const std::string text = sunkCrate(unit, 0.3);
    const scene::LoadReport r = loadText(text, "sunk.gltf");
    ASSERT_TRUE(r.ok()) << r.message();
    const std::string report = describeScene(*r.scene);
    const std::size_t at = report.find("bodies that start overlapping");
    ASSERT_NE(at, std::string::npos) << report;
    const std::string listed = report.substr(at, report.find("plan:") - at);
    EXPECT_EQ(countOf(listed, " overlaps "), 1u) << listed;
    EXPECT_NE(listed.find("'Sunk' (dynamic) overlaps 'Floor' (static) by " +
                          [&] {
                            std::ostringstream o;
                            o << 0.03 * unit;
                            return o.str();
                          }() +
                          " m"),
              std::string::npos)
        << listed;
    EXPECT_EQ(listed.find("Resting"), std::string::npos) << listed;

    const scene::LoadReport rs = loadText(sunkCrate(unit, 0.5e-3), "shallow.gltf");
    ASSERT_TRUE(rs.ok()) << rs.message();
    EXPECT_EQ(describeScene(*rs.scene).find("start overlapping"), std::string::npos) << unit;
  }
  // --json: "overlaps", the bodies' indices and the depth
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("check_sunk_" + std::to_string(::getpid()) + ".gltf");
  std::ofstream(file) << sunkCrate(1.0, 0.3);
  CheckOptions o;
  o.json = true;
  std::ostringstream out, err;
  EXPECT_EQ(runCheck(file, o, out, err), 0) << err.str();
  std::filesystem::remove(file);
  const nlohmann::json j = nlohmann::json::parse(out.str());
  ASSERT_EQ(j["overlaps"].size(), 1u) << out.str();
  const auto nameOf = [&](const char* side) {
    return j["bodies"][j["overlaps"][0][side].get<std::size_t>()]["name"].get<std::string>();
  };
  EXPECT_EQ(nameOf("body_a") + " " + nameOf("body_b"), "Sunk Floor");
  EXPECT_NEAR(j["overlaps"][0]["depth_m"].get<double>(), 0.03, 1e-9);
}

}  // namespace
}  // namespace hapticd::client
