#pragma once
/// \file
/// Builds small glTF scenes in memory for the scene loader's tests, the bad-file corpus generator,
/// the fuzz seeds and the load benchmark: JSON with nlohmann, mesh data in one buffer, written as
/// .gltf (base64 data URI) or .glb. Header-only, test code.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/geometry/pose.h"
#include "core/scene/glb.h"

namespace hapticd::scene::testing {

using nlohmann::json;
using Vec3 = geom::Vec3;

inline std::string base64(const std::vector<std::uint8_t>& data) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < data.size(); i += 3) {
    const std::uint32_t b0 = data[i];
    const std::uint32_t b1 = i + 1 < data.size() ? data[i + 1] : 0u;
    const std::uint32_t b2 = i + 2 < data.size() ? data[i + 2] : 0u;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(i + 1 < data.size() ? kAlphabet[(v >> 6) & 63] : '=');
    out.push_back(i + 2 < data.size() ? kAlphabet[v & 63] : '=');
  }
  return out;
}

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> triangles;
};

/// A unit cube [-h, h]^3, outward counter-clockwise triangles.
inline Mesh cubeMesh(double h = 0.5) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h});
  m.triangles = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  return m;
}

/// A cube whose top face is a pyramid pointing down into it: closed and not convex.
inline Mesh dentedCubeMesh(double h = 0.5) {
  Mesh m = cubeMesh(h);
  // drop the two top triangles (2 6 3, 3 6 7) and fan the top edges to a dent at (0, 0.2h, 0)
  m.triangles.erase(m.triangles.begin() + 18, m.triangles.begin() + 24);
  m.vertices.push_back({0.0, 0.2 * h, 0.0});
  const std::uint32_t d = 8;
  m.triangles.insert(m.triangles.end(), {2, 6, d, 6, 7, d, 7, 3, d, 3, 2, d});
  return m;
}

class GltfBuilder {
 public:
  json doc;
  std::vector<std::uint8_t> bin;
  /// Buffers after buffer 0 (the bin), e.g. a meshopt fallback buffer.
  std::vector<json> more_buffers;

  GltfBuilder() {
    doc = {{"asset", {{"version", "2.0"}, {"generator", "hapticd tests"}}}};
    doc["scenes"] = json::array({json{{"nodes", json::array()}}});
    doc["scene"] = 0;
    doc["nodes"] = json::array();
  }

  /// Names an extension in extensionsUsed (and extensionsRequired when `required`), once.
  void useExtension(const std::string& name, bool required) {
    const auto add = [&](const char* list) {
      json& l = doc[list];
      if (std::find(l.begin(), l.end(), name) == l.end())
        l.push_back(name);
    };
    add("extensionsUsed");
    if (required)
      add("extensionsRequired");
  }

  /// Appends raw bytes to the buffer (4-byte aligned) and returns a bufferView index.
  int addView(const void* data, std::size_t size, std::size_t stride = 0) {
    while (bin.size() % 4 != 0)
      bin.push_back(0);
    const std::size_t offset = bin.size();
    const auto* p = static_cast<const std::uint8_t*>(data);
    bin.insert(bin.end(), p, p + size);
    json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
    if (stride)
      view["byteStride"] = stride;
    doc["bufferViews"].push_back(view);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }

  int addAccessor(json accessor) {
    doc["accessors"].push_back(std::move(accessor));
    return static_cast<int>(doc["accessors"].size()) - 1;
  }

