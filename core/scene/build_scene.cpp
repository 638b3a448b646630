// The model builder's frame: world transforms, the scene's nodes, bodies (a plain model's mesh
// nodes as static geometry), extras, notes and the plan (builder.h).
#include <cmath>
#include <limits>

#include "core/geometry/rotation.h"
#include "core/scene/builder.h"

namespace hapticd::scene::detail {
namespace {

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    if (!geom::finite(Vec3(m[c])) || !std::isfinite(m[c][3]))
      return false;
  }
  return true;
}

}  // namespace

std::vector<glm::dmat4> worldTransforms(const Document& doc, Problems* problems) {
  const std::size_t n = doc.nodes.size();
  std::vector<glm::dmat4> world(n, glm::dmat4(1.0));
  std::vector<std::uint8_t> done(n, 0);
  std::vector<std::size_t> chain;
  for (std::size_t i = 0; i < n; ++i) {
    chain.clear();
    std::size_t k = i;
    while (!done[k]) {
      chain.push_back(k);
      if (doc.nodes[k].parent < 0)
        break;
      k = static_cast<std::size_t>(doc.nodes[k].parent);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const NodeDef& node = doc.nodes[*it];
      world[*it] = node.parent < 0 ? node.local()
                                   : world[static_cast<std::size_t>(node.parent)] * node.local();
      done[*it] = 1;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite(world[i]))
      problems->add(nodeWhere(doc, i), "world transform is not finite (values too large)");
  }
  return world;
}

bool Builder::computeWorld() {
  world_ = worldTransforms(doc_, p_);
  return !p_->any();
}

void Builder::collectSceneNodes() {
  // scene nodes, parents first; body roots: nodes with motion, and a probe without motion
  const std::size_t n = doc_.nodes.size();
  in_scene_.assign(n, 0);
  in_trigger_.assign(n, 0);
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
      // an OMI trigger body makes the colliders at and below it triggers, down to the next body
      if (def.trigger_body || (in_trigger_[k] && def.motion))
        in_trigger_[k] = def.trigger_body ? 1 : 0;
      // reversed onto the stack: children come out in document order
      for (auto it = def.children.rbegin(); it != def.children.rend(); ++it) {
        owner_[*it] = owner_[k];
        root_[*it] = root_[k];
        in_trigger_[*it] = in_trigger_[k];
        stack.push_back(*it);
      }
    }
  }
}

bool Builder::checkProbeAndCounts(std::int32_t* probe_node) {
  std::size_t colliders = 0;
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    colliders += (def.collider ? 1u : 0u) + (def.trigger ? 1u : 0u);
    if (!doc_.physics && def.mesh >= 0)
      colliders += doc_.meshes[static_cast<std::size_t>(def.mesh)].primitives.size();
    if (!def.probe)
      continue;
    if (*probe_node >= 0) {
      p_->add(where(k), "is a second probe (" + where(static_cast<std::size_t>(*probe_node)) +
                            " is one): a scene has at most one probe body");
    } else {
      *probe_node = static_cast<std::int32_t>(k);
    }
  }
  if (colliders > options_.limits.max_primitives) {
    p_->add("file", std::to_string(colliders) + " colliders exceeds max_primitives (" +
                        std::to_string(options_.limits.max_primitives) + ")");
  }
  return !p_->any();
}

