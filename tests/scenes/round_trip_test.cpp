// Round trip: every demo scene loads through hapticd::scene::loadScene with no problem, and the
// model is what the generator meant: bodies by name with their motions, primitive counts and
// sources, masses and inertia (declared, or computed from the hulls), initial poses, joints,
// probe, gravity, materials, and the simulation plan (only what each scene calls for).

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "core/scene/loader.h"
#include "scenes/demo_scenes.h"
#include "tests/core/scene/plan_expect.h"
#include "tests/scenes/glb_reader.h"

namespace hapticd::scenes {
namespace {

using scene::Body;
using scene::JointKind;
using scene::Motion;
using scene::SceneModel;
using scene::ShapeSource;

SceneModel load(std::string_view name) {
  const std::vector<std::uint8_t> bytes = makeDemoScene(name);
  scene::LoadReport report = scene::loadScene(bytes, std::string(name));
  EXPECT_TRUE(report.ok()) << name << ":\n" << report.message();
  EXPECT_TRUE(report.problems.empty());
  if (!report.ok())
    return {};
  return std::move(*report.scene);
}

const Body* bodyNamed(const SceneModel& s, const std::string& name) {
  for (const Body& b : s.bodies)
    if (b.name == name)
      return &b;
  ADD_FAILURE() << "no body named " << name;
  return nullptr;
}

int indexOf(const SceneModel& s, const Body* b) {
  return static_cast<int>(b - s.bodies.data());
}

/// A primitive's vertices in the scene frame.
std::vector<geom::Vec3> worldPoints(const Body& b, const scene::Primitive& p) {
  const geom::Transform X_WP = b.X_WB.toTransform() * p.X_BP.toTransform();
  std::vector<geom::Vec3> out;
  for (const auto& v : p.shape->vertices())
    out.push_back(X_WP.apply(v.p));
  return out;
}

void expectPose(const Body& b, const geom::Vec3& t, const geom::Quat& q, double tol) {
  EXPECT_NEAR(glm::length(b.X_WB.translation - t), 0.0, tol) << b.name;
  EXPECT_GT(std::fabs(glm::dot(b.X_WB.rotation, q)), 1.0 - 1e-9) << b.name;
}

const geom::Quat kIdentity{1.0, 0.0, 0.0, 0.0};

TEST(SceneRoundTrip, EveryDemoSceneLoads) {
  for (std::string_view name : demoSceneNames()) {
    const SceneModel s = load(name);
    std::size_t prims = 0;
    for (const Body& b : s.bodies)
      prims += b.primitives.size();
    std::printf("%s: %zu bodies, %zu primitives, %zu joints\n%s\n", std::string(name).c_str(),
                s.bodies.size(), prims, s.joints.size(), scene::describePlan(s.plan).c_str());
    // the plan stored is the plan of what the scene declares
    scene::testing::expectSamePlan(s.plan, scene::makePlan(s));
    EXPECT_EQ(s.plan.static_primitives + s.plan.moving_primitives, prims);
  }
}

TEST(SceneRoundTrip, GearsAreTwoDynamicBodiesOnHingesWithoutGravity) {
  const SceneModel s = load("gears");
  ASSERT_EQ(s.bodies.size(), 3u);  // the axles have no collider: they are the scene frame
  const SpurGear g = gears::gear();
  for (const std::string name : {"GearA", "GearB"}) {
    SCOPED_TRACE(name);
    const Body* b = bodyNamed(s, name);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->motion, Motion::kDynamic);
    EXPECT_FALSE(b->probe);
    EXPECT_TRUE(b->mass_declared);
    EXPECT_TRUE(b->inertia_declared);
    EXPECT_DOUBLE_EQ(b->mass, gears::kMass_kg);
    const double r = g.pitchRadius(), w = g.face_width_m, m = gears::kMass_kg;
    EXPECT_NEAR(b->inertia_B[2][2], 0.5 * m * r * r, 1e-9 * m * r * r);
    EXPECT_NEAR(b->inertia_B[0][0], m * (3 * r * r + w * w) / 12, 1e-9 * m * r * r);
    EXPECT_NEAR(glm::length(b->com_B), 0.0, 1e-12);
    const double x = (name == "GearA" ? -0.5 : 0.5) * gears::kCentreDistance_m;
    expectPose(*b, {x, 0.0, 0.0}, kIdentity, 1e-12);
    ASSERT_EQ(b->primitives.size(), 20u);
    std::size_t hubs = 0, teeth = 0;
    for (const auto& p : b->primitives) {
      EXPECT_EQ(p.source, ShapeSource::kMeshHull);
      const std::size_t n = p.shape->vertices().size();
      if (n == std::size_t{2} * static_cast<std::size_t>(g.teeth))
        ++hubs;
      if (n == 20u)
        ++teeth;  // a 10-gon prism
      // every point within the tip circle and the face width
      for (const auto& q : worldPoints(*b, p)) {
        EXPECT_LE(std::hypot(q.x - x, q.y), g.tipRadius() * (1 + 1e-6));
        EXPECT_LE(std::fabs(q.z), 0.5 * w * (1 + 1e-6));
      }
    }
    EXPECT_EQ(hubs, 1u);
    EXPECT_EQ(teeth, static_cast<std::size_t>(g.teeth));
  }
  ASSERT_EQ(s.joints.size(), 2u);
  for (const auto& j : s.joints) {
    EXPECT_EQ(j.kind, JointKind::kHinge);
    EXPECT_EQ(j.hinge_axis, 2);
    EXPECT_FALSE(j.hinge_min.has_value());
    EXPECT_FALSE(j.hinge_max.has_value());
    EXPECT_EQ(j.body_b, -1) << "hinged to the scene frame";
    ASSERT_GE(j.body_a, 0);
    const Body& b = s.bodies[static_cast<std::size_t>(j.body_a)];
    EXPECT_EQ(b.motion, Motion::kDynamic);
    EXPECT_NEAR(glm::length(j.X_AJ.translation), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(j.X_BJ.translation - b.X_WB.translation), 0.0, 1e-12);
    EXPECT_FALSE(j.enable_collision);
  }
  EXPECT_NE(s.joints[0].body_a, s.joints[1].body_a);
  const Body* handle = bodyNamed(s, "Handle");
  ASSERT_NE(handle, nullptr);
  EXPECT_EQ(handle->motion, Motion::kKinematic);
  EXPECT_TRUE(handle->probe);
  EXPECT_EQ(s.probe_body, indexOf(s, handle));
  ASSERT_EQ(handle->primitives.size(), 1u);
  EXPECT_EQ(handle->primitives[0].shape->vertices().size(),
            2u * static_cast<unsigned>(gears::kRodSides));
  EXPECT_FALSE(s.gravity_W.has_value());
  // one frictionless material on every collider: no friction in the plan, whatever the default
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].static_friction, 0.0);
  EXPECT_EQ(s.materials[0].dynamic_friction, 0.0);
  EXPECT_EQ(s.materials[0].restitution, 0.0);
  for (const Body& b : s.bodies) {
    for (const auto& p : b.primitives)
      EXPECT_EQ(p.material, 0) << b.name;
  }
  scene::testing::expectPlan(s.plan, "dynamics joints", 0, 41);
}

