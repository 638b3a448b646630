// The scene loader on hand-built glTF: shapes, meshes, materials, filters, joints, extras, mass
// properties against closed forms, the plan, unit scale, and external URIs.
#include "core/scene/loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "core/geometry/mass_properties.h"
#include "tests/core/scene/gltf_builder.h"
#include "tests/core/scene/plan_expect.h"
#include "tests/core/scene/scene_test_util.h"

namespace hapticd::scene {
namespace {

using testing::bodyNamed;
using testing::dynamicShape;
using testing::GltfBuilder;
using testing::hasProblem;
using testing::json;
using testing::load;
using testing::staticShape;

TEST(SceneLoader, StaticOnlySceneRunsContactForcesAndNothingMore) {
  GltfBuilder b;
  staticShape(b, "Floor", b.box({2.0, 0.1, 2.0}), {0.0, -0.05, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const SceneModel& s = *r.scene;
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.bodies[0].motion, Motion::kStatic);
  EXPECT_EQ(s.bodies[0].mass, 0.0);
  ASSERT_EQ(s.bodies[0].primitives.size(), 1u);
  EXPECT_EQ(s.bodies[0].primitives[0].source, ShapeSource::kBox);
  EXPECT_EQ(s.bodies[0].primitives[0].shape->vertices().size(), 8u);
  EXPECT_EQ(s.bodies[0].primitives[0].shape->faces().size(), 6u);
  testing::expectPlan(s.plan, "", 1, 0);
  EXPECT_NEAR(s.length_scale, std::sqrt(4.0 + 0.01 + 4.0), 1e-9);
  EXPECT_EQ(s.probe_body, -1);
}

TEST(SceneLoader, GlbAndGltfGiveTheSameScene) {
  GltfBuilder b;
  b.addNode([&] {
    json n = GltfBuilder::node("Cube", {0.0, 1.0, 0.0});
    n["mesh"] = b.addMesh(testing::cubeMesh(), "CubeMesh");
    GltfBuilder::physics(n)["motion"] = json::object();
    GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}}}};
    return n;
  }());
  const auto glb = b.glb();
  const LoadReport a = loadScene(glb, "cube.glb");
  const LoadReport c = load(b);
  ASSERT_TRUE(a.ok()) << a.message();
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_EQ(a.scene->bodies.size(), c.scene->bodies.size());
  EXPECT_DOUBLE_EQ(a.scene->bodies[0].mass, c.scene->bodies[0].mass);
  EXPECT_NEAR(a.scene->bodies[0].mass, 1000.0, 1e-9);
  EXPECT_EQ(a.scene->bodies[0].primitives[0].source, ShapeSource::kConvexMesh);
}

TEST(SceneLoader, EveryImplicitShapeBecomesAPolytopeWithinTolerance) {
  GltfBuilder b;
  const double r = 0.3;
  staticShape(b, "Box", b.box({1.0, 2.0, 3.0}), {0.0, 0.0, 0.0});
  staticShape(b, "Sphere", b.sphere(r), {5.0, 0.0, 0.0});
  staticShape(b, "Capsule", b.capsule(1.0, r, r), {10.0, 0.0, 0.0});
  staticShape(b, "Cone", b.cylinder(1.0, 0.0, r), {15.0, 0.0, 0.0});
  staticShape(b, "Cylinder", b.cylinder(1.0, r, r), {20.0, 0.0, 0.0});
  LoadOptions options;
  options.limits.tessellation_tolerance = 1e-3;
  const LoadReport rep = load(b, options);
  ASSERT_TRUE(rep.ok()) << rep.message();
  // all static colliders under separate roots: one static body each
  ASSERT_EQ(rep.scene->bodies.size(), 5u);
  const double tol = options.limits.tessellation_tolerance;
  {
    const Primitive& p = bodyNamed(*rep.scene, "Sphere").primitives[0];
    EXPECT_EQ(p.source, ShapeSource::kSphere);
    // every vertex within (1 + tol) r and every face at least (1 - tol) r from the centre
    for (const auto& v : p.shape->vertices()) {
      EXPECT_LE(glm::length(v.p), r * (1.0 + tol) * (1.0 + 1e-12));
      EXPECT_GE(glm::length(v.p), r);
    }
    for (const auto& f : p.shape->faces())
      EXPECT_GE(f.offset, r * (1.0 - tol) * (1.0 - 1e-12));
  }
  {
    const Primitive& p = bodyNamed(*rep.scene, "Cylinder").primitives[0];
    EXPECT_EQ(p.source, ShapeSource::kCylinder);
    for (const auto& v : p.shape->vertices()) {
      const double radial = std::hypot(v.p.x, v.p.z);
      EXPECT_LE(radial, r * (1.0 + tol) * (1.0 + 1e-12));
      EXPECT_NEAR(std::abs(v.p.y), 0.5, 1e-12);
    }
    // the faces around the side sink in by at most tol * r
    for (const auto& f : p.shape->faces()) {
      if (std::abs(f.normal.y) < 1e-9) {
        EXPECT_GE(f.offset, r * (1.0 - tol) * (1.0 - 1e-12));
      }
    }
  }
  {
    const Primitive& p = bodyNamed(*rep.scene, "Capsule").primitives[0];
    EXPECT_EQ(p.source, ShapeSource::kCapsule);
    double top = -1.0;
    for (const auto& v : p.shape->vertices())
      top = std::max(top, v.p.y);
    EXPECT_GE(top, 0.5 + r);
    EXPECT_LE(top, (0.5 + r * (1.0 + tol)) * (1.0 + 1e-12));
  }
  {
    const Primitive& p = bodyNamed(*rep.scene, "Cone").primitives[0];
    double top = -1.0;
    for (const auto& v : p.shape->vertices())
      top = std::max(top, v.p.y);
    EXPECT_NEAR(top, 0.5, 1e-12);  // the apex
  }
}

TEST(SceneLoader, AnInfinitePlaneBecomesALargeBoxUnderTheScene) {
  GltfBuilder b;
  staticShape(b, "Ground", b.plane(), {0.0, 0.0, 0.0});
  dynamicShape(b, "Cube", b.box({1.0, 1.0, 1.0}), {3.0, 0.5, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& ground = bodyNamed(*r.scene, "Ground");
  ASSERT_EQ(ground.primitives.size(), 1u);
  const Primitive& p = ground.primitives[0];
  EXPECT_EQ(p.source, ShapeSource::kPlane);
  const auto X = p.X_BP.toTransform();
  double top = -1e300, bottom = 1e300, xmin = 1e300, xmax = -1e300;
  for (const auto& v : p.shape->vertices()) {
    const Vec3 w = X.apply(v.p);
    top = std::max(top, w.y);
    bottom = std::min(bottom, w.y);
    xmin = std::min(xmin, w.x);
    xmax = std::max(xmax, w.x);
  }
  EXPECT_NEAR(top, 0.0, 1e-12);
  // the scene (the cube) spans sqrt(3); the box reaches 10 extents beyond its centre
  const double extent = std::sqrt(3.0);
  EXPECT_NEAR(bottom, -extent, 1e-9);
  EXPECT_NEAR(xmax - 3.0, 10.0 * extent, 1e-9);
  EXPECT_NEAR(3.0 - xmin, 10.0 * extent, 1e-9);
  // length_scale leaves the infinite plane out
  EXPECT_NEAR(r.scene->length_scale, extent, 1e-9);
}

/// One node whose collider is its own mesh (a convex hull of it when `hull`).
LoadReport meshColliderScene(const testing::Mesh& mesh,
                             const std::string& name,
                             bool hull,
                             const LoadOptions& options = {}) {
  GltfBuilder b;
  json n = GltfBuilder::node(name);
  n["mesh"] = b.addMesh(mesh, name + "Mesh");
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}}}};
  if (hull)
    GltfBuilder::physics(n)["collider"]["geometry"]["convexHull"] = true;
  b.addNode(n);
  return load(b, options);
}

