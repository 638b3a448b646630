// The model builder's primitives: implicit shapes tessellated, meshes as hulls or as surfaces
// (convex, or the pieces standing for a mesh that is not), flat surfaces given a thickness,
// planes, and hulls shared between identical colliders (builder.h).
#include <cmath>

#include "core/scene/builder.h"
#include "core/scene/decompose.h"

namespace hapticd::scene::detail {
namespace {

/// A surface mesh is convex when no triangle plane has a vertex farther in front of it than this
/// fraction of the mesh's radius (float32 vertex data rounds at ~1e-7).
constexpr double kConvexTolerance = 1e-5;
/// An infinite plane becomes a box this many scene extents wide on each side.
constexpr double kPlaneExtents = 10.0;
/// A surface whose points lie within this fraction of its size of one plane is flat...
constexpr double kFlatTolerance = 1e-6;
/// ... and is given this fraction of its size as a thickness, behind its front faces.
constexpr double kFlatThickness = 0.05;

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
                                bool triangles,
                                HullInput* in) {
  const MeshPrimitiveDef& prim = doc_.meshes[mi].primitives[k];
  const std::string use = meshWhere(doc_, mi) + " primitive " + std::to_string(k);
  if (triangles && (prim.mode < 4 || prim.mode > 6)) {
    p_->add(use, "mode " + std::to_string(prim.mode) +
                     " is not TRIANGLES (4), TRIANGLE_STRIP (5) or TRIANGLE_FAN (6), the modes of "
                     "a mesh collider without convexHull (with convexHull any mode will do)");
    return false;
  }
  if (prim.position < 0) {
    p_->add(use, "has no POSITION attribute");
    return false;
  }
  std::vector<Vec3>& points = in->points_C;
  if (!withinTotalHullPoints(node, doc_.accessors[static_cast<std::size_t>(prim.position)].count))
    return false;
  PrimitiveReading reading;
  if (!readPrimitivePoints(reader_, prim, use, triangles, &points, &reading))
    return false;
  hull_points_ += reading.count;
  if (points.size() > options_.limits.max_hull_input_points) {
    p_->add(where(node), "collider mesh has " + std::to_string(points.size()) +
                             " vertices, more than max_hull_input_points (" +
                             std::to_string(options_.limits.max_hull_input_points) + ")");
    return false;
  }
  for (std::size_t v = reading.first; v < points.size(); ++v)
    points[v] = Vec3(X * glm::dvec4(points[v], 1.0));
  if (!triangles)
    return true;  // a hull needs only the vertices
  return readPrimitiveTriangles(reader_, prim, use, reading, std::nullopt, p_, &in->triangles);
}

bool Builder::meshGeometry(std::uint32_t node, bool triangles, HullInput* in) {
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
      if (!primitiveGeometry(node, item.X, mi, k, triangles, in))
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

Builder::HullKey Builder::hullKey(int kind, std::int32_t index, std::int32_t sub, const Mat3& S) {
  std::array<double, 9> m{};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r)
      m[3 * static_cast<std::size_t>(c) + static_cast<std::size_t>(r)] = S[c][r];
  }
  return {kind, index, sub, m};
}

void Builder::pushPrimitive(Body& body,
                            const Target& target,
                            ShapeSource source,
                            const Placement& at,
                            std::shared_ptr<const geom::Polytope> shape) {
  Primitive prim;
  prim.shape = std::move(shape);
  prim.X_BP.translation = at.t;
  prim.X_BP.rotation = glm::normalize(glm::quat_cast(at.R));
  prim.source = source;
  prim.node = static_cast<std::int32_t>(target.node);
  prim.material = target.collider ? target.collider->material : -1;
  prim.trigger = target.trigger;
  const std::size_t filter =
      target.collider ? static_cast<std::size_t>(target.collider->filter + 1) : 0;
  prim.group = target.trigger ? 0u : filter_group_[filter];
  prim.mask = target.trigger ? 0u : filter_mask_[filter];
  body.primitives.push_back(std::move(prim));
}

bool Builder::reuse(SceneModel& scene,
                    const Target& target,
                    const Placement& at,
                    const HullKey& key) {
  const auto it = hulls_.find(key);
  if (it == hulls_.end())
    return false;
  for (const auto& hull : it->second.hulls)
    pushPrimitive(scene.bodies[target.body], target, it->second.source, at, hull);
  return true;
}

std::shared_ptr<const geom::Polytope> Builder::hullOf(const std::vector<Vec3>& points_P,
                                                      std::uint32_t node,
                                                      const std::string& name) {
  geom::HullOptions hull;
  hull.max_vertices = options_.limits.max_hull_vertices;
  hull.max_input_points = options_.limits.max_hull_input_points;
  auto poly = geom::Polytope::fromPoints(points_P, hull);
  if (!poly) {
    p_->add(where(node), (name.empty() ? "collider" : name) +
                             ": cannot build a convex hull: " + poly.error().message);
    return nullptr;
  }
  return std::make_shared<const geom::Polytope>(std::move(poly).value());
}

