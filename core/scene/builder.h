#pragma once
/// \file
/// The scene loader's last pass (internal to hapticd_scene): a validated Document and its buffers
/// to a SceneModel. build_scene.cpp: world transforms, the scene's nodes, bodies, extras, the
/// plan; build_colliders.cpp: primitives from implicit shapes and meshes (hulls, convexity,
/// planes, shared hulls); build_physics.cpp: mass properties, collision filters, joints.
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
      : doc_(doc), options_(options), p_(problems), reader_(doc, data, options.limits, problems) {}

  /// The scene, or nullopt with problems.
  std::optional<SceneModel> build(const std::string& name);

 private:
  struct PendingPlane {
    std::uint32_t body = 0;
    std::uint32_t node = 0;
    const ShapeDef* shape = nullptr;
  };
  /// The collider's frame in its body: X_BP (rigid) and S, the scale and shear folded into
  /// the points (A_BC = X_BP * S).
  struct Placement {
    Mat3 R{1.0}, S{1.0};
    Vec3 t{0.0};
  };
  /// Hulls already built for the same geometry under the same scale are shared (a field of
  /// identical pillars builds one hull). Key: kind (0 shape, 1 mesh hull, 2 convex mesh), index,
  /// S exactly.
  using HullKey = std::tuple<int, std::int32_t, std::array<double, 9>>;

  // build_scene.cpp
  bool computeWorld();
  void collectSceneNodes();
  bool checkProbeAndCounts(std::int32_t* probe_node);
  bool makeBodies(SceneModel& scene);
  void addPlanes(SceneModel& scene);
  void applyExtras(SceneModel& scene, std::int32_t probe_node);
  /// The body a node belongs to (its motion ancestor's, or its root's static body), -1 if none.
  std::int32_t bodyIndexOf(std::size_t node) const;
  /// The body an extras.haptic `key` on `node` applies to; a problem when it belongs to none.
  std::optional<std::size_t> extrasBody(std::size_t node, const char* key);
  std::string where(std::size_t node) const { return nodeWhere(doc_, node); }

  // build_colliders.cpp
  /// Points and triangles of a geometry node's meshes (and its descendants'), in its frame.
  /// `triangles` null: only the vertices are wanted (a convex hull), any primitive mode.
  bool meshGeometry(std::uint32_t node,
                    std::vector<Vec3>* points,
                    std::vector<std::uint32_t>* triangles);
  bool primitiveGeometry(std::uint32_t node,
                         const glm::dmat4& X,
                         std::size_t mesh,
                         std::size_t k,
                         std::vector<Vec3>* points,
                         std::vector<std::uint32_t>* triangles);
  void addCollider(SceneModel& scene, std::uint32_t body, std::uint32_t node);
  void addShapeCollider(SceneModel& scene, std::uint32_t body, std::uint32_t node);
  bool shapePoints(const ShapeDef& shape, std::uint32_t node, std::vector<Vec3>* points);
  void addMeshCollider(Body& body, std::uint32_t node);
  void addPlane(SceneModel& scene,
                const PendingPlane& plane,
                const Vec3& lo,
                const Vec3& hi,
                bool have_box);
  Placement placement(const Body& body, std::uint32_t node) const;
  static HullKey hullKey(int kind, std::int32_t index, const Mat3& S);
  void pushPrimitive(Body& body,
                     std::uint32_t node,
                     ShapeSource source,
                     const Placement& at,
                     std::shared_ptr<const geom::Polytope> shape);
  bool reuse(Body& body,
             std::uint32_t node,
             ShapeSource source,
             const Placement& at,
             const HullKey& key);
  /// What a primitive is built from: points in the collider's frame C, and for a mesh that must
  /// be convex its triangles.
  struct HullInput {
    ShapeSource source = ShapeSource::kCode;
    std::vector<Vec3> points_C;
    const std::vector<std::uint32_t>* triangles = nullptr;  ///< null: any hull will do
    std::string mesh_name;                                  ///< for messages; "" for shapes
    const HullKey* key = nullptr;                           ///< share the hull under this key
  };
  bool finishPrimitive(Body& body, std::uint32_t node, const Placement& at, const HullInput& in);
  bool withinTotalHullPoints(std::uint32_t node, std::uint64_t more);

  // build_physics.cpp
  void massProperties(Body& body, const MotionDef& motion, std::uint32_t node);
  void filterBits(SceneModel& scene);
  void buildJoints(SceneModel& scene);
  /// The joint's kind from its locked axes; false (with a problem) when neither fixed nor hinge.
  bool classifyJoint(Joint* joint, const std::string& where);

  const Document& doc_;
  const LoadOptions& options_;
  Problems* p_;
  AccessorReader reader_;
  std::vector<glm::dmat4> world_;           // per node
  std::vector<std::uint8_t> in_scene_;      // per node
  std::vector<std::int32_t> owner_;         // per node: node index of its body root, -1 static
  std::vector<std::int32_t> root_;          // per node: its top ancestor
  std::vector<std::int32_t> body_of_node_;  // per body-root node (or static root): body index
  std::vector<std::uint32_t> order_;        // scene nodes, parents before children
  std::vector<PendingPlane> planes_;
  std::uint64_t hull_points_ = 0;
  std::map<HullKey, std::shared_ptr<const geom::Polytope>> hulls_;
  std::optional<SphereGrid> grid_;
  std::optional<std::uint32_t> segments_;
};

}  // namespace hapticd::scene::detail
