#include "scenes/demo_scenes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/decomp/decompose.h"
#include "scenes/glb_builder.h"

namespace hapticd::scenes {
namespace {

constexpr double kPi = std::numbers::pi;

Json physics(Json body) {
  return {{"KHR_physics_rigid_bodies", std::move(body)}};
}

/// A collider on node `index` whose geometry is that node's own mesh, as a convex hull.
void meshCollider(GltfBuilder& b, int index, int material = -1) {
  Json collider = {{"geometry", {{"node", index}, {"convexHull", true}}}};
  if (material >= 0)
    collider["physicsMaterial"] = material;
  Json& n = b.node(index);
  n["extensions"]["KHR_physics_rigid_bodies"]["collider"] = collider;
}

/// A collider of implicit shape `shape` on node `index`.
void shapeCollider(GltfBuilder& b, int index, int shape, int material = -1) {
  Json collider = {{"geometry", {{"shape", shape}}}};
  if (material >= 0)
    collider["physicsMaterial"] = material;
  b.node(index)["extensions"]["KHR_physics_rigid_bodies"]["collider"] = collider;
}

/// The body the probe holds: a kinematic root node with `mesh`, at `start`; its collider is added
/// by the caller.
int heldBody(GltfBuilder& b, const std::string& name, int mesh, const Json& start) {
  const int n = b.addNode({{"name", name},
                           {"mesh", mesh},
                           {"translation", start},
                           {"extensions", physics({{"motion", {{"isKinematic", true}}}})},
                           {"extras", {{"haptic", {{"probe", true}}}}}});
  b.addRoot(n);
  return n;
}

Json boxShape(const Vec3& size) {
  return {{"type", "box"}, {"box", {{"size", jsonVec(size)}}}};
}

/// A box's implicit shape and its render mesh `name`, shared by the nodes that use them.
struct Box {
  int shape = 0;
  int mesh = 0;
};
Box addBox(GltfBuilder& b, const std::string& name, const Vec3& size, int colour) {
  const int shape = b.addShape(boxShape(size));
  return {shape, b.addMesh(name, boxMesh(size), colour)};
}

/// A dynamic root node `name` of `box` at `translation` with mass `mass_kg` (the loader computes
/// its inertia); its collider is the box's shape, with physics material `material` (-1: none).
void addDynamicBox(GltfBuilder& b,
                   const std::string& name,
                   const Box& box,
                   const Json& translation,
                   double mass_kg,
                   int material = -1) {
  const int n = b.addNode({{"name", name},
                           {"mesh", box.mesh},
                           {"translation", translation},
                           {"extensions", physics({{"motion", {{"mass", quantize(mass_kg)}}}})}});
  shapeCollider(b, n, box.shape, material);
  b.addRoot(n);
}

/// The physics material of every collider of a scene whose plan has no friction (gears,
/// peg_in_hole, stress, decomposed): static and dynamic friction 0 and no restitution, so that
/// a collider without one does not take the default friction (docs/demo-scenes.md).
int addFrictionless(GltfBuilder& b) {
  return b.addPhysicsMaterial({{"name", "frictionless"},
                               {"staticFriction", 0.0},
                               {"dynamicFriction", 0.0},
                               {"restitution", 0.0}});
}

/// The static floor "Floor": a box of `size` (20 mm thick) whose top is at y = 0, with a box
/// collider of physics material `material` (-1: none).
void addFloor(GltfBuilder& b, const Vec3& size, int colour, int material = -1) {
  const Box floor = addBox(b, "Floor", size, colour);
  const int node = b.addNode(
      {{"name", "Floor"}, {"mesh", floor.mesh}, {"translation", jsonVec({0.0, -0.01, 0.0})}});
  shapeCollider(b, node, floor.shape, material);
  b.addRoot(node);
}

/// The lowest y of a mesh's positions, or 0 when none is below 0.
double lowestY(const MeshData& mesh) {
  double min_y = 0.0;
  for (const Vec3& p : mesh.positions)
    min_y = std::min(min_y, p.y);
  return min_y;
}

std::string numbered(const char* prefix, int i) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s%d", prefix, i);
  return buf;
}

/// Two meshing spur gears on hinge joints to the scene, and a held rod to push their teeth.
std::vector<std::uint8_t> makeGears() {
  using namespace gears;
  GltfBuilder b;
  const int none = addFrictionless(b);
  const SpurGear g = gear();
  const double pitch = 2.0 * kPi / g.teeth;
  const int steel = b.addRenderMaterial("steel", {0.72, 0.73, 0.76, 1.0}, 0.9, 0.35);
  const int brass = b.addRenderMaterial("brass", {0.80, 0.62, 0.25, 1.0}, 0.9, 0.3);
  const int grip = b.addRenderMaterial("handle", {0.15, 0.35, 0.85, 1.0}, 0.0, 0.6);

  // hinge about the attachment frame's Z: position locked, rotation about X and Y locked
  const int hinge = b.addPhysicsJoint(
      {{"name", "hinge_z"},
       {"limits", Json::array({{{"linearAxes", {0, 1, 2}}, {"min", 0.0}, {"max", 0.0}},
                               {{"angularAxes", {0, 1}}, {"min", 0.0}, {"max", 0.0}}})}});

  const double r = g.pitchRadius();
  const double w = g.face_width_m;
  const Vec3 inertia{kMass_kg * (3.0 * r * r + w * w) / 12.0,
                     kMass_kg * (3.0 * r * r + w * w) / 12.0, 0.5 * kMass_kg * r * r};
  for (int which = 0; which < 2; ++which) {
    const std::string name = which == 0 ? "GearA" : "GearB";
    const Vec3 centre{(which == 0 ? -0.5 : 0.5) * kCentreDistance_m, 0.0, 0.0};
    // gear A has a tooth pointing at B (+X); B has a gap pointing at A (-X)
    const double first_tooth = which == 0 ? 0.0 : kPi + 0.5 * pitch;
    const int render = which == 0 ? steel : brass;

    const int body =
        b.addNode({{"name", name},
                   {"translation", jsonVec(centre)},
                   {"extensions", physics({{"motion",
                                            {{"mass", quantize(kMass_kg)},
                                             {"centerOfMass", jsonVec(Vec3{0.0})},
                                             {"inertiaDiagonal", jsonVec(inertia)}}}})}});
    b.addRoot(body);

    const int hub_mesh = b.addMesh(name + "_hub", prismMesh(g.hubPolygon(first_tooth), w), render);
    const int hub = b.addNode({{"name", name + "_hub"}, {"mesh", hub_mesh}});
    meshCollider(b, hub, none);
    b.addChild(body, hub);
    for (int k = 0; k < g.teeth; ++k) {
      char suffix[32];
      std::snprintf(suffix, sizeof suffix, "_tooth%02d", k);
      const int mesh =
          b.addMesh(name + suffix, prismMesh(g.toothPolygon(first_tooth + k * pitch), w), render);
      const int tooth = b.addNode({{"name", name + suffix}, {"mesh", mesh}});
      meshCollider(b, tooth, none);
      b.addChild(body, tooth);
    }
    // the axle: a node of the scene frame (no motion) at the gear's centre; the hinge node is the
    // gear's own frame, so both attachment frames coincide at rest
    const int axle = b.addNode({{"name", name + "_axle"}, {"translation", jsonVec(centre)}});
    b.addRoot(axle);
    const int joint = b.addNode(
        {{"name", name + "_hinge"},
         {"extensions",
          physics({{"joint",
                    {{"connectedNode", axle}, {"joint", hinge}, {"enableCollision", false}}}})}});
    b.addChild(body, joint);
  }

  // the held handle: a rod of radius 3 mm along Z, kinematic (moved by the probe), starting
  // outside gear A's top gap where the pose stream begins
  std::vector<Vec2> rod;
  for (int i = 0; i < kRodSides; ++i) {
    const double a = 2.0 * kPi * i / kRodSides;
    rod.push_back({kRodRadius_m * std::cos(a), kRodRadius_m * std::sin(a)});
  }
  const int rod_mesh = b.addMesh("Handle", prismMesh(rod, kRodLength_m), grip);
  const double gap = 4.5 * pitch;
  const Vec3 start{-0.5 * kCentreDistance_m + 0.075 * std::cos(gap), 0.075 * std::sin(gap), 0.0};
  meshCollider(b, heldBody(b, "Handle", rod_mesh, jsonVec(start)), none);
  return b.finish("gears");
}

/// A 20 mm square peg held by the probe over a hole of four walls and a floor, 0.5 mm clearance.
std::vector<std::uint8_t> makePegInHole() {
  using namespace peg;
  GltfBuilder b;
  const int none = addFrictionless(b);
  const int wood = b.addRenderMaterial("peg", {0.85, 0.65, 0.40, 1.0}, 0.0, 0.7);
  const int grey = b.addRenderMaterial("block", {0.55, 0.57, 0.60, 1.0}, 0.2, 0.6);

  const int hole =
      b.addNode({{"name", "Hole"},
                 {"extras", {{"haptic", {{"stiffness", quantize(kHoleStiffness_n_per_m)}}}}}});
  b.addRoot(hole);
  auto part = [&](const std::string& name, const Vec3& size, const Vec3& centre) {
    const int mesh = b.addMesh(name, boxMesh(size), grey);
    const int n = b.addNode({{"name", name}, {"mesh", mesh}, {"translation", jsonVec(centre)}});
    meshCollider(b, n, none);
    b.addChild(hole, n);
  };
  part("Hole_floor", {kBaseSide_m, kBaseThickness_m, kBaseSide_m},
       {0.0, -0.5 * kBaseThickness_m, 0.0});
  // four walls in a pinwheel around the square opening of half-width a
  const double a = 0.5 * kPegSide_m + kClearance_m;
  const double t = kWallThickness_m;
  const double len = 2.0 * a + t;  // each wall covers one side and one corner
  const double y = 0.5 * kHoleDepth_m;
  part("Hole_wall_east", {t, kHoleDepth_m, len}, {a + 0.5 * t, y, 0.5 * t});
  part("Hole_wall_north", {len, kHoleDepth_m, t}, {-0.5 * t, y, a + 0.5 * t});
  part("Hole_wall_west", {t, kHoleDepth_m, len}, {-a - 0.5 * t, y, -0.5 * t});
  part("Hole_wall_south", {len, kHoleDepth_m, t}, {0.5 * t, y, -a - 0.5 * t});

  const int peg_mesh = b.addMesh("Peg", boxMesh({kPegSide_m, kPegLength_m, kPegSide_m}), wood);
  // starts with its end 40 mm above the wall tops, off to one side (the pose stream's first row)
  const Vec3 start{0.030, kHoleDepth_m + 0.5 * kPegLength_m + 0.040, 0.020};
  meshCollider(b, heldBody(b, "Peg", peg_mesh, jsonVec(start)), none);
  return b.finish("peg_in_hole");
}

/// Four cubes, four spheres and four ellipsoids (320 faces each) on a floor under gravity, and a
/// stick held by the probe (§6.2, "a dynamic scene of multiple moving objects").
std::vector<std::uint8_t> makeDynamic() {
  using namespace dynamic;
  GltfBuilder b;
  const int floor_colour = b.addRenderMaterial("floor", {0.35, 0.37, 0.40, 1.0}, 0.0, 0.9);
  const int red = b.addRenderMaterial("cube", {0.80, 0.20, 0.15, 1.0}, 0.0, 0.6);
  const int green = b.addRenderMaterial("sphere", {0.20, 0.70, 0.25, 1.0}, 0.0, 0.5);
  const int blue = b.addRenderMaterial("ellipsoid", {0.20, 0.35, 0.85, 1.0}, 0.0, 0.4);
  const int yellow = b.addRenderMaterial("stick", {0.90, 0.80, 0.20, 1.0}, 0.0, 0.6);

  const int floor_mat = b.addPhysicsMaterial(
      {{"name", "floor"}, {"staticFriction", 0.6}, {"dynamicFriction", 0.5}, {"restitution", 0.2}});
  const int wood = b.addPhysicsMaterial(
      {{"name", "wood"}, {"staticFriction", 0.5}, {"dynamicFriction", 0.4}, {"restitution", 0.3}});
  const int rubber = b.addPhysicsMaterial({{"name", "rubber"},
                                           {"staticFriction", 0.9},
                                           {"dynamicFriction", 0.8},
                                           {"restitution", 0.7}});
  const int plastic = b.addPhysicsMaterial({{"name", "plastic"},
                                            {"staticFriction", 0.4},
                                            {"dynamicFriction", 0.3},
                                            {"restitution", 0.5}});

  addFloor(b, {1.0, 0.02, 1.0}, floor_colour, floor_mat);  // 1 m x 1 m

  const Box cube = addBox(b, "Cube", {kCubeSide_m, kCubeSide_m, kCubeSide_m}, red);
  for (int i = 0; i < 4; ++i) {
    addDynamicBox(b, numbered("Cube", i), cube,
                  jsonVec({kRowX_m[i], 0.5 * kCubeSide_m + kDropGap_m, kCubeZ_m}), kCubeMass_kg,
                  wood);
  }

  // the spheres share one mesh and the ellipsoids another; each node's collider is the hull of
  // its own mesh
  const MeshData sphere = icosphereMesh(Vec3{kSphereRadius_m}, 2);
  const double sphere_inertia = 0.4 * kSphereMass_kg * kSphereRadius_m * kSphereRadius_m;
  const int sphere_mesh = b.addMesh("Sphere", sphere, green);
  const double sphere_min_y = lowestY(sphere);
  for (int i = 0; i < 4; ++i) {
    const int n = b.addNode(
        {{"name", numbered("Sphere", i)},
         {"mesh", sphere_mesh},
         {"translation", jsonVec({kRowX_m[i], -sphere_min_y + kDropGap_m, kSphereZ_m})},
         {"extensions", physics({{"motion",
                                  {{"mass", quantize(kSphereMass_kg)},
                                   {"inertiaDiagonal", jsonVec(Vec3{sphere_inertia})}}}})}});
    meshCollider(b, n, rubber);
    b.addRoot(n);
  }

  const MeshData ellipsoid =
      icosphereMesh({kEllipsoidRadii_m[0], kEllipsoidRadii_m[1], kEllipsoidRadii_m[2]}, 2);
  const int ellipsoid_mesh = b.addMesh("Ellipsoid", ellipsoid, blue);
  const double ellipsoid_min_y = lowestY(ellipsoid);
  for (int i = 0; i < 4; ++i) {
    // turned about Y by 0, 30, 60, 90 degrees; mass and inertia left to the loader
    const int n = b.addNode(
        {{"name", numbered("Ellipsoid", i)},
         {"mesh", ellipsoid_mesh},
         {"translation", jsonVec({kRowX_m[i], -ellipsoid_min_y + kDropGap_m, kEllipsoidZ_m})},
         {"rotation", jsonQuatAxisAngle({0.0, 1.0, 0.0}, i * kPi / 6.0)},
         {"extensions", physics({{"motion", Json::object()}})}});
    meshCollider(b, n, plastic);
    b.addRoot(n);
  }

  const Vec3 stick_size{kStickSize_m[0], kStickSize_m[1], kStickSize_m[2]};
  const int stick_mesh = b.addMesh("Stick", boxMesh(stick_size), yellow);
  meshCollider(b, heldBody(b, "Stick", stick_mesh, jsonVec({0.0, 0.20, 0.25})), wood);

  b.setSceneExtras({{"haptic", {{"gravity", Json::array({0.0, -9.81, 0.0})}}}});
  return b.finish("dynamic");
}

/// A field of 32 x 32 static pillars with 16 dynamic blocks on their tops, a floor and a held
/// sphere: over a thousand primitives for the broad phase.
std::vector<std::uint8_t> makeStress() {
  using namespace stress;
  GltfBuilder b;
  const int none = addFrictionless(b);
  const int grey = b.addRenderMaterial("pillar", {0.60, 0.60, 0.62, 1.0}, 0.1, 0.7);
  const int floor_colour = b.addRenderMaterial("floor", {0.30, 0.32, 0.35, 1.0}, 0.0, 0.9);
  const int orange = b.addRenderMaterial("block", {0.95, 0.55, 0.15, 1.0}, 0.0, 0.6);
  const int white = b.addRenderMaterial("sweeper", {0.95, 0.95, 0.95, 1.0}, 0.0, 0.3);

  addFloor(b, {1.2, 0.02, 1.2}, floor_colour, none);

  const Box pillar =
      addBox(b, "Pillar", {kPillarSize_m[0], kPillarSize_m[1], kPillarSize_m[2]}, grey);
  const int field = b.addNode({{"name", "Field"}});
  b.addRoot(field);
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      char name[32];
      std::snprintf(name, sizeof name, "Pillar_%02d_%02d", i, j);
      const int n = b.addNode({{"name", name},
                               {"mesh", pillar.mesh},
                               {"translation", jsonVec({pillarCoordinate(i), 0.5 * kPillarSize_m[1],
                                                        pillarCoordinate(j)})}});
      shapeCollider(b, n, pillar.shape, none);
      b.addChild(field, n);
    }
  }

  const Box block = addBox(b, "Block", {kBlockSide_m, kBlockSide_m, kBlockSide_m}, orange);
  for (int i = 0; i < kBlocksPerSide; ++i) {
    for (int j = 0; j < kBlocksPerSide; ++j) {
      addDynamicBox(b, numbered("Block", i * kBlocksPerSide + j), block,
                    jsonVec({blockCoordinate(i), kPillarSize_m[1] + 0.5 * kBlockSide_m + 0.001,
                             blockCoordinate(j)}),
                    kBlockMass_kg, none);
    }
  }

  const int sweeper_shape =
      b.addShape({{"type", "sphere"}, {"sphere", {{"radius", quantize(kSweeperRadius_m)}}}});
  const int sweeper_mesh = b.addMesh("Sweeper", icosphereMesh(Vec3{kSweeperRadius_m}, 2), white);
  // at the stream's first row
  const int sweeper =
      heldBody(b, "Sweeper", sweeper_mesh, jsonVec({-0.52, 0.1, pillarCoordinate(4)}));
  shapeCollider(b, sweeper, sweeper_shape, none);

  b.setSceneExtras({{"haptic", {{"gravity", Json::array({0.0, -9.81, 0.0})}}}});
  return b.finish("stress");
}

