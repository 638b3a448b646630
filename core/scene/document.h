#pragma once
/// \file
/// The scene loader's first pass (internal to hapticd_scene): the container (GLB chunks or glTF
/// JSON text) and the JSON parsed once, then validated in one walk that checks every type, index,
/// count, range and limit the loader relies on, collecting every problem. What passes is kept as
/// plain structs, so the later passes (buffers.h, builder.h) read nothing unchecked and never the
/// JSON again. The walk is split by job: validate_gltf.cpp (the top level and its extensions,
/// meshes, nodes, hierarchy, scenes), validate_data.cpp (buffers, bufferViews with meshopt
/// compression, accessors with sparse storage), validate_physics.cpp (KHR_implicit_shapes,
/// KHR_physics_rigid_bodies, extras.haptic) and validate_omi.cpp (OMI_physics_shape,
/// OMI_physics_body, OMI_collider).
/// Any thread but the servo thread.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/scene/compression.h"
#include "core/scene/json_checker.h"
#include "core/scene/loader.h"

namespace hapticd::scene::detail {

enum class ShapeType : std::uint8_t { kBox, kSphere, kCapsule, kCylinder, kPlane, kMesh };

struct ShapeDef {
  ShapeType type = ShapeType::kBox;
  Vec3 size{1.0};            ///< box
  double radius = 0.5;       ///< sphere
  double height = 0.5;       ///< capsule (between cap centres), cylinder
  double radius_top = 0.25;  ///< capsule, cylinder
  double radius_bottom = 0.25;
  std::optional<double> size_x, size_z;  ///< plane; absent: infinite
  bool double_sided = false;
  std::int32_t mesh = -1;    ///< kMesh (OMI convex, trimesh): the glTF mesh, in the node's frame
  bool convex_hull = false;  ///< kMesh: OMI `convex` (its hull) rather than `trimesh` (a surface)
  bool trigger = false;      ///< OMI_collider `isTrigger`
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

/// A collider or a trigger (KHR `collider` / `trigger`, OMI `collider` / `trigger`).
struct ColliderDef {
  std::int32_t shape = -1;  ///< index into Document::shapes (KHR_implicit_shapes, then OMI)
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
  std::optional<ColliderDef> trigger;  ///< a trigger volume with geometry on this node
  /// OMI trigger body (Godot's Area3D, or the older `type: "trigger"`): colliders at or below
  /// it, down to the next body, are triggers.
  bool trigger_body = false;
  std::optional<JointRef> joint;
  bool probe = false;
  std::optional<double> stiffness;
  std::optional<bool> active;  ///< extras.haptic.active, where declared
  /// extras.haptic.concavity, where declared: the decomposition's target for meshes at or below
  /// this node, in (0, 1)
  std::optional<double> concavity;
  glm::dmat4 local() const;
};

struct FilterDef {
  std::vector<std::string> systems, collide_with, not_collide_with;
};

struct JointDef {
  std::vector<JointLimit> limits;
  std::vector<JointDrive> drives;
};

struct BufferDef {
  std::uint64_t byte_length = 0;
  std::string uri;   ///< empty: the GLB binary chunk
  std::string path;  ///< an external URI's file, resolved and checked by validation
  /// No data: a fallback buffer of meshopt compression, read only through compressed views.
  bool placeholder = false;
};

/// EXT_meshopt_compression (or KHR_meshopt_compression) on a bufferView: where the compressed
/// bytes are and how they decode into the view's byteLength.
struct MeshoptDef {
  std::uint32_t buffer = 0;
  std::uint64_t byte_offset = 0, byte_length = 0;
  MeshoptView codec;
};

struct ViewDef {
  std::uint32_t buffer = 0;
  std::uint64_t byte_offset = 0, byte_length = 0, byte_stride = 0;  ///< stride 0: packed
  std::optional<MeshoptDef> meshopt;
};

/// An accessor's sparse storage: `count` indices (strictly increasing, each below the
/// accessor's count: checked on decoding) and the values that replace those elements.
struct SparseDef {
  std::uint64_t count = 0;
  std::int32_t indices_view = -1;
  std::uint64_t indices_offset = 0;
  std::uint32_t indices_component = 0;
  std::int32_t values_view = -1;
  std::uint64_t values_offset = 0;
};

struct AccessorDef {
  std::int32_t view = -1;  ///< -1: all zeros
  std::uint64_t byte_offset = 0;
  std::uint32_t component_type = 0;
  std::uint64_t count = 0;
  std::uint32_t components = 1;
  std::string type;
  bool normalized = false;
  std::optional<SparseDef> sparse;
  std::uint64_t elementBytes() const;
  std::uint64_t strideBytes(const std::vector<ViewDef>& views) const;
};

/// KHR_draco_mesh_compression on a mesh primitive.
struct DracoDef {
  std::int32_t view = -1;         ///< the bufferView holding the Draco stream
  std::uint32_t position_id = 0;  ///< the Draco unique id of POSITION
};

struct MeshPrimitiveDef {
  std::int32_t position = -1;
  std::int32_t indices = -1;
  std::int32_t mode = 4;
  std::optional<DracoDef> draco;
};

struct MeshDef {
  std::string name;
  std::vector<MeshPrimitiveDef> primitives;
};

/// Everything the later passes read, validated.
struct Document {
  bool glb = false;
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
  /// Declares bodies or colliders (KHR_physics_rigid_bodies, OMI_physics_body, OMI_collider);
  /// false: a plain model, whose meshes become static geometry.
  bool physics = false;
  /// Where the OMI shapes, colliders, materials and filters start in shapes, materials, filters.
  std::size_t omi_shape_base = 0, omi_collider_base = 0;
  std::size_t omi_material_base = 0, omi_filter_base = 0;
  /// Where the OMI_physics_joint joints start in joints (the KHR ones come first).
  std::size_t omi_joint_base = 0;
};

/// "node 3 'Peg'" (or "node 3" when unnamed); the same for meshes.
std::string nodeWhere(const Document& doc, std::size_t node);
std::string meshWhere(const Document& doc, std::size_t mesh);
/// Every node's world transform (its parents' times its own, whether in the scene or not); a
/// transform that is not finite is a problem at its node (the loader's and readSceneTriangles').
std::vector<glm::dmat4> worldTransforms(const Document& doc, Problems* problems);

/// The whole first pass: splits the container, parses the JSON once (syntax, depth, number
/// range) and validates it into `doc`. False when any problem was found. `doc->bin` views `bytes`.
bool parseDocument(std::span<const std::uint8_t> bytes,
                   const LoadOptions& options,
                   Document* doc,
                   Problems* problems);

// ---- the validation walk, by job (called by parseDocument in this order) --------------------

/// asset, extensionsRequired/Used (each by what it changes: extensions.h), and the top-level
/// arrays' shapes; false when the structure is too broken to go on (a top-level member that is
/// not an array of objects).
struct TopLevel {
  const json* asset = nullptr;
  const json* buffers = nullptr;
  const json* views = nullptr;
  const json* accessors = nullptr;
  const json* meshes = nullptr;
  const json* nodes = nullptr;
  const json* scenes = nullptr;
  const json* materials = nullptr;
  const json* images = nullptr;
  bool meshopt_used = false;  ///< EXT_ or KHR_meshopt_compression is used
};
bool validateTopLevel(Checker& c, const json& root, TopLevel* top, Document* doc);
/// buffers (URIs resolved under the folder policy; meshopt fallback buffers; images' URIs are
/// never looked at), bufferViews (meshopt compression), accessors (sparse storage)
/// (validate_data.cpp).
void validateData(Checker& c, const TopLevel& top, const LoadOptions& options, Document* doc);
/// meshes and their primitives (KHR_draco_mesh_compression).
void validateMeshes(Checker& c, const TopLevel& top, Document* doc);
/// The root extensions objects: KHR_implicit_shapes shapes and KHR_physics_rigid_bodies
/// materials, filters and joints (validate_physics.cpp), then the OMI ones (validate_omi.cpp).
void validatePhysicsRoot(Checker& c, const json& root, Document* doc);
void validateOmiRoot(Checker& c, const json& extensions, Document* doc);
/// physicsMaterials and collisionFilters of a KHR_physics_rigid_bodies or OMI_physics_body
/// document object, appended to doc.
void validateMaterialsAndFilters(Checker& c,
                                 const json& ext,
                                 const std::string& name,
                                 Document* doc);
/// Whose rules a joint follows. KHR_physics_rigid_bodies: each limit names linearAxes or
/// angularAxes (1 to 3 axes); stiffness and maxForce are >= 0. OMI_physics_joint (Godot): a limit
/// may name both (kept as two limits with the same range) and an empty list is no axis; a
/// negative stiffness is infinitely stiff and a negative maxForce not limited, as absent ones.
enum class JointDialect { kKhr, kOmi };
/// physicsJoints (limits and drives) of a KHR_physics_rigid_bodies or OMI_physics_joint document
/// object, appended to doc.joints (validate_physics.cpp).
void validateJoints(Checker& c, const json& ext, JointDialect dialect, Document* doc);
/// nodes (transforms, physics, extras), one parent each, no cycles; false when over max_nodes.
bool validateNodes(Checker& c, const TopLevel& top, const SceneLimits& limits, Document* doc);
/// A node's KHR_physics_rigid_bodies object (validate_physics.cpp).
void validateNodePhysics(Checker& c,
                         const json& ext,
                         const std::string& where,
                         const Document& doc,
                         NodeDef* node);
/// A node's OMI_physics_body and OMI_collider objects (validate_omi.cpp), from its extensions.
void validateOmiNode(Checker& c,
                     const json& extensions,
                     const std::string& where,
                     const Document& doc,
                     NodeDef* node);
/// An optional array of node indices (a compound trigger's `nodes`).
void validateNodeList(Checker& c,
                      const json& o,
                      const char* key,
                      const std::string& where,
                      const Document& doc,
                      std::vector<std::int32_t>* out);
/// The scene to load, its roots and the gravity (scene or asset extras).
void validateScenes(Checker& c, const json& root, const TopLevel& top, Document* doc);
/// extras.haptic on a node (probe, stiffness, active) or on a scene or the asset (gravity); any
/// other key is a problem (a typo would silently change physics).
struct HapticExtras {
  bool node = true;  ///< the owner is a node; false: a scene or the asset
  bool probe = false;
  std::optional<double> stiffness;
  std::optional<bool> active;
  std::optional<double> concavity;
  std::optional<Vec3> gravity;
};
void validateHapticExtras(Checker& c,
                          const json& owner,
                          const std::string& where,
                          HapticExtras* out);

}  // namespace hapticd::scene::detail
