// End to end: a glTF document (KHR_physics_rigid_bodies) with a slider and a position drive,
// loaded by the scene loader and stepped by the dynamics as the Simulation builds them.
#include <gtest/gtest.h>

#include <cmath>

#include "core/dynamics/dynamics.h"
#include "tests/core/scene/scene_test_util.h"

namespace hapticd::dynamics {
namespace {

using scene::testing::GltfBuilder;
using scene::testing::json;

// a drawer of 1 kg on a slider along x (the other linear axes and every angle locked, x within
// +-0.1 m) to a static anchor at the origin; a critically damped drive (k = 400 N/m, c = 40 N s/m:
// w = 20 rad/s) takes the anchor, seen from the drawer's joint frame, to -0.05 m: the drawer to
// +0.05 m (KHR: the drive acts on the connected node's position in the joint node's frame)
TEST(GltfJoint, SliderWithAPositionDriveReachesItsTarget) {
  GltfBuilder b;
  const int joint =
      b.addPhysics("physicsJoints", {{"limits",
                                      {{{"linearAxes", {1, 2}}, {"max", 0.0}},
                                       {{"linearAxes", {0}}, {"min", -0.1}, {"max", 0.1}},
                                       {{"angularAxes", {0, 1, 2}}, {"max", 0.0}}}},
                                     {"drives",
                                      {{{"type", "linear"},
                                        {"mode", "force"},
                                        {"axis", 0},
                                        {"positionTarget", -0.05},
                                        {"stiffness", 400.0},
                                        {"damping", 40.0}}}}});
  const int anchor = b.addNode(GltfBuilder::node("Anchor", {0.0, 0.0, 0.0}));
  json drawer = GltfBuilder::node("Drawer", {0.0, 0.0, 0.0});
  GltfBuilder::physics(drawer)["motion"] = {{"mass", 1.0}};
  GltfBuilder::physics(drawer)["collider"] = GltfBuilder::shapeCollider(b.box({0.2, 0.1, 0.1}));
  GltfBuilder::physics(drawer)["joint"] = {{"connectedNode", anchor}, {"joint", joint}};
  b.addNode(drawer);
  const scene::LoadReport r = scene::testing::load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const scene::SceneModel& s = *r.scene;
  ASSERT_EQ(s.joints.size(), 1u);
  EXPECT_EQ(s.joints[0].kind, scene::JointKind::kSlider);
  EXPECT_TRUE(s.unsimulated_joints.empty());
  EXPECT_TRUE(s.plan.joints);
  for (const std::string& note : s.plan.notes)
    EXPECT_EQ(note.find("simulated"), std::string::npos) << note;

  auto world = buildCollisionWorld(s, collision::WorldOptions{}).value();
  auto dyn = Dynamics::create(s, *world).value();
  const auto step = [&](int n) {
    for (int k = 0; k < n; ++k) {
      world->step();
      dyn->step(*world, 0.001);
    }
  };
  step(100);  // t = 0.1 s: x = 0.05 (1 - (1 + w t) e^(-w t)), w t = 2
  EXPECT_NEAR(dyn->pose(0).translation.x / 0.05, 1.0 - 3.0 * std::exp(-2.0), 0.02);
  step(1400);
  const Pose X = dyn->pose(0);
  EXPECT_NEAR(X.translation.x / 0.05, 1.0, 1e-4);
  EXPECT_LT(std::hypot(X.translation.y, X.translation.z), 1e-6);
  EXPECT_NEAR(std::abs(X.rotation.w), 1.0, 1e-9);
}

}  // namespace
}  // namespace hapticd::dynamics
