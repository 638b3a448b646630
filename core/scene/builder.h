#pragma once
/// \file
/// The scene loader's last pass (internal to hapticd_scene): a validated Document and its buffers
/// to a SceneModel. build_scene.cpp: world transforms, the scene's nodes, bodies (a plain model's
/// mesh nodes as static bodies), extras, notes and the plan; build_colliders.cpp: primitives from
/// implicit shapes and meshes (hulls, convexity, the stand-in for non-convex meshes, planes,
/// shared hulls); build_physics.cpp: mass properties, collision filters, joints.
/// Any thread but the servo thread (allocates, builds hulls).

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/scene/accessors.h"
#include "core/scene/decompose.h"
#include "core/scene/document.h"
#include "core/scene/shapes.h"

namespace hapticd::scene::detail {

/// Density of bodies whose mass is not declared (water), kg/m^3.
inline constexpr double kDensity = 1000.0;

class Builder {
 public:
  Builder(const Document& doc,
          const BufferData& data,
          const LoadOptions& options,
          Problems* problems)
      : doc_(doc),
        options_(options),
        p_(problems),
        reader_(doc, data, options.limits, problems),
        decomposer_(options) {}

  /// The scene, or nullopt with problems.
  std::optional<SceneModel> build(const std::string& name);
  /// What the decomposition of non-convex meshes did (counts, cache warnings).
  Decomposer& decomposer() { return decomposer_; }

 private:
  struct Target;
  struct PendingPlane;
  /// The collider's frame in its body: X_BP (rigid) and S, the scale and shear folded into
  /// the points (A_BC = X_BP * S).
  struct Placement {
    Mat3 R{1.0}, S{1.0};
    Vec3 t{0.0};
  };
  /// Hulls already built for the same geometry under the same scale are shared (a field of
  /// identical pillars builds one hull). Key: kind (below), index, sub-index, S exactly.
  enum HullKind : int { kShapeHull, kNodeHull, kNodeSurface, kMeshHull, kMeshSurface, kPlainMesh };
  using HullKey = std::tuple<int, std::int32_t, std::int32_t, std::array<double, 9>>;
  struct Built {
    std::vector<std::shared_ptr<const geom::Polytope>> hulls;
    ShapeSource source = ShapeSource::kCode;
  };
  /// One primitive (or, for a mesh that is not convex, the pieces standing for it) to build: the
  /// node it belongs to, its collider (null for a plain model's mesh) and whether it is a trigger.
  struct Target {
    std::uint32_t body = 0;
    std::uint32_t node = 0;
    const ColliderDef* collider = nullptr;
    bool trigger = false;
  };
  struct PendingPlane {
    Target target;
    const ShapeDef* shape = nullptr;
  };
  /// What a primitive is built from: points in the collider's frame C, and for a mesh that must
  /// be convex (or be made so) its triangles.
  struct HullInput {
    ShapeSource source = ShapeSource::kCode;
    std::vector<Vec3> points_C;
    std::vector<std::uint32_t> triangles;
    bool surface = false;   ///< a mesh as a surface: flat ones get a thickness, others pieces
    std::string mesh_name;  ///< for messages; "" for shapes
    const HullKey* key = nullptr;  ///< share the result under this key
  };

  // build_scene.cpp
  bool computeWorld();
  void collectSceneNodes();
  bool checkProbeAndCounts(std::int32_t* probe_node);
  bool makeBodies(SceneModel& scene);
  void addPlainBodies(SceneModel& scene);
  void addAllColliders(SceneModel& scene);
  void addPlanes(SceneModel& scene);
  void applyExtras(SceneModel& scene, std::int32_t probe_node);
  void finishNotes(SceneModel& scene);
  /// The body a node belongs to (its motion ancestor's, or its root's static body), -1 if none.
  std::int32_t bodyIndexOf(std::size_t node) const;
  /// The body an extras.haptic `key` on `node` applies to; a problem when it belongs to none.
  std::optional<std::size_t> extrasBody(std::size_t node, const char* key);
  std::string where(std::size_t node) const { return nodeWhere(doc_, node); }