TEST(SceneRoundTrip, PegInHoleNeedsOnlyContactForcesAndKeepsItsClearance) {
  const SceneModel s = load("peg_in_hole");
  ASSERT_EQ(s.bodies.size(), 2u);
  const Body* peg_body = bodyNamed(s, "Peg");
  const Body* hole = bodyNamed(s, "Hole");
  ASSERT_NE(peg_body, nullptr);
  ASSERT_NE(hole, nullptr);
  EXPECT_EQ(peg_body->motion, Motion::kKinematic);
  EXPECT_TRUE(peg_body->probe);
  EXPECT_EQ(s.probe_body, indexOf(s, peg_body));
  expectPose(*peg_body, {0.030, peg::kHoleDepth_m + 0.5 * peg::kPegLength_m + 0.040, 0.020},
             kIdentity, 1e-12);
  EXPECT_EQ(hole->motion, Motion::kStatic);
  ASSERT_EQ(hole->primitives.size(), 5u);
  ASSERT_TRUE(hole->stiffness_n_per_m.has_value());
  EXPECT_DOUBLE_EQ(*hole->stiffness_n_per_m, peg::kHoleStiffness_n_per_m);
  EXPECT_FALSE(peg_body->stiffness_n_per_m.has_value());

  // the clearance again, from the loaded hulls: the opening's sides against the peg's width
  ASSERT_EQ(peg_body->primitives.size(), 1u);
  double peg_lo = 1e300, peg_hi = -1e300;
  for (const auto& q : worldPoints(*peg_body, peg_body->primitives[0])) {
    peg_lo = std::min(peg_lo, q.x);
    peg_hi = std::max(peg_hi, q.x);
  }
  double east = 1e300, west = -1e300;
  for (const auto& p : hole->primitives) {
    EXPECT_EQ(p.source, ShapeSource::kMeshHull);
    double lo = 1e300, hi = -1e300, top = -1e300;
    for (const auto& q : worldPoints(*hole, p)) {
      lo = std::min(lo, q.x);
      hi = std::max(hi, q.x);
      top = std::max(top, q.y);
    }
    if (top < 0.5 * peg::kHoleDepth_m)
      continue;  // the floor
    if (lo > 0.0)
      east = std::min(east, lo);
    if (hi < 0.0)
      west = std::max(west, hi);
  }
  const double clearance = 0.5 * ((east - west) - (peg_hi - peg_lo));
  std::printf("peg_in_hole: clearance per side from the loaded hulls %.6f mm\n", clearance * 1e3);
  EXPECT_NEAR(clearance, peg::kClearance_m, 1e-5 * peg::kPegSide_m);

  EXPECT_FALSE(s.gravity_W.has_value());
  EXPECT_TRUE(s.joints.empty());
  scene::testing::expectPlan(s.plan, "", 5, 1);
}