TEST(SceneLoader, MeshHullAndConvexMeshAndNonConvexThroughItsPieces) {
  {
    const LoadReport r = meshColliderScene(testing::dentedCubeMesh(), "Dented", true);
    ASSERT_TRUE(r.ok()) << r.message();
    const Primitive& p = r.scene->bodies[0].primitives[0];
    EXPECT_EQ(p.source, ShapeSource::kMeshHull);
    EXPECT_EQ(p.shape->vertices().size(), 8u);  // the dent is inside the hull
  }
  {
    const LoadReport r = meshColliderScene(testing::cubeMesh(), "Cube", false);
    ASSERT_TRUE(r.ok()) << r.message();
    const Primitive& p = r.scene->bodies[0].primitives[0];
    EXPECT_EQ(p.source, ShapeSource::kConvexMesh);
    EXPECT_EQ(p.shape->vertices().size(), 8u);
    EXPECT_EQ(p.shape->faces().size(), 6u);
  }
  {
    // not convex: touched through the pieces of core/decomp's decomposition, said so; the dent
    // stays open: a point in it, 0.3 h above its apex, is outside every piece
    const LoadReport r = meshColliderScene(testing::dentedCubeMesh(0.5), "Dented", false);
    ASSERT_TRUE(r.ok()) << r.message();
    const auto& prims = r.scene->bodies[0].primitives;
    ASSERT_GE(prims.size(), 2u);
    for (const Primitive& p : prims) {
      EXPECT_EQ(p.source, ShapeSource::kMeshPiece);
      const Vec3 in_dent_P = p.X_BP.toTransform().inverse().apply(Vec3{0.0, 0.4, 0.0});
      bool outside = false;
      for (const auto& f : p.shape->faces())
        outside = outside || glm::dot(f.normal, in_dent_P) > f.offset + 1e-9;
      EXPECT_TRUE(outside) << "a piece fills the dent";
    }
    const std::string notes = testing::notesOf(*r.scene);
    EXPECT_NE(notes.find("mesh 0 'DentedMesh' (node 0 'Dented'): not convex, touched through " +
                         std::to_string(prims.size()) + " convex pieces (convex decomposition"),
              std::string::npos)
        << notes;
  }
}

TEST(SceneLoader, MaxHullVerticesHoldsThePrimitivesNotTheHullOfANonConvexMesh) {
  // eight small cubes on a ring, one mesh: its hull has more vertices than the limit, each of its
  // pieces fewer (a fine non-convex mesh, such as a torus, is like this)
  testing::Mesh ring;
  for (int k = 0; k < 8; ++k) {
    const testing::Mesh cube = testing::cubeMesh(0.1);
    const double a = 2.0 * std::numbers::pi * k / 8.0;
    const auto base = static_cast<std::uint32_t>(ring.vertices.size());
    for (const Vec3& v : cube.vertices)
      ring.vertices.push_back(v + Vec3{std::cos(a), 0.0, std::sin(a)});
    for (const std::uint32_t i : cube.triangles)
      ring.triangles.push_back(base + i);
  }
  LoadOptions options;
  options.limits.max_hull_vertices = 16;
  const LoadReport hull = meshColliderScene(ring, "Ring", true, options);
  EXPECT_TRUE(hasProblem(hull, "cannot build a convex hull: hull has")) << hull.message();
  const LoadReport r = meshColliderScene(ring, "Ring", false, options);
  ASSERT_TRUE(r.ok()) << r.message();
  const auto& prims = r.scene->bodies[0].primitives;
  ASSERT_GE(prims.size(), 8u);
  for (const Primitive& p : prims) {
    EXPECT_EQ(p.source, ShapeSource::kMeshPiece);
    EXPECT_LE(p.shape->vertices().size(), 16u);
  }

  // a convex surface over the limit is decomposed too (cache16's rule, the decomposition test
  // AMeshWhoseHullIsOverTheVertexLimitIsDecomposedNotRefused), each piece within the limit
  testing::Mesh prism;
  for (int k = 0; k < 12; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 12.0;
    prism.vertices.push_back({std::cos(a), 0.0, std::sin(a)});
    prism.vertices.push_back({std::cos(a), 1.0, std::sin(a)});
  }
  for (std::uint32_t k = 0; k < 12; ++k) {
    const std::uint32_t n = (k + 1) % 12;
    prism.triangles.insert(prism.triangles.end(),
                           {2 * k, 2 * k + 1, 2 * n, 2 * n, 2 * k + 1, 2 * n + 1});
    if (k > 0 && k < 11) {
      prism.triangles.insert(prism.triangles.end(), {0, 2 * k, 2 * n});
      prism.triangles.insert(prism.triangles.end(), {1, 2 * n + 1, 2 * k + 1});
    }
  }
  const LoadReport convex = meshColliderScene(prism, "Prism", false, options);
  ASSERT_TRUE(convex.ok()) << convex.message();
  ASSERT_GE(convex.scene->bodies[0].primitives.size(), 2u);
  for (const Primitive& p : convex.scene->bodies[0].primitives)
    EXPECT_LE(p.shape->vertices().size(), 16u);
}

TEST(SceneLoader, ScaleIsFoldedIntoTheShapeAndPosesStayRigid) {
  GltfBuilder b;
  json parent = GltfBuilder::node("Parent", {1.0, 2.0, 3.0});
  parent["scale"] = {2.0, 3.0, 4.0};
  parent["rotation"] = {0.0, std::sin(0.25), 0.0, std::cos(0.25)};
  GltfBuilder::physics(parent)["motion"] = json::object();
  const int p = b.addNode(parent);
  json child = GltfBuilder::node("Child", {1.0, 0.0, 0.0});
  GltfBuilder::physics(child)["collider"] = GltfBuilder::shapeCollider(b.box({1.0, 1.0, 1.0}));
  b.addNode(child, p);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& body = r.scene->bodies[0];
  EXPECT_NEAR(glm::length(body.X_WB.rotation), 1.0, 1e-12);
  EXPECT_NEAR(body.X_WB.translation.x, 1.0, 1e-12);
  const Primitive& prim = body.primitives[0];
  // the child sits at parent-local (1, 0, 0), i.e. (2, 0, 0) in the unscaled body frame
  EXPECT_NEAR(prim.X_BP.translation.x, 2.0, 1e-12);
  EXPECT_NEAR(glm::length(prim.X_BP.rotation), 1.0, 1e-12);
  Vec3 hi{-1e300};
  for (const auto& v : prim.shape->vertices())
    hi = glm::max(hi, v.p);
  EXPECT_NEAR(hi.x, 1.0, 1e-12);
  EXPECT_NEAR(hi.y, 1.5, 1e-12);
  EXPECT_NEAR(hi.z, 2.0, 1e-12);
  // 2 x 3 x 4 box at 1000 kg/m^3
  EXPECT_NEAR(body.mass, 24000.0, 1e-6);
}

