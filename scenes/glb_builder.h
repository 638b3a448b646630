#pragma once
/// \file
/// A small, deterministic glTF 2.0 binary (.glb) writer for the demo scenes: meshes of float32
/// positions and triangle indices, nodes, and the top-level objects of KHR_physics_rigid_bodies
/// and KHR_implicit_shapes (docs/scenes.md). The JSON is written by nlohmann_json with
/// sorted keys and no indentation; computed numbers go through `quantize()` and vertices are
/// float32 (accessor min/max are those floats), so the same scene gives the same bytes on every
/// build — checked for GCC -O2/-O3 and clang -O1 with sanitizers (GLB layout: glTF 2.0
/// specification, "Binary glTF Layout").
/// Any thread; no global state.

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hapticd::scenes {

using Vec3 = glm::dvec3;
using Json = nlohmann::json;  // std::map objects: keys come out sorted

/// A triangle mesh in its node's frame (metres). Triangles counter-clockwise seen from outside.
struct MeshData {
  std::vector<Vec3> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// A number rounded to 10 significant digits (and |x| < 1e-12 to 0), so that values computed
/// with libm functions print the same on every build.
double quantize(double x);
/// A JSON array of quantized numbers.
Json jsonVec(const Vec3& v);
/// A unit quaternion in glTF order [x, y, z, w], from a rotation about a unit axis by angle_rad.
Json jsonQuatAxisAngle(const Vec3& axis, double angle_rad);

/// Builds one glTF asset and packs it into GLB bytes. Indices returned by the add* functions
/// are the glTF indices of the objects made.
class GltfBuilder {
 public:
  /// A core glTF material (pbrMetallicRoughness) for viewers; rgba in 0..1.
  int addRenderMaterial(const std::string& name,
                        const std::array<double, 4>& rgba,
                        double metallic,
                        double roughness);
  /// A mesh with one triangle primitive: a POSITION accessor (float32, with min and max) and an
  /// index accessor (uint16 when the vertex count allows, else uint32). render_material < 0: none.
  int addMesh(const std::string& name, const MeshData& mesh, int render_material);
  /// A node (any JSON object, e.g. with "name", "translation", "extensions"); not a root yet.
  int addNode(Json node);
  /// The node's JSON, to add fields after the node exists (e.g. a collider naming itself).
  Json& node(int index) { return nodes_.at(static_cast<std::size_t>(index)); }
  /// Makes `child` a child of `parent` (appended to parent's "children").
  void addChild(int parent, int child);
  /// Makes a node a root node of the scene.
  void addRoot(int node_index) { roots_.push_back(node_index); }
  /// A KHR_implicit_shapes shape, e.g. {"type":"box","box":{"size":[...]}}.
  int addShape(Json shape);
  /// A KHR_physics_rigid_bodies physics material.
  int addPhysicsMaterial(Json material);
  /// A KHR_physics_rigid_bodies joint description (limits, drives).
  int addPhysicsJoint(Json joint);
  /// scenes[0].extras (e.g. {"haptic":{"gravity":[0,-9.81,0]}}).
  void setSceneExtras(Json extras) { scene_extras_ = std::move(extras); }

  /// The whole asset as GLB: 12-byte header, JSON chunk padded with spaces to 4 bytes, BIN chunk
  /// padded with zeros to 4 bytes. KHR_physics_rigid_bodies is listed as used and required;
  /// KHR_implicit_shapes too when a shape was added.
  std::vector<std::uint8_t> finish(const std::string& scene_name) const;

 private:
  int addView(const void* data, std::size_t bytes, int target);

  std::vector<std::uint8_t> bin_;
  Json buffer_views_ = Json::array();
  Json accessors_ = Json::array();
  Json meshes_ = Json::array();
  Json render_materials_ = Json::array();
  std::vector<Json> nodes_;
  std::vector<int> roots_;
  Json shapes_ = Json::array();
  Json physics_materials_ = Json::array();
  Json physics_joints_ = Json::array();
  Json scene_extras_;
};

}  // namespace hapticd::scenes