bool Builder::makeBodies(SceneModel& scene) {
  const auto rigid = [&](std::size_t node) {
    Mat3 R, S;
    splitRigid(Mat3(world_[node]), &R, &S);
    return Pose{Vec3(world_[node][3]), glm::normalize(glm::quat_cast(R))};
  };
  const auto named = [&](std::size_t node) {
    return doc_.nodes[node].name.empty() ? "node" + std::to_string(node) : doc_.nodes[node].name;
  };
  // moving bodies, in scene order
  for (std::uint32_t k : order_) {
    if (owner_[k] != static_cast<std::int32_t>(k))
      continue;
    const NodeDef& def = doc_.nodes[k];
    Body body;
    body.name = named(k);
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
  // static bodies: the static colliders (and triggers) under each scene root form one body
  for (std::uint32_t k : order_) {
    if (!(doc_.nodes[k].collider || doc_.nodes[k].trigger) || owner_[k] >= 0)
      continue;
    const auto r = static_cast<std::size_t>(root_[k]);
    if (body_of_node_[r] >= 0)
      continue;
    Body body;
    body.name = named(r);
    body.node = static_cast<std::int32_t>(r);
    body.motion = Motion::kStatic;
    body.X_WB = rigid(r);
    body_of_node_[r] = static_cast<std::int32_t>(scene.bodies.size());
    scene.bodies.push_back(std::move(body));
  }
  if (scene.bodies.size() > options_.limits.max_bodies) {
    p_->add("file", std::to_string(scene.bodies.size()) + " bodies exceeds max_bodies (" +
                        std::to_string(options_.limits.max_bodies) + ")");
    return false;
  }
  return true;
}

std::int32_t Builder::bodyIndexOf(std::size_t node) const {
  const std::int32_t o = owner_[node];
  if (o >= 0)
    return body_of_node_[static_cast<std::size_t>(o)];
  if (body_of_node_[node] >= 0)
    return body_of_node_[node];  // a static root, or a plain model's mesh node
  return body_of_node_[static_cast<std::size_t>(root_[node])];
}

void Builder::addPlanes(SceneModel& scene) {
  // the scene's extent (without infinite planes), then the planes: finite ones first
  Vec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
  bool have_box = false;
  for (const Body& body : scene.bodies) {
    const Transform X_WB = body.X_WB.toTransform();
    for (const Primitive& prim : body.primitives) {
      if (prim.trigger)
        continue;  // triggers do not size the scene
      const Transform X_WP = X_WB * prim.X_BP.toTransform();
      for (const auto& v : prim.shape->vertices()) {
        const Vec3 p = X_WP.apply(v.p);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        have_box = true;
      }
    }
  }
  for (const bool finite_plane : {true, false}) {
    for (const PendingPlane& plane : planes_) {
      if (plane.shape->size_x.has_value() == finite_plane)
        addPlane(scene, plane, lo, hi, have_box);
    }
  }
  scene.length_scale = have_box ? glm::length(hi - lo) : 1.0;
  if (!(scene.length_scale > 0.0) || !std::isfinite(scene.length_scale))
    scene.length_scale = 1.0;
}

std::optional<std::size_t> Builder::extrasBody(std::size_t node, const char* key) {
  const std::int32_t b = bodyIndexOf(node);
  if (b >= 0)
    return static_cast<std::size_t>(b);
  p_->add(where(node), std::string("extras.haptic.") + key +
                           " on a node that belongs to no body (no motion above it and no "
                           "static collider under its root)");
  return std::nullopt;
}

void Builder::applyExtras(SceneModel& scene, std::int32_t probe_node) {
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (!def.stiffness)
      continue;
    if (const auto b = extrasBody(k, "stiffness"))
      scene.bodies[*b].stiffness_n_per_m = def.stiffness;
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
    const auto b = extrasBody(k, "active");
    if (!b)
      continue;
    Body& body = scene.bodies[*b];
    if (!*def.active && body.motion == Motion::kStatic) {
      p_->add(where(k),
              "extras.haptic.active false on a static collider: static bodies are always "
              "active (give the body a motion, isKinematic true, to add and remove it)");
    } else if (!*def.active && body.probe) {
      p_->add(where(k), "extras.haptic.active false on the probe body: the probe is always active");
    } else {
      body.active = *def.active;
    }
  }
}

void Builder::addAllColliders(SceneModel& scene) {
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (!def.collider && !def.trigger)
      continue;
    if (p_->full())
      break;  // a hostile file: stop building once the report is full
    const auto body = static_cast<std::uint32_t>(bodyIndexOf(k));
    if (def.collider)
      addCollider(scene, {body, k, &*def.collider, in_trigger_[k] != 0}, *def.collider);
    if (def.trigger)
      addCollider(scene, {body, k, &*def.trigger, true}, *def.trigger);
  }
}