TEST(SceneLoader, MassPropertiesOfABoxMatchTheClosedForm) {
  GltfBuilder b;
  dynamicShape(b, "Box", b.box({1.0, 2.0, 3.0}), {0.0, 0.0, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& body = r.scene->bodies[0];
  const double m = 6000.0;
  EXPECT_NEAR(body.mass, m, 1e-9 * m);
  EXPECT_NEAR(body.inverse_mass, 1.0 / m, 1e-12);
  EXPECT_FALSE(body.mass_declared);
  EXPECT_NEAR(glm::length(body.com_B), 0.0, 1e-12);
  const double ix = m / 12.0 * (4.0 + 9.0), iy = m / 12.0 * (1.0 + 9.0),
               iz = m / 12.0 * (1.0 + 4.0);
  EXPECT_NEAR(body.inertia_B[0][0], ix, 1e-9 * ix);
  EXPECT_NEAR(body.inertia_B[1][1], iy, 1e-9 * iy);
  EXPECT_NEAR(body.inertia_B[2][2], iz, 1e-9 * iz);
  EXPECT_NEAR(body.inertia_B[0][1], 0.0, 1e-9 * ix);
  EXPECT_NEAR(body.inverse_inertia_B[0][0], 1.0 / ix, 1e-9 / ix);
}

TEST(SceneLoader, MassPropertiesOfATessellatedSphereWithinTheTolerance) {
  for (const double tol : {1e-2, 1e-3}) {
    GltfBuilder b;
    const double r = 0.25;
    dynamicShape(b, "Ball", b.sphere(r), {0.0, 0.0, 0.0});
    LoadOptions options;
    options.limits.tessellation_tolerance = tol;
    const LoadReport rep = load(b, options);
    ASSERT_TRUE(rep.ok()) << rep.message();
    const Body& body = rep.scene->bodies[0];
    const double m = 1000.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    const double i = 0.4 * m * r * r;
    EXPECT_LE(std::abs(body.mass - m) / m, tol) << "tolerance " << tol;
    for (int k = 0; k < 3; ++k)
      EXPECT_LE(std::abs(body.inertia_B[k][k] - i) / i, tol);
  }
}

TEST(SceneLoader, OverlappingCollidersWeighTheirUnion) {
  // two 2 x 1 x 1 boxes overlapping by half their length (pieces of a decomposition overlap
  // where merged hulls reach into their neighbours): the body is the 3 x 1 x 1 box they cover,
  // not 4 m^3 with the middle counted twice
  GltfBuilder b;
  json body = GltfBuilder::node("Bar", {0.0, 0.0, 0.0});
  GltfBuilder::physics(body)["motion"] = json::object();
  const int parent = b.addNode(body);
  for (const double x : {0.0, 1.0}) {
    json piece = GltfBuilder::node("Piece", {x, 0.0, 0.0});
    GltfBuilder::physics(piece)["collider"] = GltfBuilder::shapeCollider(b.box({2.0, 1.0, 1.0}));
    b.addNode(piece, parent);
  }
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& bar = r.scene->bodies[0];
  const double m = 3000.0;
  EXPECT_NEAR(bar.mass, m, 1e-9 * m);
  EXPECT_NEAR(bar.com_B.x, 0.5, 1e-12);
  EXPECT_NEAR(glm::length(Vec3{0.0, bar.com_B.y, bar.com_B.z}), 0.0, 1e-12);
  const double ix = m / 12.0 * 2.0, iy = m / 12.0 * 10.0;
  EXPECT_NEAR(bar.inertia_B[0][0], ix, 1e-9 * ix);
  EXPECT_NEAR(bar.inertia_B[1][1], iy, 1e-9 * iy);
  EXPECT_NEAR(bar.inertia_B[2][2], iy, 1e-9 * iy);
  EXPECT_NE(testing::notesOf(*r.scene).find("1 of its colliders overlap others"), std::string::npos)
      << testing::notesOf(*r.scene);
}

TEST(SceneLoader, CollidersOverlappingTooMuchToWeighAreSummedAndSaidSo) {
  // a clump of overlapping balls, as a molecule of atoms: each ball cuts every other's cells
  // into hundreds; past the budget of work the union is given up for the sum, with a note
  GltfBuilder b;
  json body = GltfBuilder::node("Clump", {0.0, 0.0, 0.0});
  GltfBuilder::physics(body)["motion"] = json::object();
  const int parent = b.addNode(body);
  const int ball = b.sphere(1.0);
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    const double t = 0.7 * k;
    json atom =
        GltfBuilder::node("Atom", {0.4 * std::cos(t), 0.4 * std::sin(1.3 * t), 0.05 * k - 1.0});
    GltfBuilder::physics(atom)["collider"] = GltfBuilder::shapeCollider(ball);
    b.addNode(atom, parent);
  }
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& clump = r.scene->bodies[0];
  double sum = 0.0;
  for (const Primitive& p : clump.primitives)
    sum += 1000.0 * geom::polytopeIntegrals(*p.shape, geom::Transform{}).volume;
  EXPECT_NEAR(clump.mass, sum, 1e-9 * sum);
  EXPECT_NE(testing::notesOf(*r.scene).find("overlap too much to weigh their union"),
            std::string::npos)
      << testing::notesOf(*r.scene);
}

TEST(SceneLoader, DeclaredMassPropertiesAndInfiniteValues) {
  GltfBuilder b;
  dynamicShape(b, "Declared", b.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0},
               {{"mass", 2.0}, {"centerOfMass", {0.1, 0.0, 0.0}}});
  dynamicShape(b, "Inertia", b.box({1.0, 1.0, 1.0}), {5.0, 0.0, 0.0},
               {{"mass", 3.0},
                {"inertiaDiagonal", {1.0, 0.0, 2.0}},
                {"linearVelocity", {1.0, 2.0, 3.0}},
                {"gravityFactor", 0.5}});
  dynamicShape(b, "Infinite", b.box({1.0, 1.0, 1.0}), {10.0, 0.0, 0.0}, {{"mass", 0.0}});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const Body& d = bodyNamed(*r.scene, "Declared");
  EXPECT_TRUE(d.mass_declared);
  EXPECT_DOUBLE_EQ(d.mass, 2.0);
  EXPECT_NEAR(d.com_B.x, 0.1, 1e-12);
  // computed inertia (m/6 about the centre) scaled to 2 kg, moved 0.1 along x
  EXPECT_NEAR(d.inertia_B[0][0], 2.0 / 6.0, 1e-9);
  EXPECT_NEAR(d.inertia_B[1][1], 2.0 / 6.0 + 2.0 * 0.01, 1e-9);
  const Body& i = bodyNamed(*r.scene, "Inertia");
  EXPECT_TRUE(i.inertia_declared);
  EXPECT_DOUBLE_EQ(i.inertia_B[0][0], 1.0);
  EXPECT_DOUBLE_EQ(i.inertia_B[2][2], 2.0);
  EXPECT_DOUBLE_EQ(i.inverse_inertia_B[1][1], 0.0);  // 0 declared: infinite
  EXPECT_DOUBLE_EQ(i.inverse_inertia_B[2][2], 0.5);
  EXPECT_DOUBLE_EQ(i.linear_velocity_W.z, 3.0);
  EXPECT_DOUBLE_EQ(i.gravity_factor, 0.5);
  const Body& inf = bodyNamed(*r.scene, "Infinite");
  EXPECT_DOUBLE_EQ(inf.inverse_mass, 0.0);
  EXPECT_DOUBLE_EQ(inf.inverse_inertia_B[0][0], 0.0);
}

TEST(SceneLoader, ADeclaredMassWithoutColliderVolumeGetsASphereInertia) {
  // a driver body of joints (Blender writes an empty with a motion and a mass), and a body whose
  // only shape is a trigger: no volume to compute the inertia from, so a solid sphere of the
  // declared mass at 1000 kg/m^3 stands in, about the declared centre
  GltfBuilder b;
  staticShape(b, "Floor", b.box({1.0, 0.1, 1.0}), {0.0, -0.05, 0.0});
  json driver = GltfBuilder::node("Driver", {0.0, 1.0, 0.0});
  driver["scale"] = {0.02, 0.007, 0.02};
  GltfBuilder::physics(driver)["motion"] = {{"mass", 2.0}, {"centerOfMass", {0.0, 1.0, 0.0}}};
  b.addNode(driver);
  json sensor = GltfBuilder::node("Sensor", {2.0, 1.0, 0.0});
  GltfBuilder::physics(sensor)["motion"] = {{"mass", 0.5}};
  GltfBuilder::physics(sensor)["trigger"] = {{"geometry", {{"shape", b.sphere(0.2)}}}};
  b.addNode(sensor);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  for (const auto& [name, mass] : {std::pair{"Driver", 2.0}, std::pair{"Sensor", 0.5}}) {
    const Body& body = bodyNamed(*r.scene, name);
    EXPECT_DOUBLE_EQ(body.mass, mass);
    const double radius = std::cbrt(3.0 * mass / (4.0 * std::numbers::pi * 1000.0));
    const double moment = 0.4 * mass * radius * radius;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(body.inertia_B[k][k], moment, 1e-12 * moment) << name;
      EXPECT_NEAR(body.inverse_inertia_B[k][k], 1.0 / moment, 1e-9 / moment) << name;
      EXPECT_EQ(body.inertia_B[k][(k + 1) % 3], 0.0) << name;
    }
  }
  // the declared centre, in node space, takes the node's scale
  EXPECT_NEAR(bodyNamed(*r.scene, "Driver").com_B.y, 0.007, 1e-12);
  EXPECT_EQ(bodyNamed(*r.scene, "Sensor").com_B, Vec3(0.0));
  EXPECT_NE(
      testing::notesOf(*r.scene).find("node 1 'Driver': no collider volume: inertia of a solid "
                                      "sphere of its mass at 1000 kg/m^3 (radius 0.0781"),
      std::string::npos)
      << testing::notesOf(*r.scene);

  // with no mass either there is nothing to go on: refused, naming the body
  b.doc["nodes"][1]["extensions"]["KHR_physics_rigid_bodies"]["motion"].erase("mass");
  const LoadReport refused = load(b);
  EXPECT_TRUE(hasProblem(refused,
                         "node 1 'Driver': dynamic body has no collider volume to compute its "
                         "mass from"))
      << refused.message();
}