/// Volume of a closed convex polytope (tetrahedra from its centroid to every face fan).
double volume(const geom::Polytope& p) {
  double v = 0.0;
  const geom::Vec3 c = p.centroid();
  for (std::uint32_t f = 0; f < p.faces().size(); ++f) {
    const auto fe = p.faceEdges(f);
    std::vector<geom::Vec3> ring;
    for (const auto& e : fe)
      ring.push_back(p.vertices()[e.vertex].p);
    for (std::size_t k = 1; k + 1 < ring.size(); ++k)
      v += glm::dot(ring[0] - c, glm::cross(ring[k] - c, ring[k + 1] - c)) / 6.0;
  }
  return v;
}

TEST(SceneRoundTrip, DynamicHasDynamicsGravityFrictionAndRestitution) {
  const SceneModel s = load("dynamic");
  ASSERT_EQ(s.bodies.size(), 14u);  // floor, 12 objects, stick
  const Body* floor_body = bodyNamed(s, "Floor");
  ASSERT_NE(floor_body, nullptr);
  EXPECT_EQ(floor_body->motion, Motion::kStatic);
  ASSERT_EQ(floor_body->primitives.size(), 1u);
  EXPECT_EQ(floor_body->primitives[0].source, ShapeSource::kBox);
  for (int i = 0; i < 4; ++i) {
    const double x = dynamic::kRowX_m[i];
    const Body* cube = bodyNamed(s, "Cube" + std::to_string(i));
    const Body* sphere = bodyNamed(s, "Sphere" + std::to_string(i));
    const Body* ellipsoid = bodyNamed(s, "Ellipsoid" + std::to_string(i));
    ASSERT_TRUE(cube && sphere && ellipsoid);
    for (const Body* b : {cube, sphere, ellipsoid}) {
      EXPECT_EQ(b->motion, Motion::kDynamic) << b->name;
      ASSERT_EQ(b->primitives.size(), 1u) << b->name;
      const auto& p = b->primitives[0];
      ASSERT_GE(p.material, 0) << b->name;
      const scene::Material& m = s.materials[static_cast<std::size_t>(p.material)];
      EXPECT_GT(m.dynamic_friction, 0.0);
      EXPECT_GT(m.restitution, 0.0);
    }
    // cubes: declared mass, inertia of a uniform cube computed by the loader
    EXPECT_EQ(cube->primitives[0].source, ShapeSource::kBox);
    EXPECT_TRUE(cube->mass_declared);
    EXPECT_FALSE(cube->inertia_declared);
    EXPECT_DOUBLE_EQ(cube->mass, dynamic::kCubeMass_kg);
    const double a = dynamic::kCubeSide_m;
    const double i_cube = dynamic::kCubeMass_kg * a * a / 6.0;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(cube->inertia_B[k][k], i_cube, 1e-6 * i_cube);
    EXPECT_EQ(cube->primitives[0].shape->vertices().size(), 8u);
    expectPose(*cube, {x, 0.5 * a + dynamic::kDropGap_m, dynamic::kCubeZ_m}, kIdentity, 1e-12);
    EXPECT_EQ(s.materials[static_cast<std::size_t>(cube->primitives[0].material)].name, "wood");
    // spheres: 320 faces, mass and inertia declared
    EXPECT_EQ(sphere->primitives[0].source, ShapeSource::kMeshHull);
    EXPECT_EQ(sphere->primitives[0].shape->faces().size(), 320u);
    EXPECT_EQ(sphere->primitives[0].shape->vertices().size(), 162u);
    EXPECT_TRUE(sphere->mass_declared);
    EXPECT_TRUE(sphere->inertia_declared);
    EXPECT_DOUBLE_EQ(sphere->mass, dynamic::kSphereMass_kg);
    const double r = dynamic::kSphereRadius_m;
    EXPECT_NEAR(sphere->inertia_B[1][1], 0.4 * dynamic::kSphereMass_kg * r * r, 1e-9);
    EXPECT_EQ(s.materials[static_cast<std::size_t>(sphere->primitives[0].material)].name, "rubber");
    // ellipsoids: 320 faces, mass computed from the hull at 1000 kg/m^3, turned about Y
    const auto& hull = *ellipsoid->primitives[0].shape;
    EXPECT_EQ(hull.faces().size(), 320u);
    EXPECT_FALSE(ellipsoid->mass_declared);
    EXPECT_NEAR(ellipsoid->mass, 1000.0 * volume(hull), 1e-6 * ellipsoid->mass);
    const double true_mass = 1000.0 * 4.0 / 3.0 * std::numbers::pi * dynamic::kEllipsoidRadii_m[0] *
                             dynamic::kEllipsoidRadii_m[1] * dynamic::kEllipsoidRadii_m[2];
    EXPECT_LT(ellipsoid->mass, true_mass);         // inscribed polyhedron
    EXPECT_GT(ellipsoid->mass, 0.95 * true_mass);  // two subdivisions: within 5%
    EXPECT_GT(std::fabs(glm::dot(ellipsoid->X_WB.rotation,
                                 glm::angleAxis(i * std::numbers::pi / 6.0, geom::Vec3{0, 1, 0}))),
              1.0 - 1e-9);
    if (i == 0)
      std::printf("ellipsoid mass computed %.6f kg (smooth ellipsoid %.6f kg)\n", ellipsoid->mass,
                  true_mass);
  }
  const Body* stick = bodyNamed(s, "Stick");
  ASSERT_NE(stick, nullptr);
  EXPECT_EQ(stick->motion, Motion::kKinematic);
  EXPECT_TRUE(stick->probe);
  EXPECT_EQ(s.probe_body, indexOf(s, stick));
  expectPose(*stick, {0.0, 0.20, 0.25}, kIdentity, 1e-12);
  ASSERT_TRUE(s.gravity_W.has_value());
  EXPECT_EQ(*s.gravity_W, geom::Vec3(0.0, -9.81, 0.0));
  EXPECT_EQ(s.materials.size(), 4u);
  EXPECT_TRUE(s.joints.empty());
  scene::testing::expectPlan(s.plan, "dynamics gravity friction restitution", 1, 13);
}