/// The pieces of the closed mesh `mesh`, by the product's decomposition; throws if it fails.
std::vector<MeshData> decomposeCell(const MeshData& mesh) {
  decomp::TriangleMesh in;
  in.positions = mesh.positions;
  in.triangles = mesh.triangles;
  decomp::DecompOptions options;
  options.threads = 1;
  auto result = decomp::decompose(in, options);
  if (!result.ok())
    throw std::runtime_error("scene generator: decomposition failed: " + result.error().message);
  std::vector<MeshData> pieces;
  for (const decomp::ConvexPiece& p : result.value().pieces)
    pieces.push_back({p.vertices, p.triangles});
  return pieces;
}

/// A static plate of grooves along Z and a held plate of pins over it, both non-convex meshes
/// built cell by cell and decomposed into convex pieces, one collider node per piece.
std::vector<std::uint8_t> makeDecomposed() {
  using namespace decomposed;
  GltfBuilder b;
  const int none = addFrictionless(b);
  const int grey = b.addRenderMaterial("grooved", {0.55, 0.57, 0.60, 1.0}, 0.3, 0.6);
  const int copper = b.addRenderMaterial("pins", {0.78, 0.45, 0.28, 1.0}, 0.8, 0.4);

  // each plate's cell decomposed once; its pieces' meshes shared by every cell's nodes
  auto addPieces = [&](const std::string& name, const MeshData& cell, int colour) {
    std::vector<int> meshes;
    const std::vector<MeshData> pieces = decomposeCell(cell);
    for (std::size_t k = 0; k < pieces.size(); ++k)
      meshes.push_back(
          b.addMesh(numbered((name + "_piece").c_str(), static_cast<int>(k)), pieces[k], colour));
    return meshes;
  };
  const std::vector<int> ridge_pieces = addPieces(
      "Ridge", ridgeCellMesh(kCell_m, kRidgeWidth_m, kGrooveDepth_m, kBaseThickness_m), grey);
  const std::vector<int> pin_pieces =
      addPieces("Pin", pinCellMesh(kCell_m, kTileThickness_m, kPinSide_m, kPinLength_m), copper);

  const int grooved = b.addNode({{"name", "GroovedPlate"}});
  b.addRoot(grooved);
  for (int i = 0; i < kGrooveCells; ++i) {
    for (int j = 0; j < kGrooveCells; ++j) {
      for (std::size_t k = 0; k < ridge_pieces.size(); ++k) {
        char name[48];
        std::snprintf(name, sizeof name, "Ridge_%02d_%02d_%zu", i, j, k);
        const int n = b.addNode(
            {{"name", name},
             {"mesh", ridge_pieces[k]},
             {"translation", jsonVec({grooveCellCoordinate(i), 0.0, grooveCellCoordinate(j)})}});
        meshCollider(b, n, none);
        b.addChild(grooved, n);
      }
    }
  }

  // the held plate, at the stream's first row
  const int held = b.addNode({{"name", "PinPlate"},
                              {"translation", jsonVec({kRunX_m, kStartY_m, kRunZ_m[0]})},
                              {"rotation", jsonQuatAxisAngle({0.0, 0.0, 1.0}, kTilt_rad)},
                              {"extensions", physics({{"motion", {{"isKinematic", true}}}})},
                              {"extras", {{"haptic", {{"probe", true}}}}}});
  b.addRoot(held);
  for (int i = 0; i < kPinCellsX; ++i) {
    for (int j = 0; j < kPinCellsZ; ++j) {
      for (std::size_t k = 0; k < pin_pieces.size(); ++k) {
        char name[48];
        std::snprintf(name, sizeof name, "Pin_%02d_%02d_%zu", i, j, k);
        const int n = b.addNode(
            {{"name", name},
             {"mesh", pin_pieces[k]},
             {"translation", jsonVec({i * kCell_m, 0.0, (j - 0.5 * (kPinCellsZ - 1)) * kCell_m})}});
        meshCollider(b, n, none);
        b.addChild(held, n);
      }
    }
  }
  return b.finish("decomposed");
}

}  // namespace