TEST(SceneLoader, ACompoundBodyOwnsItsDescendantColliders) {
  GltfBuilder b;
  json body = GltfBuilder::node("Stick", {0.0, 1.0, 0.0});
  GltfBuilder::physics(body)["motion"] = {{"isKinematic", true}};
  const int s = b.addNode(body);
  staticShape(b, "Part1", b.box({1.0, 0.1, 0.1}), {0.5, 0.0, 0.0}, s);
  staticShape(b, "Part2", b.sphere(0.1), {-0.5, 0.0, 0.0}, s);
  // a child with its own motion is a separate body
  json inner = GltfBuilder::node("Inner", {0.0, 0.5, 0.0});
  GltfBuilder::physics(inner)["motion"] = json::object();
  GltfBuilder::physics(inner)["collider"] = GltfBuilder::shapeCollider(b.box({0.1, 0.1, 0.1}));
  b.addNode(inner, s);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r.scene->bodies.size(), 2u);
  const Body& stick = bodyNamed(*r.scene, "Stick");
  EXPECT_EQ(stick.motion, Motion::kKinematic);
  EXPECT_EQ(stick.mass, 0.0);
  EXPECT_EQ(stick.primitives.size(), 2u);
  EXPECT_EQ(bodyNamed(*r.scene, "Inner").primitives.size(), 1u);
  EXPECT_EQ(bodyNamed(*r.scene, "Inner").motion, Motion::kDynamic);
  EXPECT_EQ(r.scene->plan.moving_primitives, 3u);
}

TEST(SceneLoader, MaterialsDecideFrictionAndRestitution) {
  const auto planOf = [](double friction, double restitution, const char* combine, bool on_floor) {
    GltfBuilder b;
    const int m = b.material(friction, restitution, combine);
    json floor = GltfBuilder::node("Floor");
    GltfBuilder::physics(floor)["collider"] = GltfBuilder::shapeCollider(b.box({4.0, 0.1, 4.0}));
    json cube = GltfBuilder::node("Cube", {0.0, 1.0, 0.0});
    GltfBuilder::physics(cube)["motion"] = json::object();
    GltfBuilder::physics(cube)["collider"] = GltfBuilder::shapeCollider(b.box({1.0, 1.0, 1.0}));
    GltfBuilder::physics(on_floor ? floor : cube)["collider"]["physicsMaterial"] = m;
    b.addNode(floor);
    b.addNode(cube);
    const LoadReport r = load(b);
    EXPECT_TRUE(r.ok()) << r.message();
    return r.scene ? r.scene->plan : SimulationPlan{};
  };
  EXPECT_TRUE(planOf(0.5, 0.0, "average", false).friction);
  EXPECT_FALSE(planOf(0.5, 0.0, "average", false).restitution);
  EXPECT_TRUE(planOf(0.0, 0.3, "average", false).restitution);
  // a frictionless cube on a floor without a material: the floor's default friction (0.5),
  // averaged with the cube's 0, is what the contacts use
  const SimulationPlan ice_on_default = planOf(0.0, 0.3, "average", false);
  EXPECT_TRUE(ice_on_default.friction);
  // (0: the plan pairs each material with itself too, as two such cubes would meet)
  EXPECT_DOUBLE_EQ(ice_on_default.friction_min, 0.0);
  EXPECT_DOUBLE_EQ(ice_on_default.friction_max, 0.25);
  EXPECT_TRUE(ice_on_default.friction_default);
  EXPECT_NE(describePlan(ice_on_default).find("friction: on (0 to 0.25; 0.5 for colliders without"),
            std::string::npos);
  // a material on the floor asks for friction against the cube (average with 0)
  EXPECT_TRUE(planOf(0.5, 0.0, "average", true).friction);
  // both materials multiply (or take the minimum) and the cube's is 0: nothing to simulate
  const auto both = [](const char* combine) {
    GltfBuilder b;
    const int floor_material = b.material(0.5, 0.5, combine);
    const int cube_material = b.material(0.0, 0.0, combine);
    json floor = GltfBuilder::node("Floor");
    GltfBuilder::physics(floor)["collider"] =
        GltfBuilder::shapeCollider(b.box({4.0, 0.1, 4.0}), {{"physicsMaterial", floor_material}});
    json cube = GltfBuilder::node("Cube", {0.0, 1.0, 0.0});
    GltfBuilder::physics(cube)["motion"] = json::object();
    GltfBuilder::physics(cube)["collider"] =
        GltfBuilder::shapeCollider(b.box({1.0, 1.0, 1.0}), {{"physicsMaterial", cube_material}});
    b.addNode(floor);
    b.addNode(cube);
    const LoadReport r = load(b);
    EXPECT_TRUE(r.ok()) << r.message();
    return r.scene ? r.scene->plan : SimulationPlan{};
  };
  EXPECT_FALSE(both("multiply").friction);
  EXPECT_FALSE(both("multiply").restitution);
  EXPECT_FALSE(both("minimum").friction);
  EXPECT_TRUE(both("maximum").friction);
  EXPECT_TRUE(both("maximum").restitution);
  // the floor's material meets the cube's default (no material: friction 0.5, no combine mode
  // declared: the floor's multiply)
  EXPECT_TRUE(planOf(0.5, 0.5, "multiply", true).friction);

  GltfBuilder b;
  b.material(0.5, 0.5);
  staticShape(b, "Unused", b.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.scene->materials.size(), 1u);
  EXPECT_DOUBLE_EQ(r.scene->materials[0].static_friction, 0.5);
  // a material no collider uses asks for nothing
  EXPECT_FALSE(r.scene->plan.friction);
  EXPECT_FALSE(r.scene->plan.restitution);
}

