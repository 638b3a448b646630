// Physics as Blender and Godot write it: Godot's OMI_physics_body / OMI_physics_shape (and the
// older OMI_collider and body `type`), KHR and OMI triggers as non-colliding volumes, every joint
// kind with its limits and drives kept for the dynamics, kinematic velocities, and materials'
// defaults and combine modes as KHR_physics_rigid_bodies says.
#include <gtest/gtest.h>

#include <numbers>

#include "core/scene/loader.h"
#include "tests/core/scene/corpus_formats.h"
#include "tests/core/scene/scene_test_util.h"

namespace hapticd::scene {
namespace {

using testing::bodyNamed;
using testing::GltfBuilder;
using testing::hasProblem;
using testing::json;
using testing::load;
using testing::notesOf;
using testing::staticShape;

/// A Godot body node with a collider child of OMI shape `shape`.
int omiBody(GltfBuilder& b, const std::string& name, const json& body, int shape, Vec3 t) {
  json n = GltfBuilder::node(name, t);
  n["extensions"]["OMI_physics_body"] = body;
  const int index = b.addNode(n);
  json c = GltfBuilder::node(name + "Shape");
  c["extensions"]["OMI_physics_body"] = {{"collider", {{"shape", shape}}}};
  b.addNode(c, index);
  return index;
}

TEST(ScenePhysics, GodotOmiBodiesAndShapesMapOntoTheModel) {
  GltfBuilder b;
  b.doc["extensions"]["OMI_physics_shape"]["shapes"] = testing::godotShapes(b);
  b.useExtension("OMI_physics_body", false);
  b.useExtension("OMI_physics_shape", false);
  omiBody(b, "Floor", {{"motion", {{"type", "static"}}}}, 0, {0.0, -0.1, 0.0});
  omiBody(b, "Ball", {{"motion", {{"type", "dynamic"}, {"mass", 2.0}}}}, 1, {0.0, 1.0, 0.0});
  omiBody(b, "Pill", {{"motion", {{"type", "dynamic"}}}}, 2, {1.0, 1.0, 0.0});
  omiBody(b, "Can", {{"motion", {{"type", "kinematic"}, {"linearVelocity", {0.0, 0.0, 1.0}}}}}, 3,
          {2.0, 1.0, 0.0});
  omiBody(b, "Box", {{"motion", {{"type", "dynamic"}}}}, 4, {3.0, 1.0, 0.0});
  omiBody(b, "Rock", {{"motion", {{"type", "static"}}}}, 5, {4.0, 1.0, 0.0});
  // an Area3D: a trigger body whose child shapes are triggers
  json area = GltfBuilder::node("Goal", {5.0, 0.0, 0.0});
  area["extensions"]["OMI_physics_body"] = {{"trigger", json::object()}};
  const int goal = b.addNode(area);
  json zone = GltfBuilder::node("GoalShape");
  zone["extensions"]["OMI_physics_body"] = {{"trigger", {{"shape", 0}}}};
  b.addNode(zone, goal);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const SceneModel& s = *r.scene;
  EXPECT_EQ(bodyNamed(s, "Floor").motion, Motion::kStatic);
  EXPECT_EQ(bodyNamed(s, "Floor").primitives[0].source, ShapeSource::kBox);
  const Body& ball = bodyNamed(s, "Ball");
  EXPECT_EQ(ball.motion, Motion::kDynamic);
  EXPECT_DOUBLE_EQ(ball.mass, 2.0);
  EXPECT_EQ(ball.primitives[0].source, ShapeSource::kSphere);
  EXPECT_DOUBLE_EQ(bodyNamed(s, "Pill").mass, 1.0);  // OMI: 1 kg when not given
  // the capsule's whole height is 0.6: its cap centres 0.4 apart
  double top = 0.0;
  for (const auto& v : bodyNamed(s, "Pill").primitives[0].shape->vertices())
    top = std::max(top, v.p.y);
  EXPECT_NEAR(top, 0.3, 0.3 * 2e-3);
  const Body& can = bodyNamed(s, "Can");
  EXPECT_EQ(can.motion, Motion::kKinematic);
  EXPECT_EQ(can.linear_velocity_W, Vec3(0.0, 0.0, 1.0));
  EXPECT_EQ(can.primitives[0].source, ShapeSource::kCylinder);
  EXPECT_EQ(bodyNamed(s, "Box").primitives[0].source, ShapeSource::kMeshHull);
  EXPECT_EQ(bodyNamed(s, "Rock").primitives[0].source, ShapeSource::kMeshPiece);
  const Primitive& trigger = bodyNamed(s, "Goal").primitives.at(0);
  EXPECT_TRUE(trigger.trigger);
  EXPECT_EQ(trigger.group, 0u);
  EXPECT_EQ(trigger.mask, 0u);
  const std::string notes = notesOf(s);
  // the scene has dynamic bodies, so the dynamics move the kinematic can at its velocity
  EXPECT_EQ(notes.find("kinematic velocity"), std::string::npos) << notes;
  EXPECT_NE(notes.find("1 trigger volumes, not colliding (bodies 'Goal')"), std::string::npos);
  EXPECT_NE(notes.find("mesh 1 'DentedMesh' (node 11 'RockShape'): not convex"), std::string::npos)
      << notes;
}

TEST(ScenePhysics, TheOlderOmiColliderAndBodyTypesStillLoad) {
  GltfBuilder b;
  b.doc["extensions"]["OMI_collider"]["colliders"] =
      json::array({{{"type", "box"}, {"size", {1.0, 1.0, 1.0}}},
                   {{"type", "sphere"}, {"radius", 0.25}, {"isTrigger", true}}});
  b.useExtension("OMI_collider", false);
  b.useExtension("OMI_physics_body", false);
  json rigid = GltfBuilder::node("Crate", {0.0, 2.0, 0.0});
  rigid["extensions"]["OMI_physics_body"] = {{"type", "rigid"}, {"mass", 3.0}};
  const int crate = b.addNode(rigid);
  json shape = GltfBuilder::node("CrateShape");
  shape["extensions"]["OMI_collider"] = {{"collider", 0}};
  b.addNode(shape, crate);
  json sensor = GltfBuilder::node("Sensor", {2.0, 0.0, 0.0});
  sensor["extensions"]["OMI_collider"] = {{"collider", 1}};
  b.addNode(sensor);
  LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(bodyNamed(*r.scene, "Crate").motion, Motion::kDynamic);
  EXPECT_DOUBLE_EQ(bodyNamed(*r.scene, "Crate").mass, 3.0);
  EXPECT_TRUE(bodyNamed(*r.scene, "Sensor").primitives[0].trigger);

  // a capsule shorter than its caps
  b.doc["extensions"]["OMI_collider"]["colliders"].push_back(
      {{"type", "capsule"}, {"radius", 0.5}, {"height", 0.5}});
  json pill = GltfBuilder::node("Pill", {4.0, 0.0, 0.0});
  pill["extensions"]["OMI_collider"] = {{"collider", 2}};
  b.addNode(pill);
  r = load(b);
  EXPECT_TRUE(
      hasProblem(r, "OMI_collider collider 2 capsule: height 0.5 is less than the two caps"))
      << r.message();
}

TEST(ScenePhysics, AnOmiMotionWithoutATypeIsDynamicAsGodotReadsIt) {
  // the schema requires `type`; Godot's importer reads a motion without one as a rigid body,
  // and the extension's own trigger example writes {"mass": 1}
  GltfBuilder b;
  b.doc["extensions"]["OMI_physics_shape"]["shapes"] =
      json::array({{{"type", "box"}, {"box", {{"size", {0.2, 0.2, 0.2}}}}}});
  b.useExtension("OMI_physics_body", false);
  b.useExtension("OMI_physics_shape", false);
  omiBody(b, "Cube", {{"motion", {{"mass", 1.5}}}}, 0, {0.0, 1.0, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& cube = bodyNamed(*r.scene, "Cube");
  EXPECT_EQ(cube.motion, Motion::kDynamic);
  EXPECT_DOUBLE_EQ(cube.mass, 1.5);
  EXPECT_NE(notesOf(*r.scene).find("node 0 'Cube' OMI_physics_body motion: no type: read as "
                                   "dynamic (as Godot reads it)"),
            std::string::npos)
      << notesOf(*r.scene);
  // a type that is there must still be one of the known ones
  b.doc["nodes"][0]["extensions"]["OMI_physics_body"]["motion"]["type"] = "floaty";
  EXPECT_TRUE(hasProblem(load(b), "motion: type 'floaty' is not one of"));
}

TEST(ScenePhysics, KhrTriggersAreNonCollidingVolumesWithoutMass) {
  GltfBuilder b = testing::GltfBuilder();
  const int box = b.box({1.0, 1.0, 1.0});
  json cube = GltfBuilder::node("Cube", {0.0, 1.0, 0.0});
  GltfBuilder::physics(cube)["motion"] = {{"mass", 1.0}};
  GltfBuilder::physics(cube)["collider"] = GltfBuilder::shapeCollider(box);
  const int c = b.addNode(cube);
  json zone = GltfBuilder::node("Zone", {0.0, 0.0, 0.0});
  GltfBuilder::physics(zone)["trigger"] = {{"geometry", {{"shape", b.box({4.0, 4.0, 4.0})}}}};
  b.addNode(zone, c);
  json compound = GltfBuilder::node("Compound");
  GltfBuilder::physics(compound)["trigger"] = {{"nodes", {1}}};
  b.addNode(compound);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& body = bodyNamed(*r.scene, "Cube");
  ASSERT_EQ(body.primitives.size(), 2u);
  EXPECT_FALSE(body.primitives[0].trigger);
  EXPECT_TRUE(body.primitives[1].trigger);
  // the mass and inertia are the cube's alone: the 4 m trigger adds none
  EXPECT_NEAR(body.inertia_B[0][0], 1.0 / 6.0, 1e-9);
  EXPECT_NEAR(r.scene->length_scale, std::sqrt(3.0), 1e-9);
}

TEST(ScenePhysics, EveryJointKindWithItsLimitsAndDrivesIsKept) {
  GltfBuilder b;
  const auto joint = [&](json limits, json drives = json::array()) {
    return b.addPhysics("physicsJoints", {{"limits", limits}, {"drives", drives}});
  };
  const json locked_linear = {{"linearAxes", {0, 1, 2}}, {"max", 0.0}};
  const json locked_angular = {{"angularAxes", {0, 1, 2}}, {"max", 0.0}};
  const json drive = {{"type", "angular"}, {"mode", "force"},       {"axis", 1},
                      {"maxForce", 5.0},   {"velocityTarget", 2.0}, {"damping", 0.5}};
  const int hinge_driven =
      joint({locked_linear, {{"angularAxes", {0, 2}}, {"max", 0.0}}}, json::array({drive}));
  const int slider = joint({{{"linearAxes", {0, 2}}, {"max", 0.0}},
                            {{"linearAxes", {1}}, {"min", -0.1}, {"max", 0.2}},
                            locked_angular},
                           json::array({{{"type", "linear"},
                                         {"mode", "acceleration"},
                                         {"axis", 1},
                                         {"positionTarget", 0.05},
                                         {"stiffness", 100.0}}}));
  const int cone = joint({locked_linear, {{"angularAxes", {0, 2}}, {"max", 0.5}}});
  const int soft = joint({{{"linearAxes", {0, 1, 2}}, {"max", 0.1}, {"stiffness", 50.0}}});
  const int box = b.box({0.1, 0.1, 0.1});
  for (const auto& [name, j] : {std::pair{"Door", hinge_driven}, std::pair{"Drawer", slider},
                                std::pair{"Lamp", cone}, std::pair{"Bob", soft}}) {
    json n = GltfBuilder::node(name, {0.0, 1.0, 0.0});
    GltfBuilder::physics(n)["motion"] = json::object();
    GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(box);
    GltfBuilder::physics(n)["joint"] = {
        {"connectedNode", 0}, {"joint", j}, {"enableCollision", true}};
    b.addNode(n);
  }
  b.doc["nodes"][0]["extensions"]["KHR_physics_rigid_bodies"]["joint"]["connectedNode"] = 1;
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const SceneModel& s = *r.scene;
  ASSERT_GE(s.joints.size(), 1u);
  EXPECT_EQ(s.joints[0].kind, JointKind::kHinge);
  ASSERT_EQ(s.joints[0].drives.size(), 1u);
  const JointDrive& d = s.joints[0].drives[0];
  EXPECT_TRUE(d.angular);
  EXPECT_FALSE(d.acceleration);
  EXPECT_EQ(d.axis, 1);
  EXPECT_EQ(d.max_force, 5.0);
  EXPECT_EQ(d.velocity_target, 2.0);
  EXPECT_FALSE(d.position_target);
  EXPECT_DOUBLE_EQ(d.damping, 0.5);
  EXPECT_TRUE(s.joints[0].enable_collision);
  // every kind is simulated: all in SceneModel::joints, the old list empty, no note
  EXPECT_TRUE(s.unsimulated_joints.empty());
  ASSERT_EQ(s.joints.size(), 4u);
  EXPECT_EQ(s.joints[1].kind, JointKind::kSlider);
  EXPECT_EQ(s.joints[1].hinge_axis, 1);
  EXPECT_TRUE(s.joints[1].drives[0].acceleration);
  EXPECT_EQ(s.joints[1].drives[0].position_target, 0.05);
  EXPECT_EQ(s.joints[2].kind, JointKind::kBall);     // a cone on a ball
  EXPECT_EQ(s.joints[3].kind, JointKind::kGeneric);  // a soft distance
  EXPECT_EQ(s.joints[3].limits[0].stiffness, 50.0);
  EXPECT_TRUE(s.plan.joints);
  const std::string notes = notesOf(s);
  EXPECT_EQ(notes.find("simulated"), std::string::npos) << notes;

  // bad drives are refused with their place
  GltfBuilder bad = b;
  bad.doc["extensions"]["KHR_physics_rigid_bodies"]["physicsJoints"][0]["drives"][0]["axis"] = 3;
  bad.doc["extensions"]["KHR_physics_rigid_bodies"]["physicsJoints"][1]["drives"][0]["mode"] =
      "torque";
  const LoadReport refused = load(bad);
  EXPECT_TRUE(hasProblem(refused, "physicsJoint 0 drive 0: axis index 3 out of range (3 axes)"))
      << refused.message();
  EXPECT_TRUE(hasProblem(refused,
                         "physicsJoint 1 drive 0: mode 'torque' is not one of 'force', "
                         "'acceleration'"))
      << refused.message();
}

/// Every joint of a scene, simulated or not yet, in file order of the lists.
std::vector<Joint> allJoints(const SceneModel& s) {
  std::vector<Joint> all = s.joints;
  all.insert(all.end(), s.unsimulated_joints.begin(), s.unsimulated_joints.end());
  return all;
}

TEST(ScenePhysics, GodotOmiJointsAreReadAsKhrJoints) {
  // as Godot 4 writes a joint: the joint node under body A, its connectedNode an attachment node
  // under body B, the settings in the document's OMI_physics_joint physicsJoints
  GltfBuilder b;
  b.doc["extensions"]["OMI_physics_shape"]["shapes"] =
      json::array({{{"type", "box"}, {"box", {{"size", {0.2, 0.2, 0.2}}}}}});
  b.useExtension("OMI_physics_body", false);
  b.useExtension("OMI_physics_shape", false);
  b.useExtension("OMI_physics_joint", false);
  // a weld (one limit on linear and angular axes at once), a pin whose negative stiffness is
  // infinitely stiff, and a slider whose drive's negative maxForce is not limited
  b.doc["extensions"]["OMI_physics_joint"]["physicsJoints"] = json::array(
      {{{"limits", json::array({{{"linearAxes", {0, 1, 2}},
                                 {"angularAxes", {0, 1, 2}},
                                 {"min", 0.0},
                                 {"max", 0.0}}})}},
       {{"limits",
         json::array({{{"linearAxes", {0, 1, 2}}, {"min", 0.0}, {"max", 0.0}, {"stiffness", -1}},
                      {{"linearAxes", json::array()}, {"angularAxes", {0}}, {"max", 1.0}}})}},
       {{"limits", json::array({{{"linearAxes", {1, 2}}, {"min", 0.0}, {"max", 0.0}},
                                {{"angularAxes", {0, 1, 2}}, {"min", 0.0}, {"max", 0.0}}})},
        {"drives", json::array({{{"type", "linear"},
                                 {"mode", "force"},
                                 {"axis", 0},
                                 {"maxForce", -1},
                                 {"velocityTarget", 0.5},
                                 {"damping", 2.0}}})}}});
  std::vector<int> bodies;
  for (int i = 0; i < 4; ++i) {
    json n = GltfBuilder::node("Link" + std::to_string(i), {0.5 * i, 1.0, 0.0});
    n["extensions"]["OMI_physics_body"] = {{"motion", {{"type", "dynamic"}}}};
    bodies.push_back(b.addNode(n));
    json c = GltfBuilder::node("LinkShape" + std::to_string(i));
    c["extensions"]["OMI_physics_body"] = {{"collider", {{"shape", 0}}}};
    b.addNode(c, bodies.back());
  }
  for (int i = 0; i < 3; ++i) {
    const int attachment =
        b.addNode(GltfBuilder::node("Attach" + std::to_string(i), {-0.25, 0.0, 0.0}),
                  bodies[static_cast<std::size_t>(i) + 1]);
    json j = GltfBuilder::node("Joint" + std::to_string(i), {0.25, 0.0, 0.0});
    j["extensions"]["OMI_physics_joint"] = {{"connectedNode", attachment}, {"joint", i}};
    if (i == 2)
      j["extensions"]["OMI_physics_joint"]["enableCollision"] = true;
    b.addNode(j, bodies[static_cast<std::size_t>(i)]);
  }
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const std::vector<Joint> joints = allJoints(*r.scene);
  ASSERT_EQ(joints.size(), 3u);
  const auto jointFrom = [&](const std::string& body) -> const Joint& {
    for (const Joint& j : joints) {
      if (r.scene->bodies[static_cast<std::size_t>(j.body_a)].name == body)
        return j;
    }
    ADD_FAILURE() << "no joint from " << body;
    return joints.front();
  };
  const Joint& weld = jointFrom("Link0");
  EXPECT_EQ(weld.kind, JointKind::kFixed);
  ASSERT_EQ(weld.limits.size(), 2u);  // the one OMI limit, as a linear and an angular one
  EXPECT_EQ(weld.limits[0].linear_axes, 7);
  EXPECT_EQ(weld.limits[0].angular_axes, 0);
  EXPECT_EQ(weld.limits[1].angular_axes, 7);
  EXPECT_EQ(weld.limits[1].linear_axes, 0);
  EXPECT_EQ(r.scene->bodies[static_cast<std::size_t>(weld.body_b)].name, "Link1");
  // the attachment frames: the joint node in body A, the connected node in body B
  EXPECT_NEAR(weld.X_AJ.translation.x, 0.25, 1e-12);
  EXPECT_NEAR(weld.X_BJ.translation.x, -0.25, 1e-12);
  EXPECT_FALSE(weld.enable_collision);
  const Joint& pin = jointFrom("Link1");
  EXPECT_EQ(pin.kind, JointKind::kBall);  // the negative stiffness is a hard limit
  EXPECT_FALSE(pin.limits[0].stiffness);
  ASSERT_EQ(pin.limits.size(), 2u);  // the empty linearAxes list limits no linear axis
  EXPECT_EQ(pin.limits[1].linear_axes, 0);
  EXPECT_EQ(pin.limits[1].angular_axes, 1);
  const Joint& slider = jointFrom("Link2");
  EXPECT_EQ(slider.kind, JointKind::kSlider);
  EXPECT_EQ(slider.hinge_axis, 0);
  ASSERT_EQ(slider.drives.size(), 1u);
  EXPECT_FALSE(slider.drives[0].max_force);  // negative: not limited
  EXPECT_EQ(slider.drives[0].velocity_target, 0.5);
  EXPECT_TRUE(slider.enable_collision);
  EXPECT_EQ(notesOf(*r.scene).find("not read (unknown"), std::string::npos) << notesOf(*r.scene);

  // a limit of no axis, a joint index past the OMI joints and a KHR joint index into them are
  // refused, each with its place
  GltfBuilder bad = b;
  bad.doc["extensions"]["OMI_physics_joint"]["physicsJoints"][1]["limits"][1]["angularAxes"] =
      json::array();
  bad.doc["nodes"][static_cast<std::size_t>(bodies[0]) + 1]["extensions"]["OMI_physics_joint"] = {
      {"connectedNode", 0}, {"joint", 3}};
  bad.doc["extensions"]["KHR_physics_rigid_bodies"]["physicsJoints"] = json::array();
  json khr = GltfBuilder::node("KhrJoint");
  GltfBuilder::physics(khr)["joint"] = {{"connectedNode", 0}, {"joint", 0}};
  bad.addNode(khr, bodies[3]);
  const LoadReport refused = load(bad);
  EXPECT_TRUE(hasProblem(refused,
                         "OMI_physics_joint physicsJoint 1 limit 1: give linearAxes or "
                         "angularAxes (a limit must limit some axis)"))
      << refused.message();
  EXPECT_TRUE(hasProblem(refused,
                         "node 1 'LinkShape0' OMI_physics_joint: joint index 3 out of range (3 "
                         "OMI_physics_joint physicsJoints)"))
      << refused.message();
  EXPECT_TRUE(hasProblem(refused,
                         "node 14 'KhrJoint' joint: joint index 0 out of range (0 "
                         "physicsJoints)"))
      << refused.message();
}

TEST(ScenePhysics, MaterialsTakeTheExtensionsDefaultsAndCombineRule) {
  GltfBuilder b;
  const int plain = b.addPhysics("physicsMaterials", json::object());
  const int max =
      b.addPhysics("physicsMaterials", {{"staticFriction", 0.2}, {"frictionCombine", "maximum"}});
  const int min =
      b.addPhysics("physicsMaterials", {{"staticFriction", 0.4}, {"frictionCombine", "minimum"}});
  staticShape(b, "Floor", b.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0});
  GltfBuilder::physics(b.doc["nodes"][0])["collider"]["physicsMaterial"] = plain;
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const auto& m = r.scene->materials;
  EXPECT_DOUBLE_EQ(m[static_cast<std::size_t>(plain)].static_friction, 0.6);  // the default
  EXPECT_DOUBLE_EQ(m[static_cast<std::size_t>(plain)].dynamic_friction, 0.6);
  EXPECT_DOUBLE_EQ(m[static_cast<std::size_t>(plain)].restitution, 0.0);
  const auto combine = [&](int a, int c) {
    return combineMaterials(m[static_cast<std::size_t>(a)], m[static_cast<std::size_t>(c)],
                            MaterialValue::kStaticFriction);
  };
  EXPECT_DOUBLE_EQ(combine(plain, max), 0.6);  // only one declares: its rule, the maximum
  EXPECT_DOUBLE_EQ(combine(max, plain), 0.6);
  EXPECT_DOUBLE_EQ(combine(max, min), 0.2);      // minimum before maximum
  EXPECT_DOUBLE_EQ(combine(plain, plain), 0.6);  // neither declares: average
  Material avg;
  avg.static_friction = 1.0;
  avg.friction_combine_declared = true;  // declared average wins over everything
  EXPECT_DOUBLE_EQ(
      combineMaterials(avg, m[static_cast<std::size_t>(min)], MaterialValue::kStaticFriction), 0.7);
}

}  // namespace
}  // namespace hapticd::scene
