#include "core/scene/loader.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>

#include "core/geometry/rotation.h"
#include "core/scene/gltf_document.h"
#include "core/scene/shapes.h"

namespace hapticd::scene {
namespace {

using detail::Document;
using detail::NodeDef;
using detail::Problems;
using detail::ShapeType;
using geom::Quat;
using geom::Transform;

/// Density of bodies whose mass is not declared (water), kg/m^3.
constexpr double kDensity = 1000.0;
/// A mesh collider without convexHull is convex when no triangle plane has a vertex farther in
/// front of it than this fraction of the mesh's radius (float32 vertex data rounds at ~1e-7).
constexpr double kConvexTolerance = 1e-5;
/// An infinite plane becomes a box this many scene extents wide on each side.
constexpr double kPlaneExtents = 10.0;

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r]))
        return false;
    }
  }
  return true;
}
using geom::finite;
bool finite(const Mat3& m) {
  return finite(m[0]) && finite(m[1]) && finite(m[2]);
}

// ---- tinygltf with no file access except inside the allowed folder --------------------------

struct FsPolicy {
  const LoadOptions* options = nullptr;
};

bool fsFileExists(const std::string& path, void* user) {
  const auto* policy = static_cast<const FsPolicy*>(user);
  if (!policy->options->allowed_uri_dir)
    return false;
  // tinygltf joins base_dir (the allowed folder) and the URI; check the relative part again
  const std::string base = policy->options->allowed_uri_dir->string();
  if (path.rfind(base, 0) != 0)
    return false;
  std::string rel = path.substr(base.size());
  while (!rel.empty() && (rel.front() == '/' || rel.front() == '\\'))
    rel.erase(0, 1);
  std::string why;
  return detail::resolveUri(rel, *policy->options, &why).has_value();
}

std::string fsExpandFilePath(const std::string& path, void*) {
  return path;
}  // no wordexp

bool fsReadWholeFile(std::vector<unsigned char>* out,
                     std::string* err,
                     const std::string& path,
                     void* user) {
  const auto* policy = static_cast<const FsPolicy*>(user);
  if (!fsFileExists(path, user)) {
    if (err)
      *err += "external file refused: " + path + "\n";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return false;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(std::max<std::streamoff>(in.tellg(), 0));
  if (size > policy->options->limits.max_file_bytes) {
    if (err)
      *err += "external file " + path + " exceeds max_file_bytes\n";
    return false;
  }
  in.seekg(0);
  out->resize(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size));
  return static_cast<bool>(in);
}

bool fsWriteWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
  return false;
}

// images are never decoded: the scene needs none
bool noImage(tinygltf::Image*,
             const int,
             std::string*,
             std::string*,
             int,
             int,
             const unsigned char*,
             int,
             void*) {
  return true;
}

// ---- the model builder -------------------------------------------------------------------------

class Builder {
 public:
  Builder(const Document& doc,
          const tinygltf::Model& model,
          const LoadOptions& options,
          Problems* problems)
      : doc_(doc), model_(model), options_(options), p_(problems) {}

  std::optional<SceneModel> build(const std::string& name);

 private:
  struct Collider {
    std::uint32_t node = 0;
    std::int32_t body = -1;
  };
  struct PendingPlane {
    std::uint32_t body = 0;
    std::uint32_t node = 0;
    const detail::ShapeDef* shape = nullptr;
  };

  void computeWorld();
  std::string where(std::size_t node) const { return detail::nodeWhere(doc_, node); }
  bool readPositions(std::size_t accessor, const std::string& use, std::vector<Vec3>* out);
  bool readIndices(std::size_t accessor,
                   std::size_t vertex_count,
                   const std::string& use,
                   std::vector<std::uint32_t>* out);
  /// Points and triangles of a geometry node's meshes (and its descendants'), in its frame.
  /// `triangles` null: only the vertices are wanted (a convex hull), any primitive mode.
  bool meshGeometry(std::uint32_t node,
                    std::vector<Vec3>* points,
                    std::vector<std::uint32_t>* triangles);
  void addCollider(SceneModel& scene, std::uint32_t body, std::uint32_t node);
  void addPlane(SceneModel& scene,
                const PendingPlane& plane,
                const Vec3& lo,
                const Vec3& hi,
                bool have_box);
  /// The collider's frame in its body: X_BP (rigid) and S, the scale and shear folded into
  /// the points (A_BC = X_BP * S).
  struct Placement {
    Mat3 R{1.0}, S{1.0};
    Vec3 t{0.0};
  };
  Placement placement(const Body& body, std::uint32_t node) const;
  /// Hulls already built for the same geometry under the same scale are shared (a field of
  /// identical pillars builds one hull). Key: kind (0 shape, 1 mesh hull, 2 convex mesh), index,
  /// S exactly.
  using HullKey = std::tuple<int, std::int32_t, std::array<double, 9>>;
  static HullKey hullKey(int kind, std::int32_t index, const Mat3& S);
  bool reuse(Body& body,
             std::uint32_t node,
             ShapeSource source,
             const Placement& at,
             const HullKey& key);
  bool finishPrimitive(Body& body,
                       std::uint32_t node,
                       ShapeSource source,
                       const Placement& at,
                       const std::vector<Vec3>& points_C,
                       const std::vector<std::uint32_t>* tris,
                       const std::string& mesh_name,
                       const HullKey* key);
  void massProperties(Body& body, const detail::MotionDef& motion, std::uint32_t node);
  void buildJoints(SceneModel& scene);
  void filterBits(SceneModel& scene);