TEST(SceneLoader, CollisionFiltersFollowTheExtensionInBothDirections) {
  // KHR_physics_rigid_bodies: A collides with B when A's systems are a subset of B's
  // collideWithSystems and not of its notCollideWithSystems (the list B leaves out is the inverse
  // of the other), tested both ways
  GltfBuilder b;
  const auto filter = [&](const json& f) { return b.addPhysics("collisionFilters", f); };
  const int fa =
      filter({{"collisionSystems", {"character"}}, {"collideWithSystems", {"landscape"}}});
  const int fb =
      filter({{"collisionSystems", {"landscape"}}, {"notCollideWithSystems", {"debris"}}});
  const int fd = filter({{"collisionSystems", {"debris"}}});
  const int fe = filter({{"collisionSystems", {"character", "debris"}}});
  const int ff = filter({{"collisionSystems", {"landscape", "water"}}});
  const int fg =
      filter({{"collisionSystems", {"landscape"}}, {"collideWithSystems", {"character"}}});
  const int fh = filter({{"collisionSystems", {"rock"}}, {"collideWithSystems", {"character"}}});
  const std::pair<const char*, int> bodies[] = {{"A", fa}, {"B", fb}, {"C", -1}, {"D", fd},
                                                {"E", fe}, {"F", ff}, {"G", fg}, {"H", fh}};
  const int box = b.box({1.0, 1.0, 1.0});
  double x = 0.0;
  for (const auto& [name, f] : bodies) {
    json n = GltfBuilder::node(name, {x += 3.0, 0.0, 0.0});
    GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(box);
    if (f >= 0)
      GltfBuilder::physics(n)["collider"]["collisionFilter"] = f;
    b.addNode(n);
  }
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const auto collide = [&](const char* x_name, const char* y_name) {
    const Primitive& p = bodyNamed(*r.scene, x_name).primitives[0];
    const Primitive& q = bodyNamed(*r.scene, y_name).primitives[0];
    const bool one = (p.group & q.mask) && (q.group & p.mask);
    const bool other = (q.group & p.mask) && (p.group & q.mask);
    EXPECT_EQ(one, other) << x_name << " " << y_name;
    return one;
  };
  EXPECT_TRUE(collide("A", "B"));   // landscape is in A's list; character is not excluded by B
  EXPECT_FALSE(collide("A", "C"));  // A collides only with landscape; C is in no system
  EXPECT_TRUE(collide("B", "C"));   // B excludes only debris; C excludes nothing
  EXPECT_FALSE(collide("B", "D"));  // debris excluded by B
  EXPECT_FALSE(collide("B", "E"));  // E is partly debris: not a subset of B's inverse list
  EXPECT_FALSE(collide("A", "F"));  // F is landscape and water: not a subset of {landscape}
  EXPECT_TRUE(collide("B", "F"));
  EXPECT_TRUE(collide("A", "G"));   // each lists the other's only system
  EXPECT_FALSE(collide("A", "H"));  // H accepts A, but A does not accept rock
  EXPECT_TRUE(collide("C", "D"));   // no lists: everything
  EXPECT_TRUE(collide("E", "C"));

  // more behaviours than bits: refused
  GltfBuilder many;
  for (int i = 0; i < 40; ++i) {
    const std::string sys = "s" + std::to_string(i);
    const int f = many.addPhysics("collisionFilters",
                                  {{"collisionSystems", {sys}}, {"collideWithSystems", {sys}}});
    json n = GltfBuilder::node("N" + std::to_string(i), {2.0 * i, 0.0, 0.0});
    GltfBuilder::physics(n)["collider"] =
        GltfBuilder::shapeCollider(many.box({1.0, 1.0, 1.0}), {{"collisionFilter", f}});
    many.addNode(n);
  }
  const LoadReport bad = load(many);
  EXPECT_FALSE(bad.ok());
  EXPECT_TRUE(hasProblem(bad, "41 different collision behaviours, more than 32")) << bad.message();
  // many systems in one filter are one behaviour
  GltfBuilder wide;
  json systems = json::array();
  for (int i = 0; i < 40; ++i)
    systems.push_back("system" + std::to_string(i));
  const int f = wide.addPhysics("collisionFilters", {{"collisionSystems", systems}});
  staticShape(wide, "W", wide.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0});
  GltfBuilder::physics(wide.doc["nodes"][0])["collider"]["collisionFilter"] = f;
  EXPECT_TRUE(load(wide).ok());
}

json lockedLinear() {
  return {{"linearAxes", {0, 1, 2}}, {"max", 0.0}};
}

LoadReport jointScene(const json& limits) {
  GltfBuilder b;
  const int j = b.addPhysics("physicsJoints", {{"limits", limits}});
  json wheel = GltfBuilder::node("Wheel", {0.0, 1.0, 0.0});
  GltfBuilder::physics(wheel)["motion"] = json::object();
  GltfBuilder::physics(wheel)["collider"] = GltfBuilder::shapeCollider(b.cylinder(0.1, 0.5, 0.5));
  const int w = b.addNode(wheel);
  const int anchor = b.addNode(GltfBuilder::node("Anchor", {0.0, 1.0, 0.0}));
  json pivot = GltfBuilder::node("Pivot");
  GltfBuilder::physics(pivot)["joint"] = {{"connectedNode", anchor}, {"joint", j}};
  b.addNode(pivot, w);
  return load(b);
}

TEST(SceneLoader, JointsAreClassifiedAndAllKeptForTheDynamics) {
  {
    const LoadReport r = jointScene({lockedLinear(), {{"angularAxes", {0, 1, 2}}, {"max", 0.0}}});
    ASSERT_TRUE(r.ok()) << r.message();
    ASSERT_EQ(r.scene->joints.size(), 1u);
    EXPECT_EQ(r.scene->joints[0].kind, JointKind::kFixed);
    EXPECT_EQ(r.scene->joints[0].body_a, 0);
    EXPECT_EQ(r.scene->joints[0].body_b, -1);  // the anchor is the scene frame
    EXPECT_NEAR(r.scene->joints[0].X_BJ.translation.y, 1.0, 1e-12);
    EXPECT_TRUE(r.scene->plan.joints);
  }
  {
    const LoadReport r = jointScene({lockedLinear(),
                                     {{"angularAxes", {0, 2}}, {"max", 0.0}},
                                     {{"angularAxes", {1}}, {"min", -0.5}, {"max", 0.5}}});
    ASSERT_TRUE(r.ok()) << r.message();
    const Joint& j = r.scene->joints[0];
    EXPECT_EQ(j.kind, JointKind::kHinge);
    EXPECT_EQ(j.hinge_axis, 1);
    ASSERT_TRUE(j.hinge_min && j.hinge_max);
    EXPECT_DOUBLE_EQ(*j.hinge_min, -0.5);
    EXPECT_DOUBLE_EQ(*j.hinge_max, 0.5);
    EXPECT_EQ(j.limits.size(), 3u);
    EXPECT_FALSE(j.enable_collision);
  }
  {
    // a free hinge: one-axis locks, no limit on the free axis
    const LoadReport r = jointScene({lockedLinear(),
                                     {{"angularAxes", {0}}, {"min", 0.0}, {"max", 0.0}},
                                     {{"angularAxes", {1}}, {"min", 0.0}, {"max", 0.0}}});
    ASSERT_TRUE(r.ok()) << r.message();
    EXPECT_EQ(r.scene->joints[0].hinge_axis, 2);
    EXPECT_FALSE(r.scene->joints[0].hinge_min);
  }
  {
    // a ball joint: simulated like every kind (SceneModel::joints), no note
    const LoadReport r = jointScene(json::array({lockedLinear()}));
    ASSERT_TRUE(r.ok()) << r.message();
    EXPECT_TRUE(r.scene->unsimulated_joints.empty());
    ASSERT_EQ(r.scene->joints.size(), 1u);
    EXPECT_EQ(r.scene->joints[0].kind, JointKind::kBall);
    EXPECT_EQ(r.scene->joints[0].node, 2);
    EXPECT_TRUE(r.scene->plan.joints);
    EXPECT_EQ(testing::notesOf(*r.scene).find("joint"), std::string::npos)
        << testing::notesOf(*r.scene);
  }
  {
    const LoadReport r = jointScene({{{"linearAxes", {0, 2}}, {"max", 0.0}},
                                     {{"angularAxes", {0, 1, 2}}, {"max", 0.0}}});  // prismatic
    ASSERT_TRUE(r.ok()) << r.message();
    ASSERT_EQ(r.scene->joints.size(), 1u);
    EXPECT_EQ(r.scene->joints[0].kind, JointKind::kSlider);
    EXPECT_EQ(r.scene->joints[0].hinge_axis, 1);
  }
}