  /// A triangle mesh: float positions and uint32 indices. Returns the mesh index.
  int addMesh(const Mesh& mesh, const std::string& name = "") {
    std::vector<float> pos;
    Vec3 lo{1e300}, hi{-1e300};
    for (const Vec3& v : mesh.vertices) {
      pos.insert(pos.end(),
                 {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    const int pv = addView(pos.data(), pos.size() * sizeof(float));
    const int pa = addAccessor({{"bufferView", pv},
                                {"componentType", 5126},
                                {"count", mesh.vertices.size()},
                                {"type", "VEC3"},
                                {"min", {lo.x, lo.y, lo.z}},
                                {"max", {hi.x, hi.y, hi.z}}});
    json prim = {{"attributes", {{"POSITION", pa}}}, {"mode", 4}};
    if (!mesh.triangles.empty()) {
      const int iv = addView(mesh.triangles.data(), mesh.triangles.size() * sizeof(std::uint32_t));
      prim["indices"] = addAccessor({{"bufferView", iv},
                                     {"componentType", 5125},
                                     {"count", mesh.triangles.size()},
                                     {"type", "SCALAR"}});
    }
    json m = {{"primitives", json::array({prim})}};
    if (!name.empty())
      m["name"] = name;
    doc["meshes"].push_back(m);
    return static_cast<int>(doc["meshes"].size()) - 1;
  }

  int addShape(const json& shape) {
    auto& shapes = doc["extensions"]["KHR_implicit_shapes"]["shapes"];
    shapes.push_back(shape);
    return static_cast<int>(shapes.size()) - 1;
  }
  int box(Vec3 size) {
    return addShape({{"type", "box"}, {"box", {{"size", {size.x, size.y, size.z}}}}});
  }
  int sphere(double r) { return addShape({{"type", "sphere"}, {"sphere", {{"radius", r}}}}); }
  int capsule(double height, double rt, double rb) {
    return addShape({{"type", "capsule"},
                     {"capsule", {{"height", height}, {"radiusTop", rt}, {"radiusBottom", rb}}}});
  }
  int cylinder(double height, double rt, double rb) {
    return addShape({{"type", "cylinder"},
                     {"cylinder", {{"height", height}, {"radiusTop", rt}, {"radiusBottom", rb}}}});
  }
  int plane() { return addShape({{"type", "plane"}, {"plane", json::object()}}); }

  int addPhysics(const char* list, const json& item) {
    auto& arr = doc["extensions"]["KHR_physics_rigid_bodies"][list];
    arr.push_back(item);
    return static_cast<int>(arr.size()) - 1;
  }
  int material(double friction, double restitution, const char* combine = "average") {
    return addPhysics("physicsMaterials", {{"staticFriction", friction},
                                           {"dynamicFriction", friction},
                                           {"restitution", restitution},
                                           {"frictionCombine", combine},
                                           {"restitutionCombine", combine}});
  }

  int addNode(json node, int parent = -1) {
    doc["nodes"].push_back(std::move(node));
    const int index = static_cast<int>(doc["nodes"].size()) - 1;
    if (parent < 0) {
      doc["scenes"][0]["nodes"].push_back(index);
    } else {
      doc["nodes"][static_cast<std::size_t>(parent)]["children"].push_back(index);
    }
    return index;
  }

  /// A node with a collider of an implicit shape.
  static json shapeCollider(int shape, json extra = json::object()) {
    json collider = {{"geometry", {{"shape", shape}}}};
    collider.update(extra);
    return collider;
  }

  /// A node json with translation and optional physics pieces.
  static json node(const std::string& name, Vec3 t = Vec3{0.0}) {
    return {{"name", name}, {"translation", {t.x, t.y, t.z}}};
  }
  static json& physics(json& node) { return node["extensions"]["KHR_physics_rigid_bodies"]; }

  /// Sets `extras.haptic.gravity` on the scene.
  void gravity(Vec3 g) { doc["scenes"][0]["extras"]["haptic"]["gravity"] = {g.x, g.y, g.z}; }

  /// The JSON with the buffer as a base64 data URI (.gltf).
  std::string gltf() const {
    json d = doc;
    if (!bin.empty()) {
      d["buffers"] =
          json::array({json{{"byteLength", bin.size()},
                            {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
      for (const json& extra : more_buffers)
        d["buffers"].push_back(extra);
    }
    return d.dump();
  }

  /// The GLB container, the buffer in the BIN chunk.
  std::vector<std::uint8_t> glb() const {
    json d = doc;
    if (!bin.empty()) {
      d["buffers"] = json::array({json{{"byteLength", bin.size()}}});
      for (const json& extra : more_buffers)
        d["buffers"].push_back(extra);
    }
    return packGlb(d.dump(), bin);
  }
};

inline std::vector<std::uint8_t> bytesOf(const std::string& s) {
  return {s.begin(), s.end()};
}

}  // namespace hapticd::scene::testing
