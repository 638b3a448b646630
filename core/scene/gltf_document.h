#pragma once
/// \file
/// The scene loader's first two passes (internal to hapticd_scene): the container (GLB chunks or
/// glTF JSON text) and a validation of the JSON document that checks every type, index, count,
/// range and limit the loader relies on, collecting every problem. What passes is kept as plain
/// structs, so the model builder (loader.cpp) reads nothing unchecked.
/// Any thread but the servo thread.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/scene/loader.h"

namespace hapticd::scene::detail {

/// Collected problems, capped so that a hostile file cannot make the report huge.
class Problems {
 public:
  static constexpr std::size_t kMax = 200;
  void add(std::string where, std::string what);
  bool any() const { return !list_.empty() || dropped_ > 0; }
  /// The list is full: further work would only be counted, not reported.
  bool full() const { return list_.size() >= kMax; }
  std::vector<Problem> take();

 private:
  std::vector<Problem> list_;
  std::size_t dropped_ = 0;
};

enum class ShapeType : std::uint8_t { kBox, kSphere, kCapsule, kCylinder, kPlane };

struct ShapeDef {
  ShapeType type = ShapeType::kBox;
  Vec3 size{1.0};            ///< box
  double radius = 0.5;       ///< sphere
  double height = 0.5;       ///< capsule (between cap centres), cylinder
  double radius_top = 0.25;  ///< capsule, cylinder
  double radius_bottom = 0.25;
  std::optional<double> size_x, size_z;  ///< plane; absent: infinite
  bool double_sided = false;
};

struct MotionDef {
  bool kinematic = false;
  std::optional<double> mass;
  std::optional<Vec3> center_of_mass;
  std::optional<Vec3> inertia_diagonal;
  geom::Quat inertia_orientation{1.0, 0.0, 0.0, 0.0};
  Vec3 linear_velocity{0.0};
  Vec3 angular_velocity{0.0};
  double gravity_factor = 1.0;
};

struct ColliderDef {
  std::int32_t shape = -1;  ///< KHR_implicit_shapes index
  std::int32_t geometry_node = -1;
  bool convex_hull = false;
  std::int32_t material = -1;
  std::int32_t filter = -1;
};

struct JointRef {
  std::int32_t connected_node = -1;
  std::int32_t joint = -1;
  bool enable_collision = false;
};

struct NodeDef {
  std::string name;
  std::vector<std::uint32_t> children;
  std::int32_t parent = -1;
  std::int32_t mesh = -1;
  bool has_matrix = false;
  glm::dmat4 matrix{1.0};
  Vec3 translation{0.0};
  geom::Quat rotation{1.0, 0.0, 0.0, 0.0};
  Vec3 scale{1.0};
  std::optional<MotionDef> motion;
  std::optional<ColliderDef> collider;
  std::optional<JointRef> joint;
  bool probe = false;
  std::optional<double> stiffness;
  std::optional<bool> active;  ///< extras.haptic.active, where declared
  glm::dmat4 local() const;
};

struct FilterDef {
  std::vector<std::string> systems, collide_with, not_collide_with;
};

struct JointDef {
  std::vector<JointLimit> limits;
};

struct BufferDef {
  std::uint64_t byte_length = 0;
  std::string uri;  ///< empty: the GLB binary chunk
};

struct ViewDef {
  std::uint32_t buffer = 0;
  std::uint64_t byte_offset = 0, byte_length = 0, byte_stride = 0;  ///< stride 0: packed
};

struct AccessorDef {
  std::int32_t view = -1;  ///< -1: all zeros
  std::uint64_t byte_offset = 0;
  std::uint32_t component_type = 0;
  std::uint64_t count = 0;
  std::uint32_t components = 1;
  std::string type;
  bool normalized = false;
  std::uint64_t elementBytes() const;
  std::uint64_t strideBytes(const std::vector<ViewDef>& views) const;
};

struct MeshPrimitiveDef {
  std::int32_t position = -1;
  std::int32_t indices = -1;
  std::int32_t mode = 4;
};

struct MeshDef {
  std::string name;
  std::vector<MeshPrimitiveDef> primitives;
};

/// Everything the model builder reads, validated.
struct Document {
  bool glb = false;
  std::string json_text;              ///< the JSON (for tinygltf)
  std::span<const std::uint8_t> bin;  ///< GLB binary chunk, empty if none
  std::vector<NodeDef> nodes;
  std::vector<MeshDef> meshes;
  std::vector<AccessorDef> accessors;
  std::vector<ViewDef> views;
  std::vector<BufferDef> buffers;
  std::vector<ShapeDef> shapes;
  std::vector<Material> materials;
  std::vector<FilterDef> filters;
  std::vector<JointDef> joints;
  std::vector<std::uint32_t> scene_roots;  ///< roots of the scene that is loaded
  std::optional<Vec3> gravity;
  std::string gravity_where;
};

/// "node 3 'Peg'" (or "node 3" when unnamed); the same for meshes.
std::string nodeWhere(const Document& doc, std::size_t node);
std::string meshWhere(const Document& doc, std::size_t mesh);

/// Splits the container and parses the JSON (syntax, depth, number range).
bool parseContainer(std::span<const std::uint8_t> bytes,
                    const LoadOptions& options,
                    Document* doc,
                    Problems* problems,
                    nlohmann::json* json);

/// Checks the JSON document and fills `doc`. False when any problem was found.
bool validateDocument(const nlohmann::json& json,
                      const LoadOptions& options,
                      Document* doc,
                      Problems* problems);

/// Percent-decodes a URI and checks it against the folder policy; the file's canonical path.
std::optional<std::string> resolveUri(const std::string& uri,
                                      const LoadOptions& options,
                                      std::string* why);

}  // namespace hapticd::scene::detail