bool Builder::surfacePieces(const Target& target,
                            HullInput& in,
                            std::vector<Vec3>& points_P,
                            Built* built) {
  // a flat surface (a floor, a sign) is given a thickness behind its front faces; its outline
  // is convex when its hull's area is the triangles' area
  double flat_area = 0.0, thickness = 0.0;
  if (const auto n = flatNormal(points_P, in.triangles, kFlatTolerance)) {
    thickness = kFlatThickness * boundingDiagonal(points_P);
    flat_area = thickenFlat(*n, thickness, &points_P, &in.triangles);
    thickened_.push_back(in.mesh_name + " (" + where(target.node) +
                         "): flat, given a thickness of " + formatNumber(thickness) +
                         " m behind its front faces");
  }
  const std::string name = in.mesh_name + " (" + where(target.node) + ")";
  const double concavity = concavityOf(target.node);
  // the hulls of `pieces` (the whole mesh's `hull` reused when a piece is the whole mesh)
  const auto usePieces = [&](const ConvexPieces& pieces,
                             const std::shared_ptr<const geom::Polytope>& hull) {
    built->source = ShapeSource::kMeshPiece;
    for (const std::vector<Vec3>& piece : pieces.pieces) {
      if (hull && piece == points_P) {
        built->hulls.push_back(hull);  // the hull already built
        continue;
      }
      hull_points_ += piece.size();
      auto h = hullOf(piece, target.node, in.mesh_name);
      if (!h || !withinTotalHullPoints(target.node, 0))
        return false;
      built->hulls.push_back(std::move(h));
    }
    stand_ins_.push_back(name + ": " + pieces.method);
    return true;
  };
  // a mesh decomposed before with these options (only such meshes have an entry): its pieces
  // from the cache, without the whole mesh's hull and convexity test
  if (auto cached = decomposer_.cachedPieces(points_P, in.triangles, concavity, name))
    return usePieces(*cached, nullptr);
  // the whole mesh's hull with no vertex limit: a mesh whose hull has more vertices than
  // max_hull_vertices (a dense scan) is decomposed, its pieces within the limit
  geom::HullOptions unlimited;
  unlimited.max_vertices = options_.limits.max_hull_input_points;
  unlimited.max_input_points = options_.limits.max_hull_input_points;
  auto whole = geom::Polytope::fromPoints(points_P, unlimited);
  if (!whole) {
    p_->add(where(target.node), (in.mesh_name.empty() ? "collider" : in.mesh_name) +
                                    ": cannot build a convex hull: " + whole.error().message);
    return false;
  }
  auto hull = std::make_shared<const geom::Polytope>(std::move(whole).value());
  const bool within = hull->vertices().size() <= options_.limits.max_hull_vertices;
  const bool convex =
      thickness > 0.0
          ? polytopeIntegrals(*hull, Transform{}).volume <= (1.0 + 1e-3) * flat_area * thickness
          : convexityViolation(*hull, points_P, in.triangles) <= kConvexTolerance * hull->radius();
  if (convex && within) {
    built->source = ShapeSource::kConvexMesh;
    built->hulls = {std::move(hull)};
    return true;
  }
  const std::string why = convex ? "convex, but its hull has more than " +
                                       std::to_string(options_.limits.max_hull_vertices) +
                                       " vertices (max_hull_vertices)"
                                 : std::string("not convex");
  return usePieces(decomposer_.convexPieces(points_P, in.triangles, concavity, name, why),
                   within ? hull : nullptr);
}

double Builder::concavityOf(std::uint32_t node) const {
  for (std::int32_t n = static_cast<std::int32_t>(node); n >= 0;
       n = doc_.nodes[static_cast<std::size_t>(n)].parent) {
    if (const auto& c = doc_.nodes[static_cast<std::size_t>(n)].concavity)
      return *c;
  }
  return options_.decomposition.concavity;
}

bool Builder::finishPrimitive(SceneModel& scene,
                              const Target& target,
                              const Placement& at,
                              HullInput in) {
  std::vector<Vec3> points_P;
  points_P.reserve(in.points_C.size());
  for (const Vec3& p : in.points_C)
    points_P.push_back(at.S * p);
  if (!withinTotalHullPoints(target.node, 0))
    return false;
  Built built;
  built.source = in.source;
  if (in.surface) {
    if (!surfacePieces(target, in, points_P, &built))
      return false;
  } else {
    auto hull = hullOf(points_P, target.node, in.mesh_name);
    if (!hull)
      return false;
    built.hulls.push_back(std::move(hull));
  }
  for (const auto& hull : built.hulls)
    pushPrimitive(scene.bodies[target.body], target, built.source, at, hull);
  if (in.key)
    hulls_.emplace(*in.key, std::move(built));
  return true;
}

