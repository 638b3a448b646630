#pragma once
/// \file
/// The corpus of glTF as exporters write it (part of tests/scenes/{bad,good}, made by
/// scene_corpus_gen): each extension the loader reads or ignores, quantized, sparse, Draco and
/// meshopt geometry, buffers beside the file, plain models, Godot's OMI physics, triggers, every
/// joint kind, collision filter cases, Blender-like files; each file good (with a line that
/// `hapticctl check` prints) or bad (with its message). Header-only, test code.

#include <string>
#include <vector>

#include "tests/core/scene/encoded_mesh.h"

namespace hapticd::scene::testing {

/// One file of the corpus. Bad files: `expect` is a substring of the error; good files: a
/// substring of what `hapticctl check` prints. `scene` false: a data file beside a scene.
struct CorpusFile {
  std::string name;
  std::vector<std::uint8_t> bytes;
  std::string expect;
  bool allow_folder = false;  ///< bad files: load with allowed_uri_dir = the corpus folder
  bool scene = true;
};

/// A node whose collider is its own mesh `mesh` (a convex hull of it when `hull`).
inline json meshColliderNode(GltfBuilder& b,
                             const std::string& name,
                             int mesh,
                             bool hull = false,
                             Vec3 t = Vec3{0.0}) {
  json n = GltfBuilder::node(name, t);
  n["mesh"] = mesh;
  GltfBuilder::physics(n)["collider"] = {
      {"geometry", {{"node", b.doc["nodes"].size()}, {"convexHull", hull}}}};
  b.useExtension("KHR_physics_rigid_bodies", false);
  return n;
}

/// A scene whose only collider is a static node with mesh `mesh`.
inline GltfBuilder withMesh(GltfBuilder b, int mesh, bool hull = false) {
  b.addNode(meshColliderNode(b, "Part", mesh, hull));
  return b;
}

/// What Godot 4 writes in OMI_physics_shape: box, sphere, capsule and cylinder with `radius` and
/// the whole `height`, convex and trimesh shapes of a mesh (a 0.1 m cube, a 1 m dented cube).
inline json godotShapes(GltfBuilder& b) {
  const int cube = b.addMesh(cubeMesh(0.1), "CubeMesh");
  const int dented = b.addMesh(dentedCubeMesh(0.5), "DentedMesh");
  return json::array({{{"type", "box"}, {"box", {{"size", {1.0, 0.2, 1.0}}}}},
                      {{"type", "sphere"}, {"sphere", {{"radius", 0.1}}}},
                      {{"type", "capsule"}, {"capsule", {{"radius", 0.1}, {"height", 0.6}}}},
                      {{"type", "cylinder"}, {"cylinder", {{"radius", 0.1}, {"height", 0.3}}}},
                      {{"type", "convex"}, {"convex", {{"mesh", cube}}}},
                      {{"type", "trimesh"}, {"trimesh", {{"mesh", dented}}}}});
}

/// Geometry files: each geometry extension good, and broken.
inline void geometryCorpus(std::vector<CorpusFile>& good, std::vector<CorpusFile>& bad) {
  {
    GltfBuilder b;
    int i = 0;
    for (const std::uint32_t component : {5120u, 5121u, 5122u, 5123u}) {
      for (const bool normalized : {true, false}) {
        const double unit = normalized ? 1.0 : (component <= 5121 ? 100.0 : 10000.0);
        Mesh cube = cubeMesh(0.4 * unit);
        if (component == 5121 || component == 5123) {
          for (Vec3& v : cube.vertices)
            v += Vec3{0.5 * unit};  // unsigned: [0.1, 0.9] of the unit
        }
        const int mesh =
            addQuantizedMesh(b, cube, component, normalized, "Q" + std::to_string(component));
        json n = meshColliderNode(b, "Q" + std::to_string(i), mesh, false, {1.0 * i, 0.0, 0.0});
        ++i;
        n["scale"] = {0.1 / unit, 0.1 / unit, 0.1 / unit};
        b.addNode(n);
      }
    }
    good.push_back({"quantized.glb", b.glb(), "scene quantized.glb: 8 bodies"});
    GltfBuilder u = b;
    u.doc["accessors"][0]["componentType"] = 5125;
    u.doc["accessors"][0]["byteOffset"] = 0;
    u.doc["bufferViews"][0]["byteStride"] = 12;
    u.doc["bufferViews"][0]["byteLength"] = 96;
    bad.push_back({"quantized_uint.glb", u.glb(),
                   "must be VEC3 of FLOAT, or (KHR_mesh_quantization) of BYTE, UNSIGNED_BYTE, "
                   "SHORT or UNSIGNED_SHORT, normalized or not; got VEC3 of 5125"});
    GltfBuilder past = b;
    past.doc["accessors"][2]["count"] = 9;
    bad.push_back({"quantized_past_view.glb", past.glb(),
                   "accessor 2: byteOffset 0 + count 9 x stride 4 = 35 runs past the end of "
                   "bufferView 2 (32 bytes)"});
  }
  {
    GltfBuilder b;
    Mesh cube = cubeMesh(0.05);
    const int pa =
        addSparsePositions(b, cube.vertices, true, {6, 7}, {Vec3{0.05, 0.1, 0.05}, Vec3{0.1}});
    const int iv = b.addView(cube.triangles.data(), cube.triangles.size() * 4);
    const int ia = b.addAccessor(
        {{"bufferView", iv}, {"componentType", 5125}, {"count", 36}, {"type", "SCALAR"}});
    b.doc["meshes"].push_back(
        {{"name", "Sparse"},
         {"primitives", json::array({{{"attributes", {{"POSITION", pa}}}, {"indices", ia}}})}});
    good.push_back({"sparse.gltf", bytesOf(withMesh(b, 0, true).gltf()), "mesh hull (node 0)"});
    // the second sparse index changed
    const auto second = [&](std::uint16_t index) {
      GltfBuilder m = withMesh(b, 0, true);
      std::memcpy(m.bin.data() + m.doc["bufferViews"][1]["byteOffset"].get<std::size_t>() + 2,
                  &index, 2);
      return bytesOf(m.gltf());
    };
    bad.push_back({"sparse_index_past_base.gltf", second(9),
                   "sparse index 9 (entry 1) runs past the base (8 elements)"});
    bad.push_back({"sparse_indices_decreasing.gltf", second(5),
                   "sparse index 5 (entry 1) is not above the previous one"});
  }
  {
    GltfBuilder b;
    // the mesh is added before withMesh copies the builder (argument order is unspecified)
    const int dented = addDracoMesh(b, dentedCubeMesh(0.05), "Dented");
    const GltfBuilder d = withMesh(b, dented);
    good.push_back({"draco.glb", d.glb(), "mesh piece (non-convex mesh) (node 0)"});
    GltfBuilder broken = d;
    for (std::size_t i = 8; i < broken.bin.size(); ++i)
      broken.bin[i] = static_cast<std::uint8_t>(i * 37);
    bad.push_back({"draco_malformed.glb", broken.glb(), "KHR_draco_mesh_compression: Draco:"});
    GltfBuilder count = d;
    count.doc["accessors"][0]["count"] = 99;
    bad.push_back({"draco_wrong_count.glb", count.glb(), "the POSITION accessor says 99 VEC3"});
  }
  {
    GltfBuilder b;
    const int cube = addMeshoptMesh(b, cubeMesh(0.05), "Cube", "EXPONENTIAL");
    const GltfBuilder m = withMesh(b, cube);
    good.push_back({"meshopt.glb", m.glb(), "convex mesh (node 0)"});
    GltfBuilder seq;
    const int seq_cube = addMeshoptMesh(seq, cubeMesh(0.05), "Cube", "NONE", "INDICES");
    good.push_back({"meshopt_indices.glb", withMesh(seq, seq_cube).glb(), "convex mesh (node 0)"});
    GltfBuilder broken = m;
    broken.bin[0] ^= 0xFF;
    bad.push_back({"meshopt_malformed.glb", broken.glb(),
                   "bufferView 0 meshopt: meshopt: the attribute codec refused the stream"});
    GltfBuilder stride = m;
    stride.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION";
    bad.push_back({"meshopt_bad_filter.glb", stride.glb(), "QUATERNION needs a byteStride of 8"});
    GltfBuilder plain = m;
    plain.doc["bufferViews"][0].erase("extensions");
    bad.push_back({"meshopt_fallback_read.glb", plain.glb(),
                   "bufferView 0: buffer 1 holds no data (a meshopt fallback) and this view is "
                   "not compressed"});
  }
}

/// Extension lists, buffers beside the file, plain models.
inline void documentCorpus(std::vector<CorpusFile>& good,
                           std::vector<CorpusFile>& bad,
                           const GltfBuilder& base) {
  {
    GltfBuilder b = base;
    for (const char* e :
         {"KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_texture_transform"})
      b.useExtension(e, true);
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}}});
    good.push_back({"appearance_required.gltf", bytesOf(b.gltf()),
                    "ignored (appearance only): KHR_lights_punctual, "
                    "KHR_materials_emissive_strength, KHR_texture_transform"});
    b.useExtension("EXT_mesh_gpu_instancing", true);
    bad.push_back({"unknown_required_extension.gltf", bytesOf(b.gltf()),
                   "extensionsRequired: unsupported required extension 'EXT_mesh_gpu_instancing'"});
  }
  {
    json d = base.doc;
    d["buffers"] = json::array({json{{"byteLength", base.bin.size()}, {"uri", "beside.bin"}}});
    good.push_back({"beside.gltf", bytesOf(d.dump()), "convex mesh (node 1)"});
    good.push_back({"beside.bin", base.bin, "", false, false});
  }
  {
    GltfBuilder b;
    const int group = b.addNode(GltfBuilder::node("Model"));
    const int cube = b.addMesh(cubeMesh(0.05), "Cube");
    Mesh quad;
    quad.vertices = {{-0.5, 0, -0.5}, {0.5, 0, -0.5}, {0.5, 0, 0.5}, {-0.5, 0, 0.5}};
    quad.triangles = {0, 2, 1, 0, 3, 2};
    const int floor = b.addMesh(quad, "Ground");
    const int dented = b.addMesh(dentedCubeMesh(0.05), "Bowl");
    int k = 0;
    for (const int mesh : {floor, cube, cube, dented}) {
      json n = GltfBuilder::node("Part" + std::to_string(k),
                                 {0.15 * k, mesh == floor ? 0.0 : 0.05, 0.0});
      ++k;
      n["mesh"] = mesh;
      b.addNode(n, group);
    }
    good.push_back({"plain_model.glb", b.glb(),
                    "no physics extension: 4 meshes as static geometry\n"
                    "mesh 1 'Ground' primitive 0 (node 1 'Part0'): flat, given a thickness\n"
                    "mesh 2 'Bowl' primitive 0 (node 4 'Part3'): not convex, touched through\n"
                    "convex pieces (convex decomposition, concavity\n"
                    "1 moving primitives (one the probe sphere of the config)"});
    GltfBuilder none;
    none.useExtension("KHR_physics_rigid_bodies", false);
    none.addNode(GltfBuilder::node("Empty"));
    good.push_back({"nothing_to_touch.gltf", bytesOf(none.gltf()), "warning: nothing to touch"});
  }
}