TEST(SceneRoundTrip, StressHasOverAThousandPrimitivesMostlyStatic) {
  const SceneModel s = load("stress");
  const Body* field = bodyNamed(s, "Field");
  const Body* sweeper = bodyNamed(s, "Sweeper");
  ASSERT_TRUE(field && sweeper);
  EXPECT_EQ(field->motion, Motion::kStatic);
  ASSERT_EQ(field->primitives.size(), static_cast<std::size_t>(stress::kGrid * stress::kGrid));
  for (const auto& p : field->primitives)
    EXPECT_EQ(p.source, ShapeSource::kBox);
  EXPECT_EQ(sweeper->motion, Motion::kKinematic);
  EXPECT_TRUE(sweeper->probe);
  ASSERT_EQ(sweeper->primitives.size(), 1u);
  EXPECT_EQ(sweeper->primitives[0].source, ShapeSource::kSphere);
  // tessellated within the default tolerance (a fraction of the sphere's diameter)
  const double tol = scene::SceneLimits{}.tessellation_tolerance * 2.0 * stress::kSweeperRadius_m;
  for (const auto& v : sweeper->primitives[0].shape->vertices())
    EXPECT_NEAR(glm::length(v.p), stress::kSweeperRadius_m, tol);
  expectPose(*sweeper, {-0.52, 0.1, stress::pillarCoordinate(4)}, kIdentity, 1e-12);
  int blocks = 0;
  for (const Body& b : s.bodies) {
    if (b.name.rfind("Block", 0) != 0)
      continue;
    const int k = std::stoi(b.name.substr(5));
    const double y = stress::kPillarSize_m[1] + 0.5 * stress::kBlockSide_m + 0.001;
    expectPose(b,
               {stress::blockCoordinate(k / stress::kBlocksPerSide), y,
                stress::blockCoordinate(k % stress::kBlocksPerSide)},
               kIdentity, 1e-12);
    ++blocks;
    EXPECT_EQ(b.motion, Motion::kDynamic);
    EXPECT_DOUBLE_EQ(b.mass, stress::kBlockMass_kg);
  }
  EXPECT_EQ(blocks, 16);
  ASSERT_TRUE(s.gravity_W.has_value());
  scene::testing::expectPlan(s.plan, "dynamics gravity", 1025, 17);
  EXPECT_GE(s.plan.static_primitives + s.plan.moving_primitives, 1000u);
}