  const Document& doc_;
  const tinygltf::Model& model_;
  const LoadOptions& options_;
  Problems* p_;
  std::vector<glm::dmat4> world_;           // per node
  std::vector<std::uint8_t> in_scene_;      // per node
  std::vector<std::int32_t> owner_;         // per node: node index of its body root, -1 static
  std::vector<std::int32_t> root_;          // per node: its top ancestor
  std::vector<std::int32_t> body_of_node_;  // per body-root node (or static root): body index
  std::vector<std::uint32_t> order_;        // scene nodes, parents before children
  std::vector<PendingPlane> planes_;
  std::uint64_t hull_points_ = 0;
  std::map<HullKey, std::shared_ptr<const geom::Polytope>> hulls_;
  std::optional<detail::SphereGrid> grid_;
  std::optional<std::uint32_t> segments_;
};

void Builder::computeWorld() {
  const std::size_t n = doc_.nodes.size();
  world_.assign(n, glm::dmat4(1.0));
  std::vector<std::uint8_t> done(n, 0);
  std::vector<std::size_t> chain;
  for (std::size_t i = 0; i < n; ++i) {
    chain.clear();
    std::size_t k = i;
    while (!done[k]) {
      chain.push_back(k);
      if (doc_.nodes[k].parent < 0)
        break;
      k = static_cast<std::size_t>(doc_.nodes[k].parent);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const NodeDef& node = doc_.nodes[*it];
      world_[*it] = node.parent < 0 ? node.local()
                                    : world_[static_cast<std::size_t>(node.parent)] * node.local();
      done[*it] = 1;
    }
  }
}

bool Builder::readPositions(std::size_t index, const std::string& use, std::vector<Vec3>* out) {
  const detail::AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  if (a.type != "VEC3" || a.component_type != 5126 || a.normalized) {
    p_->add(w, use + " must be VEC3 of FLOAT (5126), got " + a.type + " of " +
                   std::to_string(a.component_type));
    return false;
  }
  if (a.count > options_.limits.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " vertices exceeds max_hull_input_points (" +
                   std::to_string(options_.limits.max_hull_input_points) + ")");
    return false;
  }
  const std::size_t count = static_cast<std::size_t>(a.count);
  const std::size_t start = out->size();
  out->resize(start + count, Vec3{0.0});
  if (a.view < 0)
    return true;  // all zeros (glTF)
  const detail::ViewDef& view = doc_.views[static_cast<std::size_t>(a.view)];
  const auto& data = model_.buffers[view.buffer].data;
  const std::uint64_t stride = a.strideBytes(doc_.views);
  const std::uint64_t base = view.byte_offset + a.byte_offset;  // checked by validateDocument
  if (base + (a.count - 1) * stride + 12 > data.size()) {
    p_->add(w, "data runs past the end of buffer " + std::to_string(view.buffer));
    return false;
  }
  for (std::size_t i = 0; i < count; ++i) {
    float f[3];
    std::memcpy(f, data.data() + base + i * stride, sizeof f);
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
      p_->add(w, use + ": vertex " + std::to_string(i) + " is not finite (NaN or Inf)");
      return false;
    }
    (*out)[start + i] = {f[0], f[1], f[2]};
  }
  return true;
}