namespace gears {
SpurGear gear() {
  SpurGear g;
  g.teeth = 19;
  g.module_m = 0.005;
  g.backlash_m = 0.001;
  g.face_width_m = 0.015;
  g.flank_samples = 3;
  g.root_inset_m = 0.001;
  return g;
}
}  // namespace gears

namespace {

/// The demo scenes in demoSceneNames() order.
struct DemoScene {
  std::string_view name;
  std::vector<std::uint8_t> (*make)();
};
constexpr DemoScene kDemoScenes[] = {{"gears", &makeGears},
                                     {"peg_in_hole", &makePegInHole},
                                     {"dynamic", &makeDynamic},
                                     {"stress", &makeStress},
                                     {"decomposed", &makeDecomposed}};

}  // namespace

std::vector<std::uint8_t> makeBoxField(int boxes) {
  GltfBuilder b;
  const int grey = b.addRenderMaterial("floor", {0.30, 0.32, 0.35, 1.0}, 0.0, 0.9);
  const int orange = b.addRenderMaterial("box", {0.95, 0.55, 0.15, 1.0}, 0.0, 0.6);
  const int n = std::max(boxes, 0);
  int side = 1;
  while (side * side < n)
    ++side;
  const double floor_side = side * kBoxFieldPitch_m + 0.1;
  addFloor(b, {floor_side, 0.02, floor_side}, grey);
  const Box box = addBox(b, "Box", Vec3{kBoxFieldSide_m}, orange);
  for (int i = 0; i < n; ++i) {
    const int row = i / side, column = i % side;
    const double x = (column - 0.5 * (side - 1)) * kBoxFieldPitch_m;
    const double z = (row - 0.5 * (side - 1)) * kBoxFieldPitch_m;
    addDynamicBox(b, numbered("Box", i), box, jsonVec({x, 0.5 * kBoxFieldSide_m, z}), 0.010);
  }
  b.setSceneExtras({{"haptic", {{"gravity", Json::array({0.0, -9.81, 0.0})}}}});
  return b.finish("box_field");
}

std::vector<std::string_view> demoSceneNames() {
  std::vector<std::string_view> names;
  for (const DemoScene& d : kDemoScenes)
    names.push_back(d.name);
  return names;
}

int demoSceneIndex(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kDemoScenes); ++i) {
    if (kDemoScenes[i].name == name)
      return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::uint8_t> makeDemoScene(std::string_view name) {
  const int i = demoSceneIndex(name);
  return i < 0 ? std::vector<std::uint8_t>{} : kDemoScenes[static_cast<std::size_t>(i)].make();
}

}  // namespace hapticd::scenes
