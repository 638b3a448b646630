// Bodies taken out of the scene and put back (Dynamics::setEnabled, for the scene edits of issue
// 8): a disabled body is frozen (no gravity, no contacts, out of the energies) even when it
// overlaps the floor; enabled at a pose it falls and rests; a joint to a disabled body is inert.
#include <gtest/gtest.h>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;

std::uint32_t pairsWith(const collision::CollisionWorld& world, std::uint32_t body) {
  std::uint32_t n = 0;
  for (const collision::Contact& c : world.contacts())
    n += c.body_a == body || c.body_b == body ? 1u : 0u;
  return n;
}

TEST(DynamicsEnable, ADisabledBodyIsFrozenAndOutOfContactsEnabledItFallsAndRests) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{1.0, 0.05, 1.0}), at(Vec3{0, -0.05, 0})));
  // inactive, and 30 mm into the floor: were its contacts solved it would be pushed out
  Body box = dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 0.02, 0}), 1000.0);
  box.active = false;
  s.bodies.push_back(box);
  Rig rig(std::move(s));
  EXPECT_FALSE(rig.dyn->enabled(1));
  EXPECT_FALSE(rig.world->enabled(1));  // buildCollisionWorld disables it too
  rig.run(300, kDt);
  EXPECT_EQ(rig.dyn->pose(1).translation.y, 0.02);
  EXPECT_EQ(pairsWith(*rig.world, 1), 0u);
  EXPECT_EQ(rig.dyn->kineticEnergy(), 0.0);
  EXPECT_EQ(rig.dyn->potentialEnergy(), 0.0);
  // enabled at 0.3 m: it falls onto the floor and rests there
  rig.world->setEnabled(1, true);
  rig.world->setPose(1, at(Vec3{0, 0.3, 0}));
  rig.dyn->setEnabled(1, true, at(Vec3{0, 0.3, 0}));
  EXPECT_TRUE(rig.dyn->enabled(1));
  rig.run(100, kDt);
  // free fall for 0.1 s: 0.3 - g t^2 / 2 (semi-implicit Euler: within a tick's worth)
  EXPECT_NEAR(rig.dyn->pose(1).translation.y, 0.3 - 0.5 * 9.81 * 0.01,
              0.5 * 9.81 * 0.1 * kDt * 1.1);
  rig.run(1900, kDt);
  EXPECT_NEAR(rig.dyn->pose(1).translation.y, 0.05, 5e-4);
  EXPECT_LT(glm::length(rig.dyn->linearVelocity(1)), 1e-3);
  // disabled again: frozen where it rests, its velocity zero
  rig.dyn->setEnabled(1, false);
  rig.world->setEnabled(1, false);
  const Pose frozen = rig.dyn->pose(1);
  rig.run(200, kDt);
  EXPECT_EQ(rig.dyn->pose(1).translation.y, frozen.translation.y);
  EXPECT_EQ(glm::length(rig.dyn->linearVelocity(1)), 0.0);
  // a static body cannot be disabled
  rig.dyn->setEnabled(0, false);
  EXPECT_TRUE(rig.dyn->enabled(0));
}

// A bar hanging from a block by a fixed joint: the block kinematic (infinite mass, in the
// scene) holds it; the block a disabled dynamic body frozen in the air: the joint is inert and
// the bar falls freely.
TEST(DynamicsEnable, AJointToADisabledBodyIsInert) {
  for (const bool disabled : {false, true}) {
    SceneModel s;
    s.gravity_W = Vec3{0, -9.81, 0};
    Body block = dynamicBody("block", boxShape(Vec3{0.05}), at(Vec3{0, 1.0, 0}), 1000.0);
    if (disabled) {
      block.active = false;
    } else {
      block.motion = Motion::kKinematic;
    }
    s.bodies.push_back(block);
    s.bodies.push_back(
        dynamicBody("bar", boxShape(Vec3{0.02, 0.1, 0.02}), at(Vec3{0, 0.8, 0}), 1000.0));
    s.joints.push_back(joint(scene::JointKind::kFixed, 0, 1, Vec3{0, -0.1, 0}, Vec3{0, 0.1, 0}));
    // a dynamic body so that the stage is active in both cases
    s.bodies.push_back(dynamicBody("other", boxShape(Vec3{0.01}), at(Vec3{5, 0, 0}), 1000.0));
    s.bodies.back().gravity_factor = 0.0;
    Rig rig(std::move(s));
    rig.run(300, kDt);
    const double y = rig.dyn->pose(1).translation.y;
    std::printf("  block %s: bar at y %.5f after 0.3 s\n", disabled ? "disabled" : "kinematic", y);
    if (disabled) {
      EXPECT_NEAR(y, 0.8 - 0.5 * 9.81 * 0.09, 0.5 * 9.81 * 0.3 * kDt * 1.1);
      EXPECT_EQ(rig.dyn->pose(0).translation.y, 1.0);
    } else {
      EXPECT_NEAR(y, 0.8, 1e-3);
    }
  }
}

}  // namespace
}  // namespace hapticd::dynamics::testing