TEST(SceneLoader, HapticExtrasProbeStiffnessGravity) {
  GltfBuilder b;
  json peg = GltfBuilder::node("Peg", {0.0, 1.0, 0.0});
  GltfBuilder::physics(peg)["collider"] = GltfBuilder::shapeCollider(b.box({0.02, 0.1, 0.02}));
  peg["extras"]["haptic"] = {{"probe", true}, {"stiffness", 2000.0}};
  b.addNode(peg);
  staticShape(b, "Floor", b.box({1.0, 0.1, 1.0}), {0.0, 0.0, 0.0});
  b.gravity({0.0, -9.81, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const SceneModel& s = *r.scene;
  ASSERT_GE(s.probe_body, 0);
  const Body& probe = s.bodies[static_cast<std::size_t>(s.probe_body)];
  EXPECT_EQ(probe.name, "Peg");
  EXPECT_TRUE(probe.probe);
  EXPECT_EQ(probe.motion, Motion::kKinematic);  // a probe without motion: moved by the device
  ASSERT_TRUE(probe.stiffness_n_per_m);
  EXPECT_DOUBLE_EQ(*probe.stiffness_n_per_m, 2000.0);
  ASSERT_TRUE(s.gravity_W);
  EXPECT_DOUBLE_EQ(s.gravity_W->y, -9.81);
  // gravity declared, but nothing dynamic feels it
  EXPECT_FALSE(s.plan.gravity);
  EXPECT_FALSE(s.plan.dynamics);
}

// extras.haptic.active: false keeps a kinematic or dynamic body out of the scene until a client
// adds it; absent or true: active; not a boolean, or false on a static collider or the probe:
// an error naming the node.
TEST(SceneLoader, HapticExtrasActive) {
  GltfBuilder b;
  staticShape(b, "Floor", b.box({1.0, 0.1, 1.0}), {0.0, -0.05, 0.0});
  json shelf = GltfBuilder::node("Shelf", {0.5, 0.5, 0.0});
  GltfBuilder::physics(shelf)["motion"] = {{"isKinematic", true}};
  GltfBuilder::physics(shelf)["collider"] = GltfBuilder::shapeCollider(b.box({0.2, 0.02, 0.2}));
  shelf["extras"]["haptic"] = {{"active", false}};
  b.addNode(shelf);
  const int crate = dynamicShape(b, "Crate", b.box({0.1, 0.1, 0.1}), {0.0, 0.5, 0.0});
  b.doc["nodes"][static_cast<std::size_t>(crate)]["extras"]["haptic"] = {{"active", false}};
  const int ball = dynamicShape(b, "Ball", b.sphere(0.05), {0.3, 0.5, 0.0});
  b.doc["nodes"][static_cast<std::size_t>(ball)]["extras"]["haptic"] = {{"active", true}};
  dynamicShape(b, "Plain", b.box({0.1, 0.1, 0.1}), {-0.3, 0.5, 0.0});
  {
    const LoadReport r = load(b);
    ASSERT_TRUE(r.ok()) << r.message();
    EXPECT_FALSE(bodyNamed(*r.scene, "Shelf").active);
    EXPECT_FALSE(bodyNamed(*r.scene, "Crate").active);
    EXPECT_TRUE(bodyNamed(*r.scene, "Ball").active);
    EXPECT_TRUE(bodyNamed(*r.scene, "Plain").active);
    EXPECT_TRUE(bodyNamed(*r.scene, "Floor").active);
  }
  {
    GltfBuilder bad = b;
    bad.doc["nodes"][static_cast<std::size_t>(crate)]["extras"]["haptic"]["active"] = 0;
    const LoadReport r = load(bad);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(hasProblem(r, "'Crate' extras.haptic: active")) << r.message();
  }
  {
    GltfBuilder bad = b;
    bad.doc["nodes"][0]["extras"]["haptic"]["active"] = false;
    const LoadReport r = load(bad);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(hasProblem(r, "'Floor': extras.haptic.active false on a static collider"))
        << r.message();
  }
  {
    GltfBuilder bad = b;
    bad.doc["nodes"][static_cast<std::size_t>(ball)]["extras"]["haptic"] = {{"active", false},
                                                                            {"probe", true}};
    const LoadReport r = load(bad);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(hasProblem(r, "'Ball': extras.haptic.active false on the probe body"))
        << r.message();
  }
}

TEST(SceneLoader, GravityOnTheAssetAndTheGravityFactor) {
  const auto plan = [](double factor, bool on_asset) {
    GltfBuilder b;
    dynamicShape(b, "Cube", b.box({1.0, 1.0, 1.0}), {0.0, 1.0, 0.0}, {{"gravityFactor", factor}});
    if (on_asset) {
      b.doc["asset"]["extras"]["haptic"]["gravity"] = {0.0, -9.81, 0.0};
    } else {
      b.gravity({0.0, -9.81, 0.0});
    }
    const LoadReport r = load(b);
    EXPECT_TRUE(r.ok()) << r.message();
    return r.scene ? r.scene->plan : SimulationPlan{};
  };
  EXPECT_TRUE(plan(1.0, false).gravity);
  EXPECT_TRUE(plan(1.0, true).gravity);
  EXPECT_TRUE(plan(1.0, false).dynamics);
  EXPECT_FALSE(plan(0.0, false).gravity);

  GltfBuilder none;
  dynamicShape(none, "Cube", none.box({1.0, 1.0, 1.0}), {0.0, 1.0, 0.0});
  const LoadReport r = load(none);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scene->gravity_W);
  EXPECT_FALSE(r.scene->plan.gravity);  // no gravity declared: none simulated
}

TEST(SceneLoader, DescribePlanNamesEveryStage) {
  SimulationPlan plan;
  plan.dynamics = true;
  plan.static_primitives = 4;
  plan.moving_primitives = 2;
  const std::string text = describePlan(plan);
  EXPECT_NE(text.find("contact forces: on"), std::string::npos);
  EXPECT_NE(text.find("dynamics: on"), std::string::npos);
  EXPECT_NE(text.find("gravity: off"), std::string::npos);
  EXPECT_NE(text.find("friction: off"), std::string::npos);
  EXPECT_NE(text.find("restitution: off"), std::string::npos);
  EXPECT_NE(text.find("joints: off"), std::string::npos);
  EXPECT_NE(text.find("2 moving primitives, 4 static primitives"), std::string::npos);
}

/// The same scene with every length multiplied by `s`.
LoadReport scaledScene(double s) {
  GltfBuilder b;
  staticShape(b, "Floor", b.box({4.0 * s, 0.2 * s, 4.0 * s}), {0.0, -0.1 * s, 0.0});
  dynamicShape(b, "Ball", b.sphere(0.3 * s), {0.0, 0.5 * s, 0.0});
  json cube = GltfBuilder::node("Cube", {1.0 * s, 0.5 * s, 0.0});
  cube["mesh"] = b.addMesh(testing::cubeMesh(0.25 * s), "CubeMesh");
  GltfBuilder::physics(cube)["motion"] = json::object();
  GltfBuilder::physics(cube)["collider"] = {{"geometry", {{"node", 2}}}};
  b.addNode(cube);
  return load(b);
}

TEST(SceneLoader, TheSameSceneInMillimetresMetresAndKilometres) {
  const LoadReport m = scaledScene(1.0);
  ASSERT_TRUE(m.ok()) << m.message();
  for (const double s : {1e-3, 1e3}) {
    const LoadReport r = scaledScene(s);
    ASSERT_TRUE(r.ok()) << r.message();
    EXPECT_NEAR(r.scene->length_scale / m.scene->length_scale, s, 1e-6 * s);
    ASSERT_EQ(r.scene->bodies.size(), m.scene->bodies.size());
    for (std::size_t i = 0; i < r.scene->bodies.size(); ++i) {
      const Body& a = m.scene->bodies[i];
      const Body& c = r.scene->bodies[i];
      ASSERT_EQ(a.primitives.size(), c.primitives.size());
      for (std::size_t k = 0; k < a.primitives.size(); ++k) {
        EXPECT_EQ(a.primitives[k].shape->vertices().size(),
                  c.primitives[k].shape->vertices().size());
        EXPECT_EQ(a.primitives[k].shape->faces().size(), c.primitives[k].shape->faces().size());
      }
      if (a.motion == Motion::kDynamic) {
        EXPECT_NEAR(c.mass / a.mass, s * s * s, 1e-6 * s * s * s);
        EXPECT_NEAR(c.inertia_B[0][0] / a.inertia_B[0][0], std::pow(s, 5), 1e-6 * std::pow(s, 5));
      }
      EXPECT_NEAR(glm::length(c.X_WB.translation) / s, glm::length(a.X_WB.translation), 1e-9);
    }
    EXPECT_EQ(r.scene->plan.dynamics, m.scene->plan.dynamics);
    EXPECT_EQ(r.scene->plan.static_primitives, m.scene->plan.static_primitives);
  }
}

TEST(SceneLoader, EveryProblemIsReportedNotJustTheFirst) {
  GltfBuilder b;
  json n0 = GltfBuilder::node("A");
  n0["translation"] = "up";
  n0["children"] = {7};
  b.addNode(n0);
  json n1 = GltfBuilder::node("B");
  n1["rotation"] = {0.0, 0.0, 0.0, 3.0};
  b.addNode(n1);
  b.doc["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
  const LoadReport r = load(b);
  ASSERT_FALSE(r.ok());
  EXPECT_GE(r.problems.size(), 4u) << r.message();
  EXPECT_TRUE(hasProblem(r, "node 0 'A': translation must be an array of 3 numbers"));
  EXPECT_TRUE(hasProblem(r, "node 0 'A': children index 7 out of range (2 nodes)"));
  EXPECT_TRUE(hasProblem(r, "node 1 'B': rotation is not a unit quaternion (norm 3"));
  EXPECT_TRUE(hasProblem(r, "unsupported required extension 'EXT_mesh_gpu_instancing'"));
}

TEST(SceneLoader, NearlyUnitQuaternionsAreNormalised) {
  GltfBuilder b;
  json n = GltfBuilder::node("Q");
  n["rotation"] = {0.0, 0.0, 0.0, 1.0004};
  GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(b.box({1.0, 1.0, 1.0}));
  b.addNode(n);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_NEAR(glm::length(r.scene->bodies[0].X_WB.rotation), 1.0, 1e-15);
}

class ExternalUri : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hapticd_uri_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "inside");
    // a scene whose buffer is the file cube.bin
    testing::GltfBuilder b;
    json n = GltfBuilder::node("Cube");
    n["mesh"] = b.addMesh(testing::cubeMesh(), "CubeMesh");
    GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}}}};
    b.addNode(n);
    bin_ = b.bin;
    std::ofstream(dir_ / "inside" / "cube.bin", std::ios::binary)
        .write(reinterpret_cast<const char*>(bin_.data()),
               static_cast<std::streamsize>(bin_.size()));
    std::ofstream(dir_ / "outside.bin", std::ios::binary)
        .write(reinterpret_cast<const char*>(bin_.data()),
               static_cast<std::streamsize>(bin_.size()));
    std::filesystem::create_symlink(dir_ / "outside.bin", dir_ / "inside" / "link.bin");
    doc_ = b.doc;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  LoadReport withUri(const std::string& uri, bool allow) {
    json d = doc_;
    d["buffers"] = json::array({json{{"byteLength", bin_.size()}, {"uri", uri}}});
    LoadOptions options;
    if (allow)
      options.allowed_uri_dir = dir_ / "inside";
    return loadScene(testing::bytesOf(d.dump()), "uri.gltf", options);
  }

  std::filesystem::path dir_;
  std::vector<std::uint8_t> bin_;
  json doc_;
};

