// The model builder's primitives: implicit shapes tessellated, mesh colliders (hull or convex),
// planes, and hulls shared between identical colliders (builder.h).
#include <cmath>

#include "core/scene/builder.h"

namespace hapticd::scene::detail {
namespace {

/// A mesh collider without convexHull is convex when no triangle plane has a vertex farther in
/// front of it than this fraction of the mesh's radius (float32 vertex data rounds at ~1e-7).
constexpr double kConvexTolerance = 1e-5;
/// An infinite plane becomes a box this many scene extents wide on each side.
constexpr double kPlaneExtents = 10.0;

}  // namespace

bool Builder::withinTotalHullPoints(std::uint32_t node, std::uint64_t more) {
  if (hull_points_ + more <= options_.limits.max_total_hull_input_points)
    return true;
  p_->add(where(node), "the scene's colliders have more than max_total_hull_input_points (" +
                           std::to_string(options_.limits.max_total_hull_input_points) +
                           ") hull input points in all");
  return false;
}

bool Builder::primitiveGeometry(std::uint32_t node,
                                const glm::dmat4& X,
                                std::size_t mi,
                                std::size_t k,
                                std::vector<Vec3>* points,
                                std::vector<std::uint32_t>* triangles) {
  const MeshPrimitiveDef& prim = doc_.meshes[mi].primitives[k];
  const std::string use = meshWhere(doc_, mi) + " primitive " + std::to_string(k);
  if (triangles && prim.mode != 4) {
    p_->add(use, "mode " + std::to_string(prim.mode) +
                     " is not TRIANGLES (4), the only mode a convex mesh collider may use "
                     "(with convexHull any mode will do)");
    return false;
  }
  if (prim.position < 0) {
    p_->add(use, "has no POSITION attribute");
    return false;
  }
  const std::size_t first = points->size();
  if (!withinTotalHullPoints(node, doc_.accessors[static_cast<std::size_t>(prim.position)].count))
    return false;
  if (!reader_.readPositions(static_cast<std::size_t>(prim.position), use + " POSITION", points))
    return false;
  const std::size_t count = points->size() - first;
  hull_points_ += count;
  if (points->size() > options_.limits.max_hull_input_points) {
    p_->add(where(node), "collider mesh has " + std::to_string(points->size()) +
                             " vertices, more than max_hull_input_points (" +
                             std::to_string(options_.limits.max_hull_input_points) + ")");
    return false;
  }
  for (std::size_t v = first; v < points->size(); ++v)
    (*points)[v] = Vec3(X * glm::dvec4((*points)[v], 1.0));
  if (!triangles)
    return true;  // a hull needs only the vertices
  if (prim.indices >= 0) {
    std::vector<std::uint32_t> local;
    if (!reader_.readIndices(static_cast<std::size_t>(prim.indices), count, use, &local))
      return false;
    for (std::uint32_t v : local)
      triangles->push_back(static_cast<std::uint32_t>(first) + v);
    return true;
  }
  if (count % 3 != 0) {
    p_->add(use, "has " + std::to_string(count) +
                     " vertices and no indices: not a whole number of triangles");
    return false;
  }
  for (std::size_t v = 0; v < count; ++v)
    triangles->push_back(static_cast<std::uint32_t>(first + v));
  return true;
}

bool Builder::meshGeometry(std::uint32_t node,
                           std::vector<Vec3>* points,
                           std::vector<std::uint32_t>* triangles) {
  // the geometry node's subtree, each mesh placed by its transform relative to the geometry node
  struct Item {
    std::uint32_t node;
    glm::dmat4 X;
  };
  std::vector<Item> stack{{node, glm::dmat4(1.0)}};
  bool any = false;
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const NodeDef& def = doc_.nodes[item.node];
    for (std::uint32_t child : def.children)
      stack.push_back({child, item.X * doc_.nodes[child].local()});
    if (def.mesh < 0)
      continue;
    const auto mi = static_cast<std::size_t>(def.mesh);
    for (std::size_t k = 0; k < doc_.meshes[mi].primitives.size(); ++k) {
      if (!primitiveGeometry(node, item.X, mi, k, points, triangles))
        return false;
      any = true;
    }
  }
  if (!any) {
    p_->add(where(node), "is a collider geometry node with no mesh (in it or its children)");
    return false;
  }
  return true;
}

Builder::Placement Builder::placement(const Body& body, std::uint32_t node) const {
  // collider frame C -> body frame B: A_BC = X_WB^-1 * W_C (with scale); its rigid part is
  // X_BP, the rest (scale, shear) is folded into the points: p_P = S * p_C
  const Transform X_BW = body.X_WB.toTransform().inverse();
  const glm::dmat4& W = world_[node];
  Placement at;
  at.t = X_BW.apply(Vec3(W[3]));
  splitRigid(X_BW.R * Mat3(W), &at.R, &at.S);
  return at;
}

