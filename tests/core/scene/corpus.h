#pragma once
/// \file
/// The corpus of the scene loader: bad files (tests/scenes/bad/) and good scenes
/// (tests/scenes/good/), made in code so that they are reproducible: `scene_corpus_gen DIR`
/// writes them with their expected.txt, scene_corpus_test checks the committed files are exactly
/// these, that each bad one gives its own error and each good one loads; `hapticctl check` is run
/// on all of them (check_corpus.cmake). The files of glTF as exporters write it are
/// corpus_formats.h's.

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "tests/core/scene/corpus_formats.h"
#include "tests/core/scene/gltf_builder.h"

namespace hapticd::scene::testing {

/// A small valid scene: a static floor box and a dynamic cube mesh (a convex mesh collider).
inline GltfBuilder baseScene() {
  GltfBuilder b;
  json floor = GltfBuilder::node("Floor", {0.0, -0.05, 0.0});
  GltfBuilder::physics(floor)["collider"] = GltfBuilder::shapeCollider(b.box({2.0, 0.1, 2.0}));
  b.addNode(floor);
  json cube = GltfBuilder::node("Cube", {0.0, 0.5, 0.0});
  cube["mesh"] = b.addMesh(cubeMesh(), "CubeMesh");
  GltfBuilder::physics(cube)["motion"] = json::object();
  GltfBuilder::physics(cube)["collider"] = {{"geometry", {{"node", 1}}}};
  b.addNode(cube);
  return b;
}

/// The base scene with the cube's mesh replaced by `mesh`; `hull`: its collider a convex hull.
inline GltfBuilder baseSceneWithMesh(const Mesh& mesh, const std::string& name, bool hull) {
  GltfBuilder b = baseScene();
  b.doc["meshes"] = json::array();
  b.doc["bufferViews"] = json::array();
  b.doc["accessors"] = json::array();
  b.bin.clear();
  b.addMesh(mesh, name);
  if (hull)
    GltfBuilder::physics(b.doc["nodes"][1])["collider"]["geometry"]["convexHull"] = true;
  return b;
}

inline void putU32(std::vector<std::uint8_t>& v, std::size_t at, std::uint32_t x) {
  for (int k = 0; k < 4; ++k)
    v[at + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(x >> (8 * k));
}

inline std::vector<CorpusFile> badCorpus() {
  std::vector<CorpusFile> out;
  const auto text = [](const std::string& s) { return bytesOf(s); };
  const auto add = [&](std::string name, std::vector<std::uint8_t> bytes, std::string expect,
                       bool allow = false) {
    out.push_back({std::move(name), std::move(bytes), std::move(expect), allow});
  };
  const std::vector<std::uint8_t> glb = baseScene().glb();
  const std::size_t json_length = std::size_t{glb[12]} | (std::size_t{glb[13]} << 8) |
                                  (std::size_t{glb[14]} << 16) | (std::size_t{glb[15]} << 24);

  // ---- the GLB container
  add("truncated.glb", {glb.begin(), glb.begin() + static_cast<std::ptrdiff_t>(glb.size() / 2)},
      "truncated GLB: the header says");
  add("truncated_header.glb", {glb.begin(), glb.begin() + 10}, "truncated GLB: 10 bytes");
  add("empty.glb", {}, "not glTF: wrong magic");
  {
    auto v = glb;
    v[3] = 'X';
    add("wrong_magic.glb", v, "not glTF: wrong magic");
  }
  {
    auto v = glb;
    putU32(v, 4, 1);
    add("glb_version_1.glb", v, "GLB version 1 (only 2 is supported)");
  }
  {
    auto v = glb;
    putU32(v, 12, 0x7FFFFFF0u);
    add("lying_json_chunk_length.glb", v, "GLB JSON chunk length 2147483632 runs past the end");
  }
  {
    auto v = glb;
    putU32(v, 20 + json_length, 0x10000000u);
    add("lying_bin_chunk_length.glb", v, "GLB BIN chunk length 268435456 runs past the end");
  }
  {
    auto v = glb;
    putU32(v, 8, static_cast<std::uint32_t>(glb.size() - 4));
    add("lying_header_length.glb", v, "does not match the file size");
  }
  {
    auto v = glb;
    putU32(v, 16, 0x4E4942u);  // BIN where JSON belongs
    add("first_chunk_not_json.glb", v, "GLB chunk 0 is not JSON");
  }
  {
    // the BIN chunk is shorter than the buffer's byteLength
    GltfBuilder b = baseScene();
    json d = b.doc;
    d["buffers"] = json::array({json{{"byteLength", b.bin.size() + 64}}});
    GltfBuilder c;
    c.doc = d;
    c.bin = b.bin;
    auto v = c.glb();
    // glb() rewrites buffers from bin: patch the JSON text's byteLength back to the lie
    std::string s(v.begin(), v.end());
    const std::string real = "\"byteLength\":" + std::to_string(b.bin.size()) + "}";
    const std::string lie = "\"byteLength\":" + std::to_string(b.bin.size() + 64) + "}";
    const std::size_t at = s.find(real);
    if (at != std::string::npos && lie.size() == real.size())
      s.replace(at, real.size(), lie);
    add("buffer_longer_than_bin_chunk.glb", {s.begin(), s.end()}, "exceeds the GLB BIN chunk");
  }

  // ---- JSON
  add("json_syntax_error.gltf", text(R"({"asset": {"version": "2.0"}, "nodes": [,]})"),
      "JSON syntax error at byte");
  add("json_truncated.gltf", text(R"({"asset": {"version": "2.0"}, "nodes": [{"name": "a")"),
      "JSON syntax error");
  add("json_not_utf8.gltf",
      text("{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"name\": \"\xff\xfe\"}]}"),
      "JSON syntax error");
  add("json_deep.gltf",
      text("{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(200, '[') +
           std::string(200, ']') + "}"),
      "JSON nested deeper than 64 levels");
  add("no_asset.gltf", text(R"({"nodes": []})"), "asset: required property asset is missing");
  add("asset_version_1.gltf", text(R"({"asset": {"version": "1.0"}})"),
      "glTF version '1.0' is not 2.x");
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["translation"] = "up";
    add("wrong_type_translation.gltf", bytesOf(b.gltf()),
        "node 0 'Floor': translation must be an array of 3 numbers");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][1]["mesh"] = "CubeMesh";
    add("wrong_type_mesh_index.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': mesh must be an integer index, got string");
  }
  add("wrong_type_nodes.gltf", text(R"({"asset": {"version": "2.0"}, "nodes": {"a": 1}})"),
      "nodes: nodes must be an array, got object");
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["count"] = -3;
    add("negative_count.gltf", bytesOf(b.gltf()), "accessor 0: count is negative (-3)");
  }
  {
    GltfBuilder b = baseScene();
    std::string s = b.gltf();
    const std::string from = "\"translation\":[0.0,-0.05,0.0]";
    const std::size_t at = s.find(from);
    if (at != std::string::npos)
      s.replace(at, from.size(), "\"translation\":[1e999,-0.05,0.0]");
    add("inf_translation.gltf", bytesOf(s),
        "JSON number not finite: [json.exception.out_of_range.406] number overflow parsing "
        "'1e999'");
  }
  {
    GltfBuilder b = baseScene();
    GltfBuilder::physics(b.doc["nodes"][1])["motion"]["mass"] = -1.0;
    add("negative_mass.gltf", bytesOf(b.gltf()), "node 1 'Cube' motion: mass must be >= 0, got -1");
  }

  // ---- binary data
  {
    GltfBuilder b = baseScene();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(b.bin.data() + 4 * 12 + 4, &nan, 4);  // vertex 4, y
    add("nan_vertex.glb", b.glb(),
        "mesh 0 'CubeMesh' primitive 0 POSITION: vertex 4 is not finite (NaN or Inf)");
  }
  {
    GltfBuilder b = baseScene();
    const float inf = std::numeric_limits<float>::infinity();
    std::memcpy(b.bin.data() + 7 * 12, &inf, 4);
    add("inf_vertex.gltf", bytesOf(b.gltf()), "vertex 7 is not finite (NaN or Inf)");
  }
  {
    GltfBuilder b = baseScene();
    const std::uint32_t big = 99;
    // the index buffer follows the 8 vertices (96 bytes)
    std::memcpy(b.bin.data() + 96 + 4 * 5, &big, 4);
    add("vertex_index_out_of_range.glb", b.glb(), "index 99 out of range (8 vertices)");
  }

  // ---- indices
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["children"] = {5};
    add("node_index_out_of_range.gltf", bytesOf(b.gltf()),
        "node 0 'Floor': children index 5 out of range (2 nodes)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9;
    add("accessor_index_out_of_range.gltf", bytesOf(b.gltf()),
        "attribute POSITION index 9 out of range (2 accessors)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][1]["bufferView"] = 4;
    add("bufferview_index_out_of_range.gltf", bytesOf(b.gltf()),
        "accessor 1: bufferView index 4 out of range (2 bufferViews)");
  }
  {
    GltfBuilder b = baseScene();
    GltfBuilder::physics(b.doc["nodes"][0])["collider"]["geometry"]["shape"] = 3;
    add("shape_index_out_of_range.gltf", bytesOf(b.gltf()),
        "shape index 3 out of range (1 KHR_implicit_shapes shapes)");
  }
  {
    GltfBuilder b = baseScene();
    GltfBuilder::physics(b.doc["nodes"][0])["collider"]["physicsMaterial"] = 0;
    add("material_index_out_of_range.gltf", bytesOf(b.gltf()),
        "physicsMaterial index 0 out of range (0 physicsMaterials)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["scene"] = 2;
    add("scene_index_out_of_range.gltf", bytesOf(b.gltf()),
        "scene index 2 out of range (1 scenes)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["scenes"][0]["nodes"] = json::array();
    b.doc["nodes"][0]["children"] = {1};
    b.doc["nodes"][1]["children"] = {0};
    add("node_cycle.gltf", bytesOf(b.gltf()), "is in a cycle of node children");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["children"] = {0};
    add("node_self_child.gltf", bytesOf(b.gltf()),
        "node 0 'Floor': lists itself as a child (a node cycle)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["scenes"][0]["nodes"] = {0};
    b.doc["nodes"][0]["children"] = {1, 1};
    add("duplicate_child.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': is listed twice among the children of node 0 'Floor'");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["scenes"][0]["nodes"] = {0, 1, 0};
    add("duplicate_scene_root.gltf", bytesOf(b.gltf()), "scene 0: node 0 'Floor' is listed twice");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"].push_back({{"name", "Other"}, {"children", {1}}});
    b.doc["nodes"][0]["children"] = {1};
    add("two_parents.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': has two parents (node 0 'Floor' and node 2 'Other')");
  }

  // ---- accessor and view ranges
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["count"] = 9;
    add("accessor_past_view.gltf", bytesOf(b.gltf()),
        "accessor 0: byteOffset 0 + count 9 x stride 12 = 108 runs past the end of bufferView 0 "
        "(96 bytes)");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["count"] = 357913942;  // 12 * count wraps 32 bits
    add("accessor_overflow_32bit.gltf", bytesOf(b.gltf()),
        "count 357913942 x stride 12 = 4294967304 runs past the end of bufferView 0");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["count"] = 4611686018427387904ull;  // 12 * count wraps 64 bits
    add("accessor_overflow_64bit.gltf", bytesOf(b.gltf()),
        "x stride 12 overflows and runs past the end of bufferView 0");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["byteOffset"] = 18446744073709551610ull;
    add("accessor_offset_overflow.gltf", bytesOf(b.gltf()),
        "overflows and runs past the end of bufferView 0");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["bufferViews"][1]["byteLength"] = 100000;
    add("view_past_buffer.gltf", bytesOf(b.gltf()),
        "bufferView 1: byteOffset 96 + byteLength 100000 runs past the end of buffer 0");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["bufferViews"][0]["byteStride"] = 6;
    add("bad_stride.gltf", bytesOf(b.gltf()), "byteStride 6 must be a multiple of 4 in [4, 252]");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["accessors"][0]["sparse"] = {{"count", 1}};
    add("sparse_accessor.gltf", bytesOf(b.gltf()),
        "accessor 0 sparse: required property indices is missing");
  }

  // ---- URIs
  {
    GltfBuilder b = baseScene();
    json d = b.doc;
    d["buffers"] = json::array({json{{"byteLength", b.bin.size()}, {"uri", "cube.bin"}}});
    add("external_uri.gltf", bytesOf(d.dump()),
        "buffer 0: external URI 'cube.bin': no such file in the allowed folder");
    d["buffers"][0]["uri"] = "../../etc/passwd";
    add("traversing_uri.gltf", bytesOf(d.dump()),
        "external URI '../../etc/passwd' traverses out of the allowed folder", true);
    d["buffers"][0]["uri"] = "%2E%2E/%2e%2e/etc/passwd";
    add("traversing_encoded_uri.gltf", bytesOf(d.dump()), "traverses out of the allowed folder",
        true);
    d["buffers"][0]["uri"] = "/etc/passwd";
    add("absolute_uri.gltf", bytesOf(d.dump()), "external URI '/etc/passwd' is an absolute path",
        true);
    d["buffers"][0]["uri"] = "https://example.com/cube.bin";
    add("remote_uri.gltf", bytesOf(d.dump()), "has a scheme", true);
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAAA";
    add("data_uri_too_short.gltf", bytesOf(d.dump()), "glTF: Failed to decode 'uri'");
  }

  // ---- extensions
  {
    GltfBuilder b = baseScene();
    b.doc["extensions"]["KHR_implicit_shapes"]["shapes"][0] = {{"type", "torus"}};
    add("unknown_shape_type.gltf", bytesOf(b.gltf()), "shape type 'torus' is not supported");
  }

  // ---- geometry
  {
    Mesh quad;
    quad.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    quad.triangles = {0, 1, 2, 0, 2, 3};
    const GltfBuilder b = baseSceneWithMesh(quad, "Quad", true);
    add("flat_hull.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': mesh 0 'Quad': cannot build a convex hull: all points are coplanar");
  }
  {
    Mesh line;
    line.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {1, 1, 1}, {2, 2, 2}};
    line.triangles = {0, 1, 2, 3, 4, 5};
    const GltfBuilder b = baseSceneWithMesh(line, "Line", true);
    add("degenerate_hull.gltf", bytesOf(b.gltf()),
        "mesh 0 'Line': cannot build a convex hull: all points are collinear");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["extensions"]["KHR_implicit_shapes"]["shapes"][0]["box"]["size"] = {2.0, 0.0, 2.0};
    add("flat_box.gltf", bytesOf(b.gltf()), "size must be positive on every axis");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["scale"] = {1.0, 0.0, 1.0};
    add("flattened_by_scale.gltf", bytesOf(b.gltf()),
        "node 0 'Floor': collider: cannot build a convex hull: all points are coplanar");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["meshes"][0]["primitives"][0]["mode"] = 1;
    add("lines_mesh_collider.gltf", bytesOf(b.gltf()), "mode 1 is not TRIANGLES (4)");
  }

  // ---- transforms and physics
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][1]["rotation"] = {0.0, 0.0, 0.0, 2.0};
    add("non_unit_quaternion.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': rotation is not a unit quaternion (norm 2");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][1].erase("translation");
    b.doc["nodes"][1]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1};
    add("matrix_not_affine.gltf", bytesOf(b.gltf()), "matrix is not affine");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["scale"] = {1e200, 1e200, 1e200};
    b.doc["nodes"][0]["children"] = {1};
    b.doc["nodes"][1]["scale"] = {1e200, 1e200, 1e200};
    b.doc["scenes"][0]["nodes"] = {0};
    add("world_transform_overflow.gltf", bytesOf(b.gltf()),
        "node 1 'Cube': world transform is not finite");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["extras"]["haptic"]["probe"] = true;
    b.doc["nodes"][1]["extras"]["haptic"]["probe"] = true;
    add("two_probes.gltf", bytesOf(b.gltf()), "is a second probe");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][1]["extras"]["haptic"]["active"] = "no";
    add("active_not_bool.gltf", bytesOf(b.gltf()), "node 1 'Cube' extras.haptic: active");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["nodes"][0]["extras"]["haptic"]["active"] = false;
    add("active_false_static.gltf", bytesOf(b.gltf()),
        "node 0 'Floor': extras.haptic.active false on a static collider");
  }
  {
    GltfBuilder b = baseScene();
    json n = GltfBuilder::node("Ghost", {3.0, 0.0, 0.0});
    GltfBuilder::physics(n)["motion"] = json::object();
    b.addNode(n);
    add("dynamic_without_volume.gltf", bytesOf(b.gltf()),
        "node 2 'Ghost': dynamic body has no collider volume to compute its mass from");
  }
  {
    GltfBuilder b = baseScene();
    b.doc["extensions"]["KHR_implicit_shapes"]["shapes"].push_back(
        {{"type", "plane"}, {"plane", json::object()}});
    json n = GltfBuilder::node("Wall", {0.0, 0.0, 0.0});
    GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(1);
    GltfBuilder::physics(n)["motion"] = json::object();
    b.addNode(n);
    add("moving_plane.gltf", bytesOf(b.gltf()), "a plane collider must be static");
  }
  std::vector<CorpusFile> good;
  formatsCorpus(good, out, baseScene());
  return out;
}