TEST_F(ExternalUri, RefusedUnlessAFolderIsAllowedThenOnlyInsideIt) {
  const LoadReport refused = withUri("cube.bin", false);
  EXPECT_FALSE(refused.ok());
  EXPECT_TRUE(
      hasProblem(refused, "buffer 0: external URI 'cube.bin' refused: no folder is allowed"))
      << refused.message();

  const LoadReport allowed = withUri("cube.bin", true);
  ASSERT_TRUE(allowed.ok()) << allowed.message();
  EXPECT_EQ(allowed.scene->bodies[0].primitives[0].shape->vertices().size(), 8u);

  const LoadReport up = withUri("../outside.bin", true);
  EXPECT_TRUE(hasProblem(up, "traverses out of the allowed folder")) << up.message();
  const LoadReport encoded = withUri("%2e%2e/outside.bin", true);
  EXPECT_TRUE(hasProblem(encoded, "traverses out of the allowed folder")) << encoded.message();
  const LoadReport absolute = withUri((dir_ / "outside.bin").string(), true);
  EXPECT_TRUE(hasProblem(absolute, "is an absolute path")) << absolute.message();
  const LoadReport link = withUri("link.bin", true);
  EXPECT_TRUE(hasProblem(link, "resolves outside the allowed folder")) << link.message();
  const LoadReport missing = withUri("nothing.bin", true);
  EXPECT_TRUE(hasProblem(missing, "no such file")) << missing.message();
  const LoadReport scheme = withUri("file:///etc/passwd", true);
  EXPECT_TRUE(hasProblem(scheme, "has a scheme")) << scheme.message();
}

TEST_F(ExternalUri, ImageUrisAreNeverResolvedReadOrRequired) {
  // textures are appearance only: missing ones, ones outside the folder, absolute paths and web
  // addresses change nothing, with a folder allowed or without one
  json d = doc_;
  d["images"] = json::array({{{"uri", "textures/missing.png"}},
                             {{"uri", "../outside.bin"}},
                             {{"uri", (dir_ / "outside.bin").string()}},
                             {{"uri", "https://example.com/wood.png"}},
                             {{"uri", "link.bin"}},
                             {{"bufferView", 0}, {"mimeType", "image/png"}}});
  d["textures"] = json::array({{{"source", 0}}});
  d["buffers"] = json::array({json{{"byteLength", bin_.size()}, {"uri", "cube.bin"}}});
  LoadOptions options;
  options.allowed_uri_dir = dir_ / "inside";
  const LoadReport beside = loadScene(testing::bytesOf(d.dump()), "images.gltf", options);
  ASSERT_TRUE(beside.ok()) << beside.message();
  EXPECT_EQ(beside.scene->bodies[0].primitives[0].shape->vertices().size(), 8u);

  d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + testing::base64(bin_);
  const LoadReport upload = loadScene(testing::bytesOf(d.dump()), "images.gltf");
  EXPECT_TRUE(upload.ok()) << upload.message();
}

TEST(SceneLoader, LoadSceneFileChecksTheSizeFirst) {
  const auto path = std::filesystem::temp_directory_path() / "hapticd_size_test.gltf";
  GltfBuilder b;
  staticShape(b, "Box", b.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0});
  { std::ofstream(path) << b.gltf(); }
  LoadOptions small;
  small.limits.max_file_bytes = 10;
  const LoadReport r = loadSceneFile(path, small);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(hasProblem(r, "exceeds max_file_bytes (10)")) << r.message();
  const LoadReport ok = loadSceneFile(path);
  EXPECT_TRUE(ok.ok()) << ok.message();
  EXPECT_EQ(ok.scene->name, "hapticd_size_test.gltf");
  std::filesystem::remove(path);
  const LoadReport none = loadSceneFile(path);
  EXPECT_TRUE(hasProblem(none, "cannot read")) << none.message();
}

TEST(SceneLoader, LimitsAreEnforced) {
  GltfBuilder b;
  for (int i = 0; i < 5; ++i)
    staticShape(b, "B" + std::to_string(i), b.box({1.0, 1.0, 1.0}), {2.0 * i, 0.0, 0.0});
  LoadOptions options;
  options.limits.max_primitives = 4;
  EXPECT_TRUE(hasProblem(load(b, options), "5 colliders exceeds max_primitives (4)"));
  options = {};
  options.limits.max_nodes = 3;
  EXPECT_TRUE(hasProblem(load(b, options), "5 nodes exceeds max_nodes (3)"));
  options = {};
  options.limits.max_bodies = 2;
  EXPECT_TRUE(hasProblem(load(b, options), "5 bodies exceeds max_bodies (2)"));
  {
    // three colliders on one mesh at three scales: three hulls of 8 points, over a budget of 20
    GltfBuilder m;
    const int mesh = m.addMesh(testing::cubeMesh(), "CubeMesh");
    for (int i = 0; i < 3; ++i) {
      json n = GltfBuilder::node("C" + std::to_string(i), {2.0 * i, 0.0, 0.0});
      n["mesh"] = mesh;
      n["scale"] = {1.0 + i, 1.0, 1.0};
      GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", i}}}};
      m.addNode(n);
    }
    options = {};
    options.limits.max_total_hull_input_points = 20;
    const LoadReport r = load(m, options);
    EXPECT_TRUE(hasProblem(r,
                           "node 2 'C2': the scene's colliders have more than "
                           "max_total_hull_input_points (20)"))
        << r.message();
    options.limits.max_total_hull_input_points = 24;
    EXPECT_TRUE(load(m, options).ok());
  }
  GltfBuilder s;
  staticShape(s, "Ball", s.sphere(1.0), {0.0, 0.0, 0.0});
  options = {};
  options.limits.tessellation_tolerance = 1e-7;
  EXPECT_TRUE(hasProblem(load(s, options), "needs more than 4096 hull vertices"));
  options.limits.tessellation_tolerance = 0.0;
  EXPECT_TRUE(hasProblem(load(s, options), "tessellation_tolerance 0 must be in (0, 0.5)"));
}

}  // namespace
}  // namespace hapticd::scene