  // build_colliders.cpp
  /// Points and triangles of a geometry node's meshes (and its descendants'), in its frame.
  bool meshGeometry(std::uint32_t node, bool triangles, HullInput* in);
  /// The points (and triangles when wanted) of primitive k of `mesh`, placed by X.
  bool primitiveGeometry(std::uint32_t node,
                         const glm::dmat4& X,
                         std::size_t mesh,
                         std::size_t k,
                         bool triangles,
                         HullInput* in);
  void addCollider(SceneModel& scene, const Target& target, const ColliderDef& collider);
  void addShapeCollider(SceneModel& scene, const Target& target);
  bool shapePoints(const ShapeDef& shape, std::uint32_t node, std::vector<Vec3>* points);
  /// A mesh collider as a hull or a surface; `gather` fills the points (and triangles) and name.
  template <class Gather>
  void addMeshCollider(SceneModel& scene,
                       const Target& target,
                       bool hull,
                       std::int32_t index,
                       Gather gather);
  void addNodeMeshCollider(SceneModel& scene, const Target& target);
  void addOmiMeshCollider(SceneModel& scene, const Target& target, const ShapeDef& shape);
  void addPlane(SceneModel& scene,
                const PendingPlane& plane,
                const Vec3& lo,
                const Vec3& hi,
                bool have_box);
  Placement placement(const Body& body, std::uint32_t node) const;
  static HullKey hullKey(int kind, std::int32_t index, std::int32_t sub, const Mat3& S);
  void pushPrimitive(Body& body,
                     const Target& target,
                     ShapeSource source,
                     const Placement& at,
                     std::shared_ptr<const geom::Polytope> shape);
  bool reuse(SceneModel& scene, const Target& target, const Placement& at, const HullKey& key);
  /// Builds the primitive(s) of `in` on the target's body; false with a problem.
  bool finishPrimitive(SceneModel& scene, const Target& target, const Placement& at, HullInput in);
  /// A hull of points_P of at most max_hull_vertices vertices, or null with a problem naming
  /// `name`.
  std::shared_ptr<const geom::Polytope> hullOf(const std::vector<Vec3>& points_P,
                                               std::uint32_t node,
                                               const std::string& name);
  /// A surface mesh (in P) made convex: itself when convex, else the pieces standing for it.
  bool surfacePieces(const Target& target,
                     HullInput& in,
                     std::vector<Vec3>& points_P,
                     Built* built);
  bool withinTotalHullPoints(std::uint32_t node, std::uint64_t more);
  /// The decomposition's concavity for a mesh on `node`: `extras.haptic.concavity` of the node
  /// or its nearest ancestor that sets it, else the load's option.
  double concavityOf(std::uint32_t node) const;

  // build_physics.cpp
  void massProperties(Body& body, const MotionDef& motion, std::uint32_t node);
  /// Collision classes: each filter (and "unfiltered") with the bits it collides with.
  bool filterClasses();
  void buildJoints(SceneModel& scene);
  /// The joint's kind from its locked axes and limits.
  static void classifyJoint(Joint* joint);

  const Document& doc_;
  const LoadOptions& options_;
  Problems* p_;
  AccessorReader reader_;
  Decomposer decomposer_;
  std::vector<glm::dmat4> world_;           // per node
  std::vector<std::uint8_t> in_scene_;      // per node
  std::vector<std::uint8_t> in_trigger_;    // per node: under an OMI trigger body (same body)
  std::vector<std::int32_t> owner_;         // per node: node index of its body root, -1 static
  std::vector<std::int32_t> root_;          // per node: its top ancestor
  std::vector<std::int32_t> body_of_node_;  // per body-root node (or static root): body index
  std::vector<std::uint32_t> order_;        // scene nodes, parents before children
  std::vector<PendingPlane> planes_;
  std::uint64_t hull_points_ = 0;
  std::map<HullKey, Built> hulls_;
  std::optional<SphereGrid> grid_;
  std::optional<std::uint32_t> segments_;
  /// Per filter index + 1 (0: unfiltered): its class bit and the classes it collides with.
  std::vector<std::uint32_t> filter_group_, filter_mask_;
  std::vector<std::string> stand_ins_;  // meshes touched through pieces (notes)
  std::vector<std::string> thickened_;  // flat meshes given a thickness (notes)
  std::size_t plain_meshes_ = 0;        // a plain model's mesh nodes made static geometry
};

}  // namespace hapticd::scene::detail