// decomposed: two bodies, the static grooved plate and the held pin plate, each a primitive per
// piece node (hulls, already convex), the pin plate tilted where the stream starts; contact
// forces only
TEST(SceneRoundTrip, DecomposedIsTwoPlatesOfPiecesAndNeedsOnlyContactForces) {
  using namespace decomposed;
  const SceneModel s = load("decomposed");
  const Body* grooved = bodyNamed(s, "GroovedPlate");
  const Body* pins = bodyNamed(s, "PinPlate");
  ASSERT_TRUE(grooved && pins);
  EXPECT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(grooved->motion, Motion::kStatic);
  EXPECT_EQ(pins->motion, Motion::kKinematic);
  EXPECT_TRUE(pins->probe);
  EXPECT_EQ(grooved->primitives.size() % static_cast<std::size_t>(kGrooveCells * kGrooveCells), 0u);
  EXPECT_GE(grooved->primitives.size(), 450u);
  EXPECT_EQ(pins->primitives.size() % static_cast<std::size_t>(kPinCellsX * kPinCellsZ), 0u);
  EXPECT_GE(pins->primitives.size(), 90u);
  expectPose(*pins, {kRunX_m, kStartY_m, kRunZ_m[0]},
             glm::angleAxis(kTilt_rad, geom::Vec3{0.0, 0.0, 1.0}), 1e-9);
  // the ridge tops at y = 0 and the plate's floor kGrooveDepth_m + kBaseThickness_m below
  double top = -1.0, bottom = 1.0;
  for (const auto& p : grooved->primitives) {
    for (const geom::Vec3& v : worldPoints(*grooved, p)) {
      top = std::max(top, v.y);
      bottom = std::min(bottom, v.y);
    }
  }
  EXPECT_NEAR(top, 0.0, 1e-7);
  EXPECT_NEAR(bottom, -(kGrooveDepth_m + kBaseThickness_m), 1e-7);
  scene::testing::expectPlan(s.plan, "", static_cast<std::uint32_t>(grooved->primitives.size()),
                             static_cast<std::uint32_t>(pins->primitives.size()));
}

}  // namespace
}  // namespace hapticd::scenes