void Builder::addPlainBodies(SceneModel& scene) {
  // no physics extension: every mesh node of the scene is static geometry, one body each (or
  // part of the probe's body), each mesh primitive a primitive: convex where it is convex
  for (std::uint32_t k : order_) {
    const NodeDef& def = doc_.nodes[k];
    if (def.mesh < 0 || p_->full())
      continue;
    if (bodyIndexOf(k) < 0) {
      Body body;
      body.name = def.name.empty() ? "node" + std::to_string(k) : def.name;
      body.node = static_cast<std::int32_t>(k);
      body.motion = Motion::kStatic;
      Mat3 R, S;
      splitRigid(Mat3(world_[k]), &R, &S);
      body.X_WB = Pose{Vec3(world_[k][3]), glm::normalize(glm::quat_cast(R))};
      body_of_node_[k] = static_cast<std::int32_t>(scene.bodies.size());
      scene.bodies.push_back(std::move(body));
    }
    ++plain_meshes_;
    const Target target{static_cast<std::uint32_t>(bodyIndexOf(k)), k, nullptr, false};
    const Placement at = placement(scene.bodies[target.body], k);
    const auto mi = static_cast<std::size_t>(def.mesh);
    for (std::size_t j = 0; j < doc_.meshes[mi].primitives.size(); ++j) {
      const HullKey key = hullKey(kPlainMesh, def.mesh, static_cast<std::int32_t>(j), at.S);
      if (reuse(scene, target, at, key))
        continue;
      HullInput in;
      const std::int32_t mode = doc_.meshes[mi].primitives[j].mode;
      in.surface = mode >= 4 && mode <= 6;
      in.source = in.surface ? ShapeSource::kConvexMesh : ShapeSource::kMeshHull;
      in.key = &key;
      in.mesh_name = meshWhere(doc_, mi) + " primitive " + std::to_string(j);
      if (primitiveGeometry(k, glm::dmat4(1.0), mi, j, in.surface, &in))
        finishPrimitive(scene, target, at, std::move(in));
    }
  }
  if (scene.bodies.size() > options_.limits.max_bodies) {
    p_->add("file", std::to_string(scene.bodies.size()) + " bodies exceeds max_bodies (" +
                        std::to_string(options_.limits.max_bodies) + ")");
  }
}

void Builder::finishNotes(SceneModel& scene) {
  std::vector<std::string> notes = p_->takeNotes();
  if (!doc_.physics) {
    notes.push_back("no physics extension: " + std::to_string(plain_meshes_) +
                    " meshes as static geometry");
  }
  const auto listed = [&](const std::vector<std::string>& lines, const char* what) {
    constexpr std::size_t kMaxLines = 20;
    for (std::size_t i = 0; i < lines.size() && i < kMaxLines; ++i)
      notes.push_back(lines[i]);
    if (lines.size() > kMaxLines) {
      notes.push_back("... and " + std::to_string(lines.size() - kMaxLines) + " more " + what);
    }
  };
  listed(stand_ins_, "meshes that are not convex, touched through convex pieces");
  listed(thickened_, "flat meshes given a thickness");
  notes.insert(notes.end(), scene.plan.notes.begin(), scene.plan.notes.end());
  scene.plan.notes = std::move(notes);
}

std::optional<SceneModel> Builder::build(const std::string& name) {
  if (!computeWorld() || !filterClasses())
    return std::nullopt;
  collectSceneNodes();
  std::int32_t probe_node = -1;
  if (!checkProbeAndCounts(&probe_node))
    return std::nullopt;
  SceneModel scene;
  scene.name = name;
  if (!makeBodies(scene))
    return std::nullopt;
  addAllColliders(scene);
  if (!doc_.physics)
    addPlainBodies(scene);
  if (p_->any())
    return std::nullopt;
  addPlanes(scene);
  if (p_->any())
    return std::nullopt;
  for (Body& body : scene.bodies) {
    if (body.motion != Motion::kDynamic)
      continue;
    const auto k = static_cast<std::uint32_t>(body.node);
    massProperties(body, *doc_.nodes[k].motion, k);
  }
  applyExtras(scene, probe_node);
  scene.materials = doc_.materials;
  buildJoints(scene);
  if (doc_.gravity)
    scene.gravity_W = doc_.gravity;
  if (p_->any())
    return std::nullopt;
  scene.plan = makePlan(scene);
  finishNotes(scene);
  return scene;
}

}  // namespace hapticd::scene::detail