bool Builder::readIndices(std::size_t index,
                          std::size_t vertex_count,
                          const std::string& use,
                          std::vector<std::uint32_t>* out) {
  const detail::AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  const std::uint32_t size = a.component_type == 5121   ? 1
                             : a.component_type == 5123 ? 2
                             : a.component_type == 5125 ? 4
                                                        : 0;
  if (a.type != "SCALAR" || size == 0) {
    p_->add(w, use + " indices must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    return false;
  }
  if (a.count % 3 != 0) {
    p_->add(w,
            use + ": " + std::to_string(a.count) + " indices is not a whole number of triangles");
    return false;
  }
  if (a.count > 6ull * options_.limits.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " indices is too many for " +
                   "max_hull_input_points");
    return false;
  }
  const std::size_t count = static_cast<std::size_t>(a.count);
  if (a.view < 0) {
    out->insert(out->end(), count, 0u);
    return true;
  }
  const detail::ViewDef& view = doc_.views[static_cast<std::size_t>(a.view)];
  const auto& data = model_.buffers[view.buffer].data;
  const std::uint64_t stride = a.strideBytes(doc_.views);
  const std::uint64_t base = view.byte_offset + a.byte_offset;
  if (base + (a.count - 1) * stride + size > data.size()) {
    p_->add(w, "data runs past the end of buffer " + std::to_string(view.buffer));
    return false;
  }
  out->reserve(out->size() + count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint8_t* q = data.data() + base + i * stride;
    std::uint32_t v = 0;
    if (size == 1) {
      v = q[0];
    } else if (size == 2) {
      std::uint16_t s;
      std::memcpy(&s, q, 2);
      v = s;
    } else {
      std::memcpy(&v, q, 4);
    }
    if (v >= vertex_count) {
      p_->add(w, use + ": index " + std::to_string(v) + " out of range (" +
                     std::to_string(vertex_count) + " vertices)");
      return false;
    }
    out->push_back(v);
  }
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
    for (std::uint32_t child : def.children) {
      stack.push_back({child, item.X * doc_.nodes[child].local()});
    }
    if (def.mesh < 0)
      continue;
    const auto mi = static_cast<std::size_t>(def.mesh);
    const detail::MeshDef& mesh = doc_.meshes[mi];
    for (std::size_t k = 0; k < mesh.primitives.size(); ++k) {
      const detail::MeshPrimitiveDef& prim = mesh.primitives[k];
      const std::string use = detail::meshWhere(doc_, mi) + " primitive " + std::to_string(k);
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
      const std::uint64_t count_declared =
          doc_.accessors[static_cast<std::size_t>(prim.position)].count;
      if (hull_points_ + count_declared > options_.limits.max_total_hull_input_points) {
        p_->add(where(node), "the scene's colliders have more than max_total_hull_input_points (" +
                                 std::to_string(options_.limits.max_total_hull_input_points) +
                                 ") hull input points in all");
        return false;
      }
      if (!readPositions(static_cast<std::size_t>(prim.position), use + " POSITION", points)) {
        return false;
      }
      const std::size_t count = points->size() - first;
      hull_points_ += count;
      if (points->size() > options_.limits.max_hull_input_points) {
        p_->add(where(node), "collider mesh has " + std::to_string(points->size()) +
                                 " vertices, more than max_hull_input_points (" +
                                 std::to_string(options_.limits.max_hull_input_points) + ")");
        return false;
      }
      for (std::size_t v = first; v < points->size(); ++v) {
        (*points)[v] = Vec3(item.X * glm::dvec4((*points)[v], 1.0));
      }
      if (!triangles) {
        // a hull needs only the vertices
      } else if (prim.indices >= 0) {
        std::vector<std::uint32_t> local;
        if (!readIndices(static_cast<std::size_t>(prim.indices), count, use, &local))
          return false;
        for (std::uint32_t v : local)
          triangles->push_back(static_cast<std::uint32_t>(first) + v);
      } else {
        if (count % 3 != 0) {
          p_->add(use, "has " + std::to_string(count) +
                           " vertices and no indices: not a whole number of triangles");
          return false;
        }
        for (std::size_t v = 0; v < count; ++v) {
          triangles->push_back(static_cast<std::uint32_t>(first + v));
        }
      }
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
  detail::splitRigid(X_BW.R * Mat3(W), &at.R, &at.S);
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

bool Builder::reuse(Body& body,
                    std::uint32_t node,
                    ShapeSource source,
                    const Placement& at,
                    const HullKey& key) {
  const auto it = hulls_.find(key);
  if (it == hulls_.end())
    return false;
  Primitive prim;
  prim.shape = it->second;
  prim.X_BP.translation = at.t;
  prim.X_BP.rotation = glm::normalize(glm::quat_cast(at.R));
  prim.source = source;
  prim.node = static_cast<std::int32_t>(node);
  prim.material = doc_.nodes[node].collider->material;
  body.primitives.push_back(std::move(prim));
  return true;
}

bool Builder::finishPrimitive(Body& body,
                              std::uint32_t node,
                              ShapeSource source,
                              const Placement& at,
                              const std::vector<Vec3>& points_C,
                              const std::vector<std::uint32_t>* tris,
                              const std::string& mesh_name,
                              const HullKey* key) {
  std::vector<Vec3> points_P;
  points_P.reserve(points_C.size());
  for (const Vec3& p : points_C)
    points_P.push_back(at.S * p);
  if (hull_points_ > options_.limits.max_total_hull_input_points) {
    p_->add(where(node), "the scene's colliders have more than max_total_hull_input_points (" +
                             std::to_string(options_.limits.max_total_hull_input_points) +
                             ") hull input points in all");
    return false;
  }
  geom::HullOptions hull;
  hull.max_vertices = options_.limits.max_hull_vertices;
  hull.max_input_points = options_.limits.max_hull_input_points;
  auto poly = geom::Polytope::fromPoints(points_P, hull);
  if (!poly) {
    p_->add(where(node), (mesh_name.empty() ? "collider" : mesh_name) +
                             ": cannot build a convex hull: " + poly.error().message);
    return false;
  }
  if (tris) {
    const double violation = detail::convexityViolation(poly.value(), points_P, *tris);
    if (violation > kConvexTolerance * poly.value().radius()) {
      p_->add(where(node), mesh_name +
                               ": non-convex mesh collider without convexHull (convex "
                               "decomposition is not supported); a vertex lies " +
                               num(violation) + " in front of a triangle's plane");
      return false;
    }
  }
  auto shape = std::make_shared<const geom::Polytope>(std::move(poly).value());
  if (key)
    hulls_.emplace(*key, shape);
  Primitive prim;
  prim.shape = std::move(shape);
  prim.X_BP.translation = at.t;
  prim.X_BP.rotation = glm::normalize(glm::quat_cast(at.R));
  prim.source = source;
  prim.node = static_cast<std::int32_t>(node);
  prim.material = doc_.nodes[node].collider->material;
  body.primitives.push_back(std::move(prim));
  return true;
}

void Builder::addCollider(SceneModel& scene, std::uint32_t body_index, std::uint32_t node) {
  Body& body = scene.bodies[body_index];
  const detail::ColliderDef& collider = *doc_.nodes[node].collider;
  const Mat3 L(world_[node]);
  if (glm::length(L[0]) == 0.0 && glm::length(L[1]) == 0.0 && glm::length(L[2]) == 0.0) {
    return;  // scale zero on every axis: the collider is disabled (KHR_physics_rigid_bodies)
  }
  const double tol = options_.limits.tessellation_tolerance;
  const std::uint32_t max_v = options_.limits.max_hull_vertices;
  const Placement at = placement(body, node);
  if (collider.shape >= 0) {
    const detail::ShapeDef& shape = doc_.shapes[static_cast<std::size_t>(collider.shape)];
    static constexpr ShapeSource kSources[] = {ShapeSource::kBox, ShapeSource::kSphere,
                                               ShapeSource::kCapsule, ShapeSource::kCylinder,
                                               ShapeSource::kPlane};
    const HullKey key = hullKey(0, collider.shape, at.S);
    if (shape.type != ShapeType::kPlane &&
        reuse(body, node, kSources[static_cast<int>(shape.type)], at, key)) {
      return;
    }
    std::vector<Vec3> points;
    ShapeSource source = ShapeSource::kBox;
    const auto needGrid = [&](std::optional<detail::SphereGrid>* grid, std::uint32_t limit) {
      if (!*grid) {
        auto g = detail::sphereGridFor(tol, limit);
        if (!g) {
          p_->add(where(node), g.error().message);
          return false;
        }
        *grid = g.value();
      }
      return true;
    };
    switch (shape.type) {
      case ShapeType::kBox:
        points = detail::boxPoints(shape.size);
        source = ShapeSource::kBox;
        break;
      case ShapeType::kSphere:
        if (!needGrid(&grid_, max_v))
          return;
        points = detail::spherePoints(shape.radius, *grid_);
        source = ShapeSource::kSphere;
        break;
      case ShapeType::kCapsule:
        if (!needGrid(&grid_, max_v))
          return;
        points = detail::capsulePoints(shape.height, shape.radius_top, shape.radius_bottom, *grid_);
        source = ShapeSource::kCapsule;
        break;
      case ShapeType::kCylinder: {
        if (!segments_) {
          auto s = detail::circleSegmentsFor(tol, max_v);
          if (!s) {
            p_->add(where(node), s.error().message);
            return;
          }
          segments_ = s.value();
        }
        points =
            detail::cylinderPoints(shape.height, shape.radius_top, shape.radius_bottom, *segments_);
        source = ShapeSource::kCylinder;
        break;
      }
      case ShapeType::kPlane:
        if (body.motion != Motion::kStatic) {
          p_->add(where(node), "a plane collider must be static (it is part of moving body '" +
                                   body.name + "')");
          return;
        }
        if (shape.double_sided) {
          p_->add(where(node),
                  "double-sided planes are not supported (a plane is the solid "
                  "half-space below it)");
          return;
        }
        planes_.push_back({body_index, node, &shape});
        return;
    }
    hull_points_ += points.size();
    finishPrimitive(body, node, source, at, points, nullptr, "", &key);
    return;
  }
  const auto g = static_cast<std::uint32_t>(collider.geometry_node);
  const HullKey key = hullKey(collider.convex_hull ? 1 : 2, collider.geometry_node, at.S);
  const ShapeSource source =
      collider.convex_hull ? ShapeSource::kMeshHull : ShapeSource::kConvexMesh;
  if (reuse(body, node, source, at, key))
    return;
  std::vector<Vec3> points;
  std::vector<std::uint32_t> triangles;
  if (!meshGeometry(g, &points, collider.convex_hull ? nullptr : &triangles))
    return;
  std::string mesh_name;
  if (doc_.nodes[g].mesh >= 0) {
    mesh_name = detail::meshWhere(doc_, static_cast<std::size_t>(doc_.nodes[g].mesh));
  } else {
    mesh_name = "the meshes under " + where(g);
  }
  finishPrimitive(body, node, source, at, points, collider.convex_hull ? nullptr : &triangles,
                  mesh_name, &key);
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
  std::vector<Vec3> points;
  if (plane.shape->size_x) {
    const double sx = *plane.shape->size_x, sz = *plane.shape->size_z;
    const double depth = 0.1 * std::min(sx, sz);
    for (int i = 0; i < 8; ++i) {
      points.push_back(
          {(i & 1) ? 0.5 * sx : -0.5 * sx, (i & 2) ? 0.0 : -depth, (i & 4) ? 0.5 * sz : -0.5 * sz});
    }
  } else {
    const double extent = have_box ? glm::length(hi - lo) : 1.0;
    const Vec3 centre_W = have_box ? 0.5 * (lo + hi) : Vec3(W[3]);
    const Vec3 centre_C = Vec3(glm::inverse(W) * glm::dvec4(centre_W, 1.0));
    const double half = kPlaneExtents * extent / s_min;
    const double depth = extent / s_min;
    for (int i = 0; i < 8; ++i) {
      points.push_back({centre_C.x + ((i & 1) ? half : -half), (i & 2) ? 0.0 : -depth,
                        centre_C.z + ((i & 4) ? half : -half)});
    }
  }
  Body& body = scene.bodies[plane.body];
  finishPrimitive(body, plane.node, ShapeSource::kPlane, placement(body, plane.node), points,
                  nullptr, "", nullptr);
}

void Builder::massProperties(Body& body, const detail::MotionDef& motion, std::uint32_t node) {
  const std::string w = where(node);
  detail::VolumeIntegrals integrals;
  for (const Primitive& prim : body.primitives) {
    integrals.add(detail::polytopeIntegrals(*prim.shape, prim.X_BP.toTransform()));
  }
  const detail::MassProperties computed = detail::massFromIntegrals(integrals, kDensity);
  const bool have_volume = computed.mass > 0.0;
  // node space -> body frame: the body node's scale and shear (its rigid part is X_WB)
  Mat3 R_unused, S;
  detail::splitRigid(Mat3(world_[node]), &R_unused, &S);

  body.mass_declared = motion.mass.has_value();
  body.inertia_declared = motion.inertia_diagonal.has_value();
  if (!have_volume && (!motion.mass || !motion.inertia_diagonal)) {
    p_->add(w, "dynamic body has no collider volume to compute its " +
                   std::string(!motion.mass ? "mass" : "inertia") +
                   " from: declare mass and inertiaDiagonal, or give it colliders");
    return;
  }
  const bool infinite_mass = motion.mass && *motion.mass == 0.0;  // 0 means infinite (KHR)
  body.mass = motion.mass ? *motion.mass : computed.mass;
  body.inverse_mass = infinite_mass ? 0.0 : 1.0 / body.mass;
  body.com_B = motion.center_of_mass ? S * *motion.center_of_mass : computed.com_B;

  if (motion.inertia_diagonal) {
    const Mat3 Rq = glm::mat3_cast(motion.inertia_orientation);
    const Vec3 d = *motion.inertia_diagonal;
    Mat3 D(0.0), Dinv(0.0);
    for (int k = 0; k < 3; ++k) {
      D[k][k] = d[k];
      Dinv[k][k] = d[k] == 0.0 ? 0.0 : 1.0 / d[k];  // 0 means infinite (KHR)
    }
    body.inertia_B = Rq * D * glm::transpose(Rq);
    body.inverse_inertia_B = Rq * Dinv * glm::transpose(Rq);
  } else if (infinite_mass) {
    body.inertia_B = Mat3(0.0);
    body.inverse_inertia_B = Mat3(0.0);
  } else {
    // computed about the computed centre; moved to the declared centre and scaled to the
    // declared mass (uniform density)
    Mat3 I = computed.inertia_B;
    const Vec3 dc = body.com_B - computed.com_B;
    I += computed.mass * (glm::dot(dc, dc) * Mat3(1.0) - glm::outerProduct(dc, dc));
    I *= body.mass / computed.mass;
    body.inertia_B = I;
    body.inverse_inertia_B = glm::inverse(I);
  }
  if (!std::isfinite(body.mass) || !std::isfinite(body.inverse_mass) || !finite(body.com_B) ||
      !finite(body.inertia_B) || !finite(body.inverse_inertia_B)) {
    p_->add(w, "mass properties are not finite (mass " + num(body.mass) + ")");
  }
}

void Builder::filterBits(SceneModel& scene) {
  std::map<std::string, std::uint32_t> bits;
  for (const auto& f : doc_.filters) {
    for (const auto* list : {&f.systems, &f.collide_with, &f.not_collide_with}) {
      for (const std::string& s : *list) {
        if (bits.count(s))
          continue;
        if (bits.size() == 32) {
          p_->add("collisionFilters", "more than 32 collision systems (at '" + s + "')");
          return;
        }
        const auto bit = static_cast<std::uint32_t>(bits.size());
        bits.emplace(s, 1u << bit);
      }
    }
  }
  const auto mask = [&](const std::vector<std::string>& names) {
    std::uint32_t m = 0;
    for (const std::string& s : names)
      m |= bits[s];
    return m;
  };
  for (Body& body : scene.bodies) {
    for (Primitive& prim : body.primitives) {
      const std::int32_t f = doc_.nodes[static_cast<std::size_t>(prim.node)].collider->filter;
      if (f < 0) {
        // unfiltered: in every system, colliding with every system
        prim.group = ~0u;
        prim.mask = ~0u;
        continue;
      }
      const detail::FilterDef& def = doc_.filters[static_cast<std::size_t>(f)];
      prim.group = def.systems.empty() ? ~0u : mask(def.systems);
      if (!def.collide_with.empty()) {
        prim.mask = mask(def.collide_with);
      } else if (!def.not_collide_with.empty()) {
        prim.mask = ~mask(def.not_collide_with);
      } else {
        prim.mask = ~0u;
      }
    }
  }
}

void Builder::buildJoints(SceneModel& scene) {
  const auto bodyOf = [&](std::size_t node) -> std::int32_t {
    const std::int32_t o = owner_[node];
    return o < 0 ? -1 : body_of_node_[static_cast<std::size_t>(o)];
  };
  // a node's attachment frame in its body's frame (the scene frame for static nodes); rigid only
  const auto frameIn = [&](std::int32_t body, std::size_t node) {
    Mat3 R, S;
    detail::splitRigid(Mat3(world_[node]), &R, &S);
    Pose X_WJ{Vec3(world_[node][3]), glm::normalize(glm::quat_cast(R))};
    if (body < 0)
      return X_WJ;
    const Pose& X_WB = scene.bodies[static_cast<std::size_t>(body)].X_WB;
    const Transform X_BJ = geom::relativeTransform(X_WB, X_WJ);
    return Pose{X_BJ.t, glm::normalize(glm::quat_cast(X_BJ.R))};
  };
  for (std::uint32_t node : order_) {
    const NodeDef& def = doc_.nodes[node];
    if (!def.joint)
      continue;
    const std::string w = where(node) + " joint";
    const detail::JointRef& ref = *def.joint;
    const auto connected = static_cast<std::size_t>(ref.connected_node);
    if (!in_scene_[connected]) {
      p_->add(w, "connectedNode " + where(connected) + " is not in the scene");
      continue;
    }
    Joint joint;
    joint.body_a = bodyOf(node);
    joint.body_b = bodyOf(connected);
    joint.X_AJ = frameIn(joint.body_a, node);
    joint.X_BJ = frameIn(joint.body_b, connected);
    if (joint.body_a < 0) {
      std::swap(joint.body_a, joint.body_b);
      std::swap(joint.X_AJ, joint.X_BJ);
    }
    if (joint.body_a < 0) {
      p_->add(w, "connects two static frames (neither node has motion above it)");
      continue;
    }
    if (joint.body_a == joint.body_b) {
      p_->add(w, "connects body '" + scene.bodies[static_cast<std::size_t>(joint.body_a)].name +
                     "' to itself");
      continue;
    }
    joint.enable_collision = ref.enable_collision;
    joint.limits = doc_.joints[static_cast<std::size_t>(ref.joint)].limits;
    // which axes are locked: a linear limit with max 0 (and min 0 for one axis), an angular
    // limit the same way; soft limits (with stiffness) lock nothing
    std::uint8_t linear = 0, angular = 0;
    std::array<const JointLimit*, 3> angular_limit{nullptr, nullptr, nullptr};
    for (const JointLimit& lim : joint.limits) {
      const int axes = std::popcount(static_cast<unsigned>(lim.linear_axes | lim.angular_axes));
      const bool locks = !lim.stiffness && lim.max && *lim.max == 0.0 &&
                         (axes > 1 ? (!lim.min || *lim.min <= 0.0) : (lim.min && *lim.min == 0.0));
      if (lim.linear_axes) {
        if (locks)
          linear = static_cast<std::uint8_t>(linear | lim.linear_axes);
      } else if (locks) {
        angular = static_cast<std::uint8_t>(angular | lim.angular_axes);
      } else if (axes == 1) {
        angular_limit[static_cast<std::size_t>(
            std::countr_zero(static_cast<unsigned>(lim.angular_axes)))] = &lim;
      }
    }
    if (linear != 7) {
      p_->add(w,
              "is neither fixed nor a hinge: not every linear axis is locked at 0 (only fixed "
              "and hinge joints are supported)");
      continue;
    }
    if (angular == 7) {
      joint.kind = JointKind::kFixed;
    } else if (std::popcount(static_cast<unsigned>(angular)) == 2) {
      joint.kind = JointKind::kHinge;
      joint.hinge_axis =
          static_cast<std::uint8_t>(std::countr_zero(static_cast<unsigned>(~angular & 7u)));
      if (const JointLimit* lim = angular_limit[joint.hinge_axis]) {
        joint.hinge_min = lim->min;
        joint.hinge_max = lim->max;
      }
      for (std::size_t k = 0; k < 3; ++k) {
        if (angular_limit[k] && k != joint.hinge_axis && !(angular & (1u << k))) {
          p_->add(w, "has a soft or non-zero angular limit on a locked axis");
        }
      }
    } else {
      p_->add(w, "is neither fixed nor a hinge: " +
                     std::to_string(3 - std::popcount(static_cast<unsigned>(angular))) +
                     " free angular axes (only fixed and hinge joints are supported)");
      continue;
    }
    scene.joints.push_back(std::move(joint));
  }
}

std::optional<SceneModel> Builder::build(const std::string& name) {
  const std::size_t n = doc_.nodes.size();
  computeWorld();
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite(world_[i]))
      p_->add(where(i), "world transform is not finite (values too large)");
  }
  if (p_->any())
    return std::nullopt;

  // scene nodes, parents first; body roots: nodes with motion, and a probe without motion
  in_scene_.assign(n, 0);
  owner_.assign(n, -1);
  root_.assign(n, -1);
  body_of_node_.assign(n, -1);
  for (std::uint32_t r : doc_.scene_roots) {
    std::vector<std::uint32_t> stack{r};
    root_[r] = static_cast<std::int32_t>(r);
    while (!stack.empty()) {
      const std::uint32_t k = stack.back();
      stack.pop_back();
      in_scene_[k] = 1;
      order_.push_back(k);
      const NodeDef& def = doc_.nodes[k];
      const bool body_root = def.motion.has_value() || (def.probe && owner_[k] < 0);
      if (body_root)
        owner_[k] = static_cast<std::int32_t>(k);
      // reversed onto the stack: children come out in document order
      for (auto it = def.children.rbegin(); it != def.children.rend(); ++it) {
        owner_[*it] = owner_[k];
        root_[*it] = root_[k];
        stack.push_back(*it);
      }
    }
  }

  SceneModel scene;
  scene.name = name;
  std::int32_t probe_node = -1;
  std::size_t colliders = 0;
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (def.collider)
      ++colliders;
    if (def.probe) {
      if (probe_node >= 0) {
        p_->add(where(k), "is a second probe (" + where(static_cast<std::size_t>(probe_node)) +
                              " is one): a scene has at most one probe body");
      } else {
        probe_node = static_cast<std::int32_t>(k);
      }
    }
  }
  if (colliders > options_.limits.max_primitives) {
    p_->add("file", std::to_string(colliders) + " colliders exceeds max_primitives (" +
                        std::to_string(options_.limits.max_primitives) + ")");
  }
  if (p_->any())
    return std::nullopt;

  const auto rigid = [&](std::size_t node) {
    Mat3 R, S;
    detail::splitRigid(Mat3(world_[node]), &R, &S);
    return Pose{Vec3(world_[node][3]), glm::normalize(glm::quat_cast(R))};
  };
  // moving bodies, in scene order
  for (std::uint32_t k : order_) {
    if (owner_[k] != static_cast<std::int32_t>(k))
      continue;
    const NodeDef& def = doc_.nodes[k];
    Body body;
    body.name = def.name.empty() ? "node" + std::to_string(k) : def.name;
    body.node = static_cast<std::int32_t>(k);
    body.motion = !def.motion || def.motion->kinematic ? Motion::kKinematic : Motion::kDynamic;
    body.X_WB = rigid(k);
    if (def.motion) {
      const Mat3 R = glm::mat3_cast(body.X_WB.rotation);
      body.linear_velocity_W = R * def.motion->linear_velocity;
      body.angular_velocity_W = R * def.motion->angular_velocity;
      body.gravity_factor = def.motion->gravity_factor;
    }
    body_of_node_[k] = static_cast<std::int32_t>(scene.bodies.size());
    scene.bodies.push_back(std::move(body));
  }
  // static bodies: the static colliders under each scene root form one body
  for (std::uint32_t k : order_) {
    if (!doc_.nodes[k].collider || owner_[k] >= 0)
      continue;
    const auto r = static_cast<std::size_t>(root_[k]);
    if (body_of_node_[r] >= 0)
      continue;
    Body body;
    body.name = doc_.nodes[r].name.empty() ? "node" + std::to_string(r) : doc_.nodes[r].name;
    body.node = static_cast<std::int32_t>(r);
    body.motion = Motion::kStatic;
    body.X_WB = rigid(r);
    body_of_node_[r] = static_cast<std::int32_t>(scene.bodies.size());
    scene.bodies.push_back(std::move(body));
  }
  if (scene.bodies.size() > options_.limits.max_bodies) {
    p_->add("file", std::to_string(scene.bodies.size()) + " bodies exceeds max_bodies (" +
                        std::to_string(options_.limits.max_bodies) + ")");
    return std::nullopt;
  }
  const auto bodyIndexOf = [&](std::size_t node) -> std::int32_t {
    const std::int32_t o = owner_[node];
    if (o >= 0)
      return body_of_node_[static_cast<std::size_t>(o)];
    return body_of_node_[static_cast<std::size_t>(root_[node])];
  };
  for (std::uint32_t k : order_) {
    if (!doc_.nodes[k].collider)
      continue;
    if (p_->full())
      break;  // a hostile file: stop building once the report is full
    addCollider(scene, static_cast<std::uint32_t>(bodyIndexOf(k)), k);
  }
  if (p_->any())
    return std::nullopt;

  // the scene's extent (without infinite planes), then the planes
  Vec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
  bool have_box = false;
  for (const Body& body : scene.bodies) {
    const Transform X_WB = body.X_WB.toTransform();
    for (const Primitive& prim : body.primitives) {
      const Transform X_WP = X_WB * prim.X_BP.toTransform();
      for (const auto& v : prim.shape->vertices()) {
        const Vec3 p = X_WP.apply(v.p);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        have_box = true;
      }
    }
  }
  for (const PendingPlane& plane : planes_) {
    if (!plane.shape->size_x)
      continue;
    addPlane(scene, plane, lo, hi, have_box);
  }
  for (const PendingPlane& plane : planes_) {
    if (plane.shape->size_x)
      continue;
    addPlane(scene, plane, lo, hi, have_box);
  }
  if (p_->any())
    return std::nullopt;
  scene.length_scale = have_box ? glm::length(hi - lo) : 1.0;
  if (!(scene.length_scale > 0.0) || !std::isfinite(scene.length_scale))
    scene.length_scale = 1.0;

  // mass properties, stiffness, probe
  for (Body& body : scene.bodies) {
    if (body.motion != Motion::kDynamic)
      continue;
    const auto k = static_cast<std::uint32_t>(body.node);
    massProperties(body, *doc_.nodes[k].motion, k);
  }
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (!def.stiffness)
      continue;
    const std::int32_t b = bodyIndexOf(k);
    if (b < 0) {
      p_->add(where(k),
              "extras.haptic.stiffness on a node that belongs to no body (no motion "
              "above it and no static collider under its root)");
      continue;
    }
    scene.bodies[static_cast<std::size_t>(b)].stiffness_n_per_m = def.stiffness;
  }
  if (probe_node >= 0) {
    const std::int32_t b = bodyIndexOf(static_cast<std::size_t>(probe_node));
    scene.probe_body = b;
    scene.bodies[static_cast<std::size_t>(b)].probe = true;
  }
  // extras.haptic.active: a body out of the scene until a client adds it (docs/scenes.md);
  // static colliders and the probe are always in it
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (!def.active)
      continue;
    const std::int32_t b = bodyIndexOf(k);
    if (b < 0) {
      p_->add(where(k),
              "extras.haptic.active on a node that belongs to no body (no motion above it and no "
              "static collider under its root)");
      continue;
    }
    Body& body = scene.bodies[static_cast<std::size_t>(b)];
    if (!*def.active && body.motion == Motion::kStatic) {
      p_->add(where(k),
              "extras.haptic.active false on a static collider: static bodies are always "
              "active (give the body a motion, isKinematic true, to add and remove it)");
      continue;
    }
    if (!*def.active && body.probe) {
      p_->add(where(k), "extras.haptic.active false on the probe body: the probe is always active");
      continue;
    }
    body.active = *def.active;
  }
  scene.materials = doc_.materials;
  filterBits(scene);
  buildJoints(scene);
  if (doc_.gravity)
    scene.gravity_W = doc_.gravity;
  if (p_->any())
    return std::nullopt;
  scene.plan = makePlan(scene);
  return scene;
}