namespace hapticd::scene {
namespace {

Body codeBody(Motion motion, std::int32_t material) {
  Body b;
  b.motion = motion;
  Primitive p;
  p.material = material;
  b.primitives.push_back(p);
  return b;
}

TEST(ScenePlan, OnlyWhatTheSceneCallsFor) {
  SceneModel s;
  s.materials.push_back(Material{"grippy", 0.8, 0.7, 0.0});
  s.materials.push_back(Material{"bouncy", 0.0, 0.0, 0.9});
  // kinematic bodies alone: contact forces, nothing else
  s.bodies.push_back(codeBody(Motion::kKinematic, -1));
  s.bodies.push_back(codeBody(Motion::kStatic, 0));
  s.gravity_W = Vec3{0.0, -9.81, 0.0};
  SimulationPlan p = makePlan(s);
  EXPECT_TRUE(p.contact_forces);
  EXPECT_FALSE(p.dynamics);
  EXPECT_FALSE(p.gravity);   // declared, but nothing dynamic
  EXPECT_FALSE(p.friction);  // the kinematic body is not the probe
  EXPECT_EQ(p.static_primitives, 1u);
  EXPECT_EQ(p.moving_primitives, 1u);
  // the kinematic body becomes the probe: the static grippy floor gives it friction
  s.bodies[0].probe = true;
  s.probe_body = 0;
  p = makePlan(s);
  EXPECT_TRUE(p.friction);
  EXPECT_FALSE(p.restitution);  // restitution needs a dynamic body
  // a dynamic bouncy body: dynamics, gravity, restitution
  s.bodies.push_back(codeBody(Motion::kDynamic, 1));
  p = makePlan(s);
  EXPECT_TRUE(p.dynamics);
  EXPECT_TRUE(p.gravity);
  EXPECT_TRUE(p.restitution);
  // zero gravity declared: no gravity stage
  s.gravity_W = Vec3{0.0};
  EXPECT_FALSE(makePlan(s).gravity);
  s.gravity_W.reset();
  EXPECT_FALSE(makePlan(s).gravity);
  EXPECT_FALSE(makePlan(s).joints);
  s.joints.push_back(Joint{});
  EXPECT_TRUE(makePlan(s).joints);
}

}  // namespace
}  // namespace hapticd::scene

namespace hapticd::scene {
namespace {

TEST(SceneLoader, IdenticalCollidersShareOneHull) {
  GltfBuilder b;
  const int box = b.box({0.1, 0.4, 0.1});
  json field = GltfBuilder::node("Field");
  const int f = b.addNode(field);
  for (int i = 0; i < 3; ++i)
    staticShape(b, "Pillar" + std::to_string(i), box, {0.3 * i, 0.0, 0.0}, f);
  json big = GltfBuilder::node("Big", {2.0, 0.0, 0.0});
  big["scale"] = {2.0, 2.0, 2.0};
  GltfBuilder::physics(big)["collider"] = GltfBuilder::shapeCollider(box);
  b.addNode(big, f);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r.scene->bodies.size(), 1u);  // one static body for the root Field
  const auto& prims = r.scene->bodies[0].primitives;
  ASSERT_EQ(prims.size(), 4u);
  EXPECT_EQ(prims[0].shape.get(), prims[1].shape.get());
  EXPECT_EQ(prims[0].shape.get(), prims[2].shape.get());
  EXPECT_NE(prims[0].shape.get(), prims[3].shape.get());  // scaled: its own hull
  EXPECT_NEAR(prims[2].X_BP.translation.x - prims[0].X_BP.translation.x, 0.6, 1e-12);
}

}  // namespace
}  // namespace hapticd::scene

namespace hapticd::scene {
namespace {

TEST(SceneLoader, AMatrixNodeMatchesTheSameTrsNode) {
  const double a = 0.7;
  const auto make = [&](bool matrix) {
    GltfBuilder b;
    json n = GltfBuilder::node("Box");
    if (matrix) {
      // column-major: rotation a about Z, scale (2, 1, 3), translation (1, 2, 3)
      n.erase("translation");
      n["matrix"] = {2 * std::cos(a),
                     2 * std::sin(a),
                     0,
                     0,
                     -std::sin(a),
                     std::cos(a),
                     0,
                     0,
                     0,
                     0,
                     3,
                     0,
                     1,
                     2,
                     3,
                     1};
    } else {
      n["translation"] = {1, 2, 3};
      n["rotation"] = {0, 0, std::sin(a / 2), std::cos(a / 2)};
      n["scale"] = {2, 1, 3};
    }
    GltfBuilder::physics(n)["motion"] = json::object();
    GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(b.box({1.0, 1.0, 1.0}));
    b.addNode(n);
    return load(b);
  };
  const LoadReport m = make(true), t = make(false);
  ASSERT_TRUE(m.ok()) << m.message();
  ASSERT_TRUE(t.ok()) << t.message();
  const Body& bm = m.scene->bodies[0];
  const Body& bt = t.scene->bodies[0];
  EXPECT_NEAR(glm::length(bm.X_WB.translation - bt.X_WB.translation), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(glm::dot(bm.X_WB.rotation, bt.X_WB.rotation)), 1.0, 1e-12);
  EXPECT_NEAR(bm.mass, 6000.0, 1e-6);
  EXPECT_NEAR(bt.mass, 6000.0, 1e-6);
}

TEST(SceneLoader, GeometryMayComeFromANodeOutsideTheScene) {
  GltfBuilder b;
  json n = GltfBuilder::node("Body");
  GltfBuilder::physics(n)["motion"] = json::object();
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 1}, {"convexHull", true}}}};
  b.addNode(n);
  // node 1: not in the scene, only the geometry's source, with a child mesh offset by 1 on x
  b.doc["nodes"].push_back({{"name", "Source"}, {"children", {2}}});
  b.doc["nodes"].push_back({{"name", "Part"},
                            {"translation", {1.0, 0.0, 0.0}},
                            {"mesh", b.addMesh(testing::cubeMesh(), "CubeMesh")}});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r.scene->bodies.size(), 1u);
  const Body& body = r.scene->bodies[0];
  EXPECT_NEAR(body.com_B.x, 1.0, 1e-12);  // the child's offset is kept
  EXPECT_NEAR(body.mass, 1000.0, 1e-9);
}

TEST(SceneLoader, ATaperedCapsuleIsTheHullOfItsTwoSpheres) {
  GltfBuilder b;
  staticShape(b, "Tapered", b.capsule(1.0, 0.1, 0.3), {0.0, 0.0, 0.0});
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  Vec3 lo{1e300}, hi{-1e300};
  for (const auto& v : r.scene->bodies[0].primitives[0].shape->vertices()) {
    lo = glm::min(lo, v.p);
    hi = glm::max(hi, v.p);
  }
  EXPECT_NEAR(hi.y, 0.5 + 0.1, 0.1 * 1e-3 + 1e-12);
  EXPECT_NEAR(lo.y, -0.5 - 0.3, 0.3 * 1e-3 + 1e-12);
  EXPECT_NEAR(hi.x, 0.3, 0.3 * 1e-3 + 1e-12);
}

TEST(SceneLoader, ADeepHierarchyLoadsWithoutRecursion) {
  GltfBuilder b;
  int parent = b.addNode(GltfBuilder::node("Root"));
  for (int i = 0; i < 5000; ++i)
    parent = b.addNode(GltfBuilder::node("N", {0.001, 0.0, 0.0}), parent);
  staticShape(b, "Leaf", b.box({1.0, 1.0, 1.0}), {0.0, 0.0, 0.0}, parent);
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r.scene->bodies.size(), 1u);
  EXPECT_EQ(r.scene->bodies[0].name, "Root");
  EXPECT_NEAR(r.scene->bodies[0].primitives[0].X_BP.translation.x, 5.0, 1e-9);
}

}  // namespace
}  // namespace hapticd::scene