Builder::HullKey Builder::hullKey(int kind, std::int32_t index, const Mat3& S) {
  std::array<double, 9> m{};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r)
      m[static_cast<std::size_t>(3 * c + r)] = S[c][r];
  }
  return {kind, index, m};
}

void Builder::pushPrimitive(Body& body,
                            std::uint32_t node,
                            ShapeSource source,
                            const Placement& at,
                            std::shared_ptr<const geom::Polytope> shape) {
  Primitive prim;
  prim.shape = std::move(shape);
  prim.X_BP.translation = at.t;
  prim.X_BP.rotation = glm::normalize(glm::quat_cast(at.R));
  prim.source = source;
  prim.node = static_cast<std::int32_t>(node);
  prim.material = doc_.nodes[node].collider->material;
  body.primitives.push_back(std::move(prim));
}

bool Builder::reuse(Body& body,
                    std::uint32_t node,
                    ShapeSource source,
                    const Placement& at,
                    const HullKey& key) {
  const auto it = hulls_.find(key);
  if (it == hulls_.end())
    return false;
  pushPrimitive(body, node, source, at, it->second);
  return true;
}

bool Builder::finishPrimitive(Body& body,
                              std::uint32_t node,
                              const Placement& at,
                              const HullInput& in) {
  std::vector<Vec3> points_P;
  points_P.reserve(in.points_C.size());
  for (const Vec3& p : in.points_C)
    points_P.push_back(at.S * p);
  if (!withinTotalHullPoints(node, 0))
    return false;
  geom::HullOptions hull;
  hull.max_vertices = options_.limits.max_hull_vertices;
  hull.max_input_points = options_.limits.max_hull_input_points;
  auto poly = geom::Polytope::fromPoints(points_P, hull);
  if (!poly) {
    p_->add(where(node), (in.mesh_name.empty() ? "collider" : in.mesh_name) +
                             ": cannot build a convex hull: " + poly.error().message);
    return false;
  }
  if (in.triangles) {
    const double violation = convexityViolation(poly.value(), points_P, *in.triangles);
    if (violation > kConvexTolerance * poly.value().radius()) {
      p_->add(where(node), in.mesh_name +
                               ": non-convex mesh collider without convexHull (convex "
                               "decomposition is not supported); a vertex lies " +
                               formatNumber(violation) + " in front of a triangle's plane");
      return false;
    }
  }
  auto shape = std::make_shared<const geom::Polytope>(std::move(poly).value());
  if (in.key)
    hulls_.emplace(*in.key, shape);
  pushPrimitive(body, node, in.source, at, std::move(shape));
  return true;
}

void Builder::addCollider(SceneModel& scene, std::uint32_t body_index, std::uint32_t node) {
  const Mat3 L(world_[node]);
  if (glm::length(L[0]) == 0.0 && glm::length(L[1]) == 0.0 && glm::length(L[2]) == 0.0)
    return;  // scale zero on every axis: the collider is disabled (KHR_physics_rigid_bodies)
  if (doc_.nodes[node].collider->shape >= 0)
    addShapeCollider(scene, body_index, node);
  else
    addMeshCollider(scene.bodies[body_index], node);
}

namespace {

/// The value in `slot`, made by `make` (a Result) the first time; false with a problem when it
/// cannot be made.
template <class T, class Make>
bool cached(std::optional<T>* slot, Make make, Problems* problems, const std::string& where) {
  if (*slot)
    return true;
  auto made = make();
  if (!made) {
    problems->add(where, made.error().message);
    return false;
  }
  *slot = made.value();
  return true;
}

}  // namespace

bool Builder::shapePoints(const ShapeDef& shape, std::uint32_t node, std::vector<Vec3>* points) {
  const double tol = options_.limits.tessellation_tolerance;
  const std::uint32_t max_v = options_.limits.max_hull_vertices;
  const auto grid = [&] {
    return cached(
        &grid_, [&] { return sphereGridFor(tol, max_v); }, p_, where(node));
  };
  switch (shape.type) {
    case ShapeType::kBox:
      *points = boxPoints(shape.size);
      return true;
    case ShapeType::kSphere:
      if (!grid())
        return false;
      *points = spherePoints(shape.radius, *grid_);
      return true;
    case ShapeType::kCapsule:
      if (!grid())
        return false;
      *points = capsulePoints(shape.height, shape.radius_top, shape.radius_bottom, *grid_);
      return true;
    case ShapeType::kCylinder:
      if (!cached(
              &segments_, [&] { return circleSegmentsFor(tol, max_v); }, p_, where(node)))
        return false;
      *points = cylinderPoints(shape.height, shape.radius_top, shape.radius_bottom, *segments_);
      return true;
    case ShapeType::kPlane:
      return false;
  }
  return false;
}