LoadReport loadImpl(std::span<const std::uint8_t> bytes,
                    const std::string& name,
                    const LoadOptions& options) {
  LoadReport report;
  Problems problems;
  const auto finish = [&]() {
    report.problems = problems.take();
    if (!report.problems.empty())
      report.scene.reset();
    return report;
  };
  const SceneLimits& limits = options.limits;
  if (!(limits.tessellation_tolerance > 0.0 && limits.tessellation_tolerance < 0.5)) {
    problems.add("options", "tessellation_tolerance " + num(limits.tessellation_tolerance) +
                                " must be in (0, 0.5)");
    return finish();
  }
  Document doc;
  nlohmann::json json;
  if (!detail::parseContainer(bytes, options, &doc, &problems, &json))
    return finish();
  if (!detail::validateDocument(json, options, &doc, &problems))
    return finish();
  json = nlohmann::json();  // free it before the model is built

  tinygltf::TinyGLTF gltf;
  FsPolicy policy{&options};
  gltf.SetFsCallbacks(
      {&fsFileExists, &fsExpandFilePath, &fsReadWholeFile, &fsWriteWholeFile, &policy});
  gltf.SetImageLoader(&noImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string base = options.allowed_uri_dir ? options.allowed_uri_dir->string() : "";
  const bool ok =
      doc.glb ? gltf.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                          static_cast<unsigned int>(bytes.size()), base)
              : gltf.LoadASCIIFromString(&model, &err, &warn, doc.json_text.data(),
                                         static_cast<unsigned int>(doc.json_text.size()), base);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == '\r'))
      err.pop_back();
    problems.add("file", "glTF: " + (err.empty() ? std::string("tinygltf refused the file") : err));
    return finish();
  }
  if (model.buffers.size() != doc.buffers.size()) {
    problems.add("file", "glTF: tinygltf read " + std::to_string(model.buffers.size()) +
                             " buffers, the JSON declares " + std::to_string(doc.buffers.size()));
    return finish();
  }
  for (std::size_t i = 0; i < doc.buffers.size(); ++i) {
    if (model.buffers[i].data.size() < doc.buffers[i].byte_length) {
      problems.add("buffer " + std::to_string(i), "holds " +
                                                      std::to_string(model.buffers[i].data.size()) +
                                                      " bytes, less than its byteLength " +
                                                      std::to_string(doc.buffers[i].byte_length));
    }
  }
  if (problems.any())
    return finish();

  Builder builder(doc, model, options, &problems);
  report.scene = builder.build(name);
  return finish();
}

}  // namespace