void Builder::addCollider(SceneModel& scene, const Target& target, const ColliderDef& collider) {
  const Mat3 L(world_[target.node]);
  if (glm::length(L[0]) == 0.0 && glm::length(L[1]) == 0.0 && glm::length(L[2]) == 0.0)
    return;  // scale zero on every axis: the collider is disabled (KHR_physics_rigid_bodies)
  if (collider.shape < 0) {
    addNodeMeshCollider(scene, target);
    return;
  }
  const ShapeDef& shape = doc_.shapes[static_cast<std::size_t>(collider.shape)];
  if (shape.type == ShapeType::kMesh)
    addOmiMeshCollider(scene, target, shape);
  else
    addShapeCollider(scene, target);
}

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
    case ShapeType::kMesh:
      return false;
  }
  return false;
}

void Builder::addShapeCollider(SceneModel& scene, const Target& target) {
  Body& body = scene.bodies[target.body];
  const std::int32_t index = target.collider->shape;
  const ShapeDef& shape = doc_.shapes[static_cast<std::size_t>(index)];
  if (shape.type == ShapeType::kPlane) {
    if (body.motion != Motion::kStatic) {
      p_->add(where(target.node),
              "a plane collider must be static (it is part of moving body '" + body.name + "')");
    } else if (shape.double_sided) {
      p_->add(where(target.node),
              "double-sided planes are not supported (a plane is the solid half-space below it)");
    } else {
      planes_.push_back({target, &shape});
    }
    return;
  }
  static constexpr ShapeSource kSources[] = {ShapeSource::kBox, ShapeSource::kSphere,
                                             ShapeSource::kCapsule, ShapeSource::kCylinder};
  const Placement at = placement(body, target.node);
  const HullKey key = hullKey(kShapeHull, index, 0, at.S);
  if (reuse(scene, target, at, key))
    return;
  HullInput in;
  in.source = kSources[static_cast<int>(shape.type)];
  in.key = &key;
  if (!shapePoints(shape, target.node, &in.points_C))
    return;
  hull_points_ += in.points_C.size();
  finishPrimitive(scene, target, at, std::move(in));
}

template <class Gather>
void Builder::addMeshCollider(SceneModel& scene,
                              const Target& target,
                              bool hull,
                              std::int32_t index,
                              Gather gather) {
  const Placement at = placement(scene.bodies[target.body], target.node);
  const bool node = target.collider->shape < 0;
  const HullKind kind =
      node ? (hull ? kNodeHull : kNodeSurface) : (hull ? kMeshHull : kMeshSurface);
  const HullKey key = hullKey(kind, index, 0, at.S);
  if (reuse(scene, target, at, key))
    return;
  HullInput in;
  in.source = hull ? ShapeSource::kMeshHull : ShapeSource::kConvexMesh;
  in.surface = !hull;
  in.key = &key;
  if (gather(&in))
    finishPrimitive(scene, target, at, std::move(in));
}

void Builder::addNodeMeshCollider(SceneModel& scene, const Target& target) {
  // KHR geometry.node: the meshes of the node and its descendants
  const auto g = static_cast<std::uint32_t>(target.collider->geometry_node);
  addMeshCollider(scene, target, target.collider->convex_hull, target.collider->geometry_node,
                  [&](HullInput* in) {
                    in->mesh_name =
                        doc_.nodes[g].mesh >= 0
                            ? meshWhere(doc_, static_cast<std::size_t>(doc_.nodes[g].mesh))
                            : "the meshes under " + where(g);
                    return meshGeometry(g, in->surface, in);
                  });
}

void Builder::addOmiMeshCollider(SceneModel& scene, const Target& target, const ShapeDef& shape) {
  // OMI convex and trimesh shapes: one glTF mesh, in the collider node's frame
  const auto mi = static_cast<std::size_t>(shape.mesh);
  addMeshCollider(scene, target, shape.convex_hull, shape.mesh, [&](HullInput* in) {
    in->mesh_name = meshWhere(doc_, mi);
    for (std::size_t k = 0; k < doc_.meshes[mi].primitives.size(); ++k) {
      if (!primitiveGeometry(target.node, glm::dmat4(1.0), mi, k, in->surface, in))
        return false;
    }
    return true;
  });
}

void Builder::addPlane(SceneModel& scene,
                       const PendingPlane& plane,
                       const Vec3& lo,
                       const Vec3& hi,
                       bool have_box) {
  // a plane is the half-space y <= 0 of its node; it becomes a box whose top face is the plane:
  // finite planes sizeX x sizeZ and 0.1 * min(sizeX, sizeZ) deep; infinite ones 2 * 10 scene
  // extents wide, centred under the scene, one scene extent deep
  const std::uint32_t node = plane.target.node;
  const glm::dmat4& W = world_[node];
  const Mat3 L(W);
  const double det = glm::determinant(L);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
    p_->add(where(node), "plane collider with a singular scale");
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
  finishPrimitive(scene, plane.target, placement(scene.bodies[plane.target.body], node),
                  std::move(in));
}

}  // namespace hapticd::scene::detail