inline std::vector<CorpusFile> goodCorpus() {
  std::vector<CorpusFile> out;
  const std::string plan = "plan:\n  contact forces: on";
  out.push_back({"base.glb", baseScene().glb(), plan});
  out.push_back({"base.gltf", bytesOf(baseScene().gltf()), plan});
  {
    // textures are never read: ones elsewhere, missing or on the web load as if absent
    GltfBuilder b = baseScene();
    b.doc["images"] =
        json::array({json{{"uri", "../textures/wood.png"}}, json{{"uri", "missing.png"}},
                     json{{"uri", "https://example.com/wood.png"}}});
    out.push_back({"textures_elsewhere.gltf", bytesOf(b.gltf()), plan});
  }
  {
    GltfBuilder b;
    b.gravity({0.0, -9.81, 0.0});
    const int m = b.material(0.6, 0.2);
    json ground = GltfBuilder::node("Ground");
    GltfBuilder::physics(ground)["collider"] =
        GltfBuilder::shapeCollider(b.plane(), {{"physicsMaterial", m}});
    b.addNode(ground);
    const int shapes[] = {b.box({0.1, 0.1, 0.1}), b.sphere(0.05), b.capsule(0.1, 0.03, 0.03),
                          b.cylinder(0.1, 0.04, 0.04)};
    for (int i = 0; i < 4; ++i) {
      json n = GltfBuilder::node("Body" + std::to_string(i), {0.2 * i, 0.2, 0.0});
      GltfBuilder::physics(n)["motion"] = json::object();
      GltfBuilder::physics(n)["collider"] = GltfBuilder::shapeCollider(shapes[i]);
      b.addNode(n);
    }
    json probe = GltfBuilder::node("Stick", {0.0, 0.5, 0.0});
    GltfBuilder::physics(probe)["motion"] = {{"isKinematic", true}};
    GltfBuilder::physics(probe)["collider"] =
        GltfBuilder::shapeCollider(b.capsule(0.2, 0.01, 0.01));
    probe["extras"]["haptic"] = {{"probe", true}, {"stiffness", 1500.0}};
    b.addNode(probe);
    out.push_back({"shapes_gravity_probe.glb", b.glb(), plan});
  }
  {
    GltfBuilder b;
    const int hinge = b.addPhysics(
        "physicsJoints", {{"limits", json::array({{{"linearAxes", {0, 1, 2}}, {"max", 0.0}},
                                                  {{"angularAxes", {0, 1}}, {"max", 0.0}}})}});
    for (int i = 0; i < 2; ++i) {
      json gear = GltfBuilder::node("Gear" + std::to_string(i), {0.1 * i, 0.0, 0.0});
      GltfBuilder::physics(gear)["motion"] = json::object();
      GltfBuilder::physics(gear)["collider"] =
          GltfBuilder::shapeCollider(b.cylinder(0.01, 0.05, 0.05));
      const int g = b.addNode(gear);
      const int anchor =
          b.addNode(GltfBuilder::node("Axle" + std::to_string(i), {0.1 * i, 0.0, 0.0}));
      json pivot = GltfBuilder::node("Pivot" + std::to_string(i));
      GltfBuilder::physics(pivot)["joint"] = {{"connectedNode", anchor}, {"joint", hinge}};
      b.addNode(pivot, g);
    }
    out.push_back({"hinges.gltf", bytesOf(b.gltf()), plan});
  }
  // once refused, now loaded: a non-convex mesh collider, a ball joint, 40 systems in one filter
  out.push_back({"non_convex_mesh.glb",
                 baseSceneWithMesh(dentedCubeMesh(), "DentedMesh", false).glb(),
                 "node 1 'Cube'): not convex, touched through\n"
                 "convex pieces (convex decomposition, concavity"});
  {
    GltfBuilder b = baseScene();
    const int j = b.addPhysics(
        "physicsJoints", {{"limits", json::array({{{"linearAxes", {0, 1, 2}}, {"max", 0.0}}})}});
    GltfBuilder::physics(b.doc["nodes"][1])["joint"] = {{"connectedNode", 0}, {"joint", j}};
    out.push_back({"ball_joint.gltf", bytesOf(b.gltf()), "ball between body 0 and the scene"});
  }
  {
    GltfBuilder b = baseScene();
    json systems = json::array();
    for (int i = 0; i < 40; ++i)
      systems.push_back("system" + std::to_string(i));
    const int f = b.addPhysics("collisionFilters", {{"collisionSystems", systems}});
    GltfBuilder::physics(b.doc["nodes"][0])["collider"]["collisionFilter"] = f;
    out.push_back({"many_collision_systems.gltf", bytesOf(b.gltf()), plan});
  }
  std::vector<CorpusFile> bad;
  formatsCorpus(out, bad, baseScene());
  return out;
}

}  // namespace hapticd::scene::testing