/// Godot's OMI physics (new and older forms), KHR triggers, every joint kind, filter cases, a
/// Blender-like file.
inline void physicsCorpus(std::vector<CorpusFile>& good, std::vector<CorpusFile>& bad) {
  {
    GltfBuilder b;
    b.doc["extensions"]["OMI_physics_shape"]["shapes"] = godotShapes(b);
    b.useExtension("OMI_physics_body", false);
    b.useExtension("OMI_physics_shape", false);
    const json types[] = {{{"type", "static"}},  {{"type", "dynamic"}, {"mass", 2.0}},
                          {{"type", "dynamic"}}, {{"type", "kinematic"}},
                          {{"type", "dynamic"}}, {{"type", "static"}}};
    for (int i = 0; i < 6; ++i) {
      json n = GltfBuilder::node("Body" + std::to_string(i), {0.3 * i, i == 0 ? -0.05 : 0.3, 0.0});
      n["extensions"]["OMI_physics_body"] = {{"motion", types[i]}};
      const int body = b.addNode(n);
      json c = GltfBuilder::node("Shape" + std::to_string(i));
      c["extensions"]["OMI_physics_body"] = {{"collider", {{"shape", i}}}};
      b.addNode(c, body);
    }
    json area = GltfBuilder::node("Goal", {0.0, 0.5, 1.0});
    area["extensions"]["OMI_physics_body"] = {{"trigger", json::object()}};
    const int goal = b.addNode(area);
    json zone = GltfBuilder::node("GoalZone");
    zone["extensions"]["OMI_physics_body"] = {{"trigger", {{"shape", 1}}}};
    b.addNode(zone, goal);
    good.push_back({"godot_omi.gltf", bytesOf(b.gltf()),
                    "'Body1' dynamic, mass 2 kg (declared)\n"
                    "'Body3' kinematic\n"
                    "mesh piece (non-convex mesh) (node 11)\n"
                    "1 trigger volumes, not colliding (bodies 'Goal')"});
    GltfBuilder bad_type = b;
    bad_type.doc["nodes"][2]["extensions"]["OMI_physics_body"]["motion"]["type"] = "floaty";
    bad.push_back({"omi_bad_motion_type.gltf", bytesOf(bad_type.gltf()),
                   "node 2 'Body1' OMI_physics_body motion: type 'floaty' is not one of"});
    GltfBuilder bad_shape = b;
    bad_shape.doc["nodes"][3]["extensions"]["OMI_physics_body"]["collider"]["shape"] = 9;
    bad.push_back({"omi_shape_out_of_range.gltf", bytesOf(bad_shape.gltf()),
                   "shape index 9 out of range (6 OMI_physics_shape shapes)"});
  }
  {
    GltfBuilder b;
    b.doc["extensions"]["OMI_collider"]["colliders"] =
        json::array({{{"type", "box"}, {"size", {0.1, 0.1, 0.1}}},
                     {{"type", "sphere"}, {"radius", 0.2}, {"isTrigger", true}},
                     {{"type", "capsule"}, {"radius", 0.05}, {"height", 0.3}}});
    b.useExtension("OMI_collider", false);
    b.useExtension("OMI_physics_body", false);
    json crate = GltfBuilder::node("Crate", {0.0, 0.5, 0.0});
    crate["extensions"]["OMI_physics_body"] = {{"type", "rigid"}, {"mass", 3.0}};
    const int c = b.addNode(crate);
    for (int i : {0, 2}) {
      json s = GltfBuilder::node("CrateShape" + std::to_string(i), {0.0, 0.1 * i, 0.0});
      s["extensions"]["OMI_collider"] = {{"collider", i}};
      b.addNode(s, c);
    }
    json sensor = GltfBuilder::node("Sensor", {1.0, 0.0, 0.0});
    sensor["extensions"]["OMI_collider"] = {{"collider", 1}};
    b.addNode(sensor);
    good.push_back({"omi_collider_older.gltf", bytesOf(b.gltf()),
                    "'Crate' dynamic, mass 3 kg (declared), 2 primitives\n"
                    "sphere (node 3), 2522 vertices\n"
                    "trigger (not colliding)"});
    b.doc["extensions"]["OMI_collider"]["colliders"][2]["height"] = 0.05;
    bad.push_back({"omi_capsule_too_short.gltf", bytesOf(b.gltf()),
                   "OMI_collider collider 2 capsule: height 0.05 is less than the two caps"});
  }
}

