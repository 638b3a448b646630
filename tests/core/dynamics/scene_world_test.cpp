// The one scene -> CollisionWorld builder (core/dynamics/scene_world.h), which the Simulation,
// the dynamics tests and the benchmarks all use.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

std::set<std::pair<std::uint32_t, std::uint32_t>> primitivePairs(
    const collision::CollisionWorld& w) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> out;
  for (const collision::Contact& c : w.contacts())
    out.insert({c.prim_a, c.prim_b});
  return out;
}

// two overlapping bodies of two primitives each, in two collision systems (bits 0 and 1):
// primitives collide exactly when (a.group & b.mask) && (b.group & a.mask), each primitive with
// its own filter (a body's filters are not merged, and bits other than 0 are kept)
TEST(SceneWorld, EachPrimitiveKeepsItsOwnCollisionFilter) {
  SceneModel s;
  Body a = staticBody("a", boxShape(Vec3{0.1}), at(Vec3{0.0}));
  a.primitives.push_back(a.primitives[0]);
  a.primitives[0].group = a.primitives[0].mask = 1u;  // system 0
  a.primitives[1].group = a.primitives[1].mask = 2u;  // system 1
  Body b = a;
  b.name = "b";
  b.motion = Motion::kKinematic;
  b.X_WB = at(Vec3{0.05, 0.0, 0.0});
  s.bodies = {a, b};
  s.length_scale = lengthScale(s);
  auto world = buildCollisionWorld(s, {}).value();
  world->setPose(1, s.bodies[1].X_WB);
  world->step();
  const std::set<std::pair<std::uint32_t, std::uint32_t>> want = {{0u, 0u}, {1u, 1u}};
  EXPECT_EQ(primitivePairs(*world), want);
}

TEST(SceneWorld, KindsFromMotionAndProbeInactiveBodiesDisabledMarginForDynamics) {
  SceneModel s;
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{1, 0.1, 1}), at(Vec3{0, -0.1, 0})));
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 0.05, 0}), 500.0));
  Body probe = staticBody("probe", boxShape(Vec3{0.01}), at(Vec3{0, 0.5, 0}));
  probe.motion = Motion::kKinematic;
  s.bodies.push_back(probe);
  Body off = probe;
  off.name = "off";
  off.active = false;
  s.bodies.push_back(off);
  s.probe_body = 2;
  s.length_scale = 2.0;
  collision::WorldOptions o;
  o.box_margin = 1e-4;
  auto world = buildCollisionWorld(s, o).value();
  EXPECT_EQ(world->kind(0), collision::BodyKind::kStatic);
  EXPECT_EQ(world->kind(1), collision::BodyKind::kDynamic);
  EXPECT_EQ(world->kind(2), collision::BodyKind::kProbe);
  EXPECT_EQ(world->kind(3), collision::BodyKind::kKinematic);
  EXPECT_TRUE(world->enabled(2));
  EXPECT_FALSE(world->enabled(3));
  EXPECT_EQ(world->options().box_margin, recommendedBoxMargin(s));  // raised: a dynamic body
  EXPECT_GE(world->reservedPairs(), 64u);
  // an extra probe goes after the scene's bodies
  collision::BodyDesc sphere;
  sphere.kind = collision::BodyKind::kProbe;
  sphere.primitives.push_back({boxShape(Vec3{0.01}), geom::Transform{}});
  s.probe_body = -1;
  world = buildCollisionWorld(s, o, &sphere).value();
  EXPECT_EQ(world->kind(4), collision::BodyKind::kProbe);
  EXPECT_EQ(world->kind(2), collision::BodyKind::kKinematic);
}

TEST(SceneWorld, RefusesAnInactiveProbeAndAPrimitiveWithoutShape) {
  SceneModel s;
  Body probe = staticBody("probe", boxShape(Vec3{0.01}), at(Vec3{0.0}));
  probe.motion = Motion::kKinematic;
  probe.active = false;
  s.bodies.push_back(probe);
  s.probe_body = 0;
  auto r = buildCollisionWorld(s, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'probe'"), std::string::npos);
  s.bodies[0].active = true;
  s.bodies[0].primitives[0].shape = nullptr;
  EXPECT_FALSE(buildCollisionWorld(s, {}).ok());
}

}  // namespace
}  // namespace hapticd::dynamics::testing
