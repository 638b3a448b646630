// hapticctl check's text report (client/check.h): the pairs that collision filters keep apart are
// named up to a bound, then counted, so a scene with thousands of such pairs stays readable.
#include "client/check.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/core/scene/gltf_builder.h"

namespace hapticd::client {
namespace {

using scene::testing::GltfBuilder;
using scene::testing::json;

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
  const scene::LoadReport r = scene::loadScene(
      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), "crates.gltf");
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

}  // namespace
}  // namespace hapticd::client