/// Two dynamic boxes on a static floor, the second joined to the first by `joint`.
inline GltfBuilder jointScene(const json& joint) {
  GltfBuilder b;
  const int box = b.box({0.1, 0.1, 0.1});
  json floor = GltfBuilder::node("Floor", {0.0, -0.05, 0.0});
  GltfBuilder::physics(floor)["collider"] = GltfBuilder::shapeCollider(b.box({2.0, 0.1, 2.0}));
  b.addNode(floor);
  const int j = b.addPhysics("physicsJoints", joint);
  for (int i = 0; i < 2; ++i) {
    json n = GltfBuilder::node(i == 0 ? "Frame" : "Part", {0.0, 0.3 + 0.2 * i, 0.0});
    GltfBuilder::physics(n)["motion"] = json::object();
    GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(box);
    if (i == 1)
      GltfBuilder::physics(n)["joint"] = {{"connectedNode", 1}, {"joint", j}};
    b.addNode(n);
  }
  b.useExtension("KHR_physics_rigid_bodies", true);
  b.useExtension("KHR_implicit_shapes", true);
  return b;
}

/// Every joint kind, drives, KHR triggers, collision filter cases, a Blender-like file.
inline void jointCorpus(std::vector<CorpusFile>& good, std::vector<CorpusFile>& bad) {
  const json lin = {{"linearAxes", {0, 1, 2}}, {"max", 0.0}};
  const json ang = {{"angularAxes", {0, 1, 2}}, {"max", 0.0}};
  const json drive = {{"type", "linear"},       {"mode", "force"},    {"axis", 0},
                      {"positionTarget", 0.05}, {"stiffness", 200.0}, {"damping", 2.0},
                      {"maxForce", 10.0}};
  const std::pair<const char*, json> kinds[] = {
      {"fixed", {{"limits", {lin, ang}}}},
      {"hinge",
       {{"limits",
         {lin,
          {{"angularAxes", {0, 2}}, {"max", 0.0}},
          {{"angularAxes", {1}}, {"min", -1.0}, {"max", 1.0}}}}}},
      {"slider",
       {{"limits",
         {{{"linearAxes", {1, 2}}, {"max", 0.0}},
          {{"linearAxes", {0}}, {"min", 0.0}, {"max", 0.1}},
          ang}},
        {"drives", {drive}}}},
      {"ball", {{"limits", {lin}}}},
      {"cone", {{"limits", {lin, {{"angularAxes", {1, 2}}, {"max", 0.4}}}}}},
      {"one_sided", {{"limits", {{{"linearAxes", {1}}, {"min", -0.2}}, ang}}}},
      {"soft",
       {{"limits",
         {{{"linearAxes", {0, 1, 2}}, {"max", 0.0}, {"stiffness", 500.0}, {"damping", 5.0}},
          ang}}}},
      {"hinge_drive",
       {{"limits", {lin, {{"angularAxes", {0, 1}}, {"max", 0.0}}}},
        {"drives",
         {{{"type", "angular"},
           {"mode", "acceleration"},
           {"axis", 2},
           {"velocityTarget", 3.0},
           {"damping", 1.0}}}}}}};
  const char* answers[] = {"fixed between body 1 and body 0",
                           "hinge between body 1 and body 0",
                           "slider between body 1 and body 0, 1 drives",
                           "ball between body 1 and body 0",
                           "ball between body 1 and body 0",
                           "generic between body 1 and body 0",
                           "generic between body 1 and body 0",
                           "hinge between body 1 and body 0, 1 drives"};
  for (std::size_t i = 0; i < std::size(kinds); ++i)
    good.push_back({std::string("joint_") + kinds[i].first + ".gltf",
                    bytesOf(jointScene(kinds[i].second).gltf()), answers[i]});
  json bad_drive = kinds[2].second;
  bad_drive["drives"][0]["axis"] = 3;
  bad.push_back({"joint_drive_bad_axis.gltf", bytesOf(jointScene(bad_drive).gltf()),
                 "physicsJoint 0 drive 0: axis index 3 out of range (3 axes)"});
  bad_drive = kinds[2].second;
  bad_drive["drives"][0]["mode"] = "torque";
  bad.push_back({"joint_drive_bad_mode.gltf", bytesOf(jointScene(bad_drive).gltf()),
                 "mode 'torque' is not one of 'force', 'acceleration'"});
  {
    // a trigger on a moving body and a static one; a compound trigger naming its parts
    GltfBuilder b = jointScene(kinds[0].second);
    json zone = GltfBuilder::node("Zone", {1.0, 0.0, 0.0});
    GltfBuilder::physics(zone)["trigger"] = {{"geometry", {{"shape", b.box({0.5, 0.5, 0.5})}}}};
    const int z = b.addNode(zone);
    json compound = GltfBuilder::node("Compound");
    GltfBuilder::physics(compound)["trigger"] = {{"nodes", {z}}};
    b.addNode(compound);
    json sensor = GltfBuilder::node("Sensor", {0.0, 0.1, 0.0});
    GltfBuilder::physics(sensor)["trigger"] = {{"geometry", {{"shape", 0}}}};
    b.addNode(sensor, 2);
    good.push_back({"khr_triggers.gltf", bytesOf(b.gltf()),
                    "2 trigger volumes, not colliding (bodies 'Part', 'Zone')"});
    GltfBuilder empty = b;
    GltfBuilder::physics(empty.doc["nodes"][static_cast<std::size_t>(z)])["trigger"] =
        json::object();
    bad.push_back({"khr_trigger_empty.gltf", bytesOf(empty.gltf()),
                   "node 3 'Zone' trigger: give geometry (or shape), or the nodes of a compound "
                   "trigger"});
  }
  {
    // filter cases: subset, exclusion, both directions; the check lines name the classes
    GltfBuilder b = jointScene(kinds[0].second);
    const int f_char = b.addPhysics("collisionFilters", {{"collisionSystems", {"character"}},
                                                         {"collideWithSystems", {"landscape"}}});
    const int f_land = b.addPhysics("collisionFilters", {{"collisionSystems", {"landscape"}},
                                                         {"notCollideWithSystems", {"debris"}}});
    const int f_mixed =
        b.addPhysics("collisionFilters", {{"collisionSystems", {"landscape", "debris"}}});
    GltfBuilder::physics(b.doc["nodes"][0])["collider"]["collisionFilter"] = f_land;
    GltfBuilder::physics(b.doc["nodes"][1])["collider"]["collisionFilter"] = f_char;
    GltfBuilder::physics(b.doc["nodes"][2])["collider"]["collisionFilter"] = f_mixed;
    good.push_back({"filters.gltf", bytesOf(b.gltf()),
                    "collision filters keep apart:\n  'Frame' and 'Part'\n  'Part' and 'Floor'"});
    json many = json::array();
    for (int i = 0; i < 40; ++i) {
      const std::string sys = "s" + std::to_string(i);
      many.push_back({{"collisionSystems", {sys}}, {"collideWithSystems", {sys}}});
    }
    b.doc["extensions"]["KHR_physics_rigid_bodies"]["collisionFilters"] = many;
    bad.push_back({"too_many_filter_behaviours.gltf", bytesOf(b.gltf()),
                   "41 different collision behaviours, more than 32"});
  }
  {
    // as Blender's physics add-on writes a scene: a light required, drives, a mesh collider
    GltfBuilder b = jointScene(kinds[7].second);
    b.useExtension("KHR_lights_punctual", true);
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "sun"}, {"intensity", 3.0}}});
    b.doc["nodes"].push_back(
        {{"name", "Sun"}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    b.doc["scenes"][0]["nodes"].push_back(3);
    const std::vector<std::uint8_t> glb = b.glb();
    good.push_back({"blender_like.glb", glb,
                    "ignored (appearance only): KHR_lights_punctual\n"
                    "hinge between body 1 and body 0, 1 drives"});
  }
}

/// Every file of this corpus; `base` is the corpus's small valid scene.
inline void formatsCorpus(std::vector<CorpusFile>& good,
                          std::vector<CorpusFile>& bad,
                          const GltfBuilder& base) {
  geometryCorpus(good, bad);
  documentCorpus(good, bad, base);
  physicsCorpus(good, bad);
  jointCorpus(good, bad);
}

}  // namespace hapticd::scene::testing