void Builder::addShapeCollider(SceneModel& scene, std::uint32_t body_index, std::uint32_t node) {
  Body& body = scene.bodies[body_index];
  const ColliderDef& collider = *doc_.nodes[node].collider;
  const ShapeDef& shape = doc_.shapes[static_cast<std::size_t>(collider.shape)];
  if (shape.type == ShapeType::kPlane) {
    if (body.motion != Motion::kStatic) {
      p_->add(where(node),
              "a plane collider must be static (it is part of moving body '" + body.name + "')");
    } else if (shape.double_sided) {
      p_->add(where(node),
              "double-sided planes are not supported (a plane is the solid half-space below it)");
    } else {
      planes_.push_back({body_index, node, &shape});
    }
    return;
  }
  static constexpr ShapeSource kSources[] = {ShapeSource::kBox, ShapeSource::kSphere,
                                             ShapeSource::kCapsule, ShapeSource::kCylinder};
  const ShapeSource source = kSources[static_cast<int>(shape.type)];
  const Placement at = placement(body, node);
  const HullKey key = hullKey(0, collider.shape, at.S);
  if (reuse(body, node, source, at, key))
    return;
  HullInput in;
  in.source = source;
  in.key = &key;
  if (!shapePoints(shape, node, &in.points_C))
    return;
  hull_points_ += in.points_C.size();
  finishPrimitive(body, node, at, in);
}

void Builder::addMeshCollider(Body& body, std::uint32_t node) {
  const ColliderDef& collider = *doc_.nodes[node].collider;
  const auto g = static_cast<std::uint32_t>(collider.geometry_node);
  const Placement at = placement(body, node);
  const HullKey key = hullKey(collider.convex_hull ? 1 : 2, collider.geometry_node, at.S);
  const ShapeSource source =
      collider.convex_hull ? ShapeSource::kMeshHull : ShapeSource::kConvexMesh;
  if (reuse(body, node, source, at, key))
    return;
  std::vector<std::uint32_t> triangles;
  HullInput in;
  in.source = source;
  in.triangles = collider.convex_hull ? nullptr : &triangles;
  in.key = &key;
  if (!meshGeometry(g, &in.points_C, collider.convex_hull ? nullptr : &triangles))
    return;
  in.mesh_name = doc_.nodes[g].mesh >= 0
                     ? meshWhere(doc_, static_cast<std::size_t>(doc_.nodes[g].mesh))
                     : "the meshes under " + where(g);
  finishPrimitive(body, node, at, in);
}

void Builder::addPlane(SceneModel& scene,
                       const PendingPlane& plane,
                       const Vec3& lo,
                       const Vec3& hi,
                       bool have_box) {
  // a plane is the half-space y <= 0 of its node; it becomes a box whose top face is the plane:
  // finite planes sizeX x sizeZ and 0.1 * min(sizeX, sizeZ) deep; infinite ones 2 * 10 scene
  // extents wide, centred under the scene, one scene extent deep
  const glm::dmat4& W = world_[plane.node];
  const Mat3 L(W);
  const double det = glm::determinant(L);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
    p_->add(where(plane.node), "plane collider with a singular scale");
    return;
  }
  const double s_min =
      std::max(1e-300, std::min({glm::length(L[0]), glm::length(L[1]), glm::length(L[2])}));
  Vec3 centre_C{0.0}, half{0.0};
  double depth = 0.0;
  if (plane.shape->size_x) {
    half = {0.5 * *plane.shape->size_x, 0.0, 0.5 * *plane.shape->size_z};
    depth = 0.1 * std::min(*plane.shape->size_x, *plane.shape->size_z);
  } else {
    const double extent = have_box ? glm::length(hi - lo) : 1.0;
    const Vec3 centre_W = have_box ? 0.5 * (lo + hi) : Vec3(W[3]);
    centre_C = Vec3(glm::inverse(W) * glm::dvec4(centre_W, 1.0));
    half = Vec3{kPlaneExtents * extent / s_min, 0.0, kPlaneExtents * extent / s_min};
    depth = extent / s_min;
  }
  HullInput in;
  in.source = ShapeSource::kPlane;
  for (int i = 0; i < 8; ++i) {
    in.points_C.push_back({centre_C.x + ((i & 1) ? half.x : -half.x), (i & 2) ? 0.0 : -depth,
                           centre_C.z + ((i & 4) ? half.z : -half.z)});
  }
  Body& body = scene.bodies[plane.body];
  finishPrimitive(body, plane.node, placement(body, plane.node), in);
}

}  // namespace hapticd::scene::detail