std::string LoadReport::message() const {
  std::string out;
  for (const Problem& p : problems) {
    out += p.where;
    out += ": ";
    out += p.what;
    out += '\n';
  }
  return out;
}

LoadReport loadScene(std::span<const std::uint8_t> bytes,
                     const std::string& name,
                     const LoadOptions& options) {
  try {
    return loadImpl(bytes, name, options);
  } catch (const std::exception& e) {
    LoadReport report;
    report.problems.push_back({"file", std::string("internal error while loading: ") + e.what()});
    return report;
  }
}

LoadReport loadSceneFile(const std::filesystem::path& path, const LoadOptions& options) {
  LoadReport report;
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::is_regular_file(status)) {
    report.problems.push_back({"file", "cannot read " + path.string() + ": " +
                                           (ec ? ec.message() : "not a regular file")});
    return report;
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) {
    report.problems.push_back({"file", "cannot read " + path.string() + ": " + ec.message()});
    return report;
  }
  if (size > options.limits.max_file_bytes) {
    report.problems.push_back({"file", std::to_string(size) + " bytes exceeds max_file_bytes (" +
                                           std::to_string(options.limits.max_file_bytes) + ")"});
    return report;
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (!in) {
    report.problems.push_back({"file", "cannot read " + path.string()});
    return report;
  }
  return loadScene(bytes, path.filename().string(), options);
}

}  // namespace hapticd::scene
