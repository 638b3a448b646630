// The validation walk over the physics extensions: KHR_implicit_shapes, KHR_physics_rigid_bodies
// (materials, filters, joints with their limits and drives; a node's motion, collider, trigger
// and joint) and extras.haptic (document.h). The OMI extensions are validate_omi.cpp's.
#include "core/scene/document.h"

namespace hapticd::scene::detail {
namespace {

/// True when `j` is an object; a "must be an object" problem otherwise.
bool isObject(Checker& c, const json& j, const std::string& where) {
  if (!j.is_object())
    c.add(where, "must be an object");
  return j.is_object();
}

Combine combineOf(Checker& c, const json& o, const char* key, const std::string& where) {
  static const std::vector<std::string> kNames = {"average", "minimum", "maximum", "multiply"};
  static constexpr Combine kValues[] = {Combine::kAverage, Combine::kMinimum, Combine::kMaximum,
                                        Combine::kMultiply};
  std::size_t i = 0;
  return c.choice(o, key, where, kNames, &i) == Got::kOk ? kValues[i] : Combine::kAverage;
}

/// A shape's parameters by its type (every parameter has a default).
void shapeParameters(Checker& c,
                     const json& p,
                     const std::string& type,
                     const std::string& w,
                     ShapeDef* def) {
  if (type == "box") {
    def->type = ShapeType::kBox;
    if (c.vec3(p, "size", w + " box", &def->size) == Got::kOk &&
        !(def->size.x > 0.0 && def->size.y > 0.0 && def->size.z > 0.0)) {
      c.add(w + " box", "size must be positive on every axis (degenerate shapes are prohibited)");
    }
  } else if (type == "sphere") {
    def->type = ShapeType::kSphere;
    c.bounded(p, "radius", w + " sphere", &def->radius, 0.0, true);
  } else if (type == "capsule" || type == "cylinder") {
    def->type = type == "capsule" ? ShapeType::kCapsule : ShapeType::kCylinder;
    const std::string ww = w + " " + type;
    c.bounded(p, "height", ww, &def->height, 0.0, true);
    c.bounded(p, "radiusTop", ww, &def->radius_top, 0.0, false);
    c.bounded(p, "radiusBottom", ww, &def->radius_bottom, 0.0, false);
    if (!(def->radius_top > 0.0) && !(def->radius_bottom > 0.0))
      c.add(ww, "radiusTop and radiusBottom are both 0 (degenerate shapes are prohibited)");
  } else if (type == "plane") {
    def->type = ShapeType::kPlane;
    double v = 0.0;
    if (c.bounded(p, "sizeX", w + " plane", &v, 0.0, true) == Got::kOk)
      def->size_x = v;
    if (c.bounded(p, "sizeZ", w + " plane", &v, 0.0, true) == Got::kOk)
      def->size_z = v;
    if (def->size_x.has_value() != def->size_z.has_value())
      c.add(w + " plane", "give both sizeX and sizeZ, or neither (infinite)");
    c.boolean(p, "doubleSided", w + " plane", &def->double_sided);
  } else {
    c.add(w, "shape type " + inQuotes(type) +
                 " is not supported (box, sphere, capsule, cylinder, plane)");
  }
}

void validateShapes(Checker& c, const json& ext, Document* doc) {
  const json* shapes = nullptr;
  if (c.array(ext, "shapes", "KHR_implicit_shapes", &shapes) != Got::kOk)
    return;
  for (std::size_t i = 0; i < shapes->size(); ++i) {
    const json& s = (*shapes)[i];
    const std::string w = "KHR_implicit_shapes shape " + std::to_string(i);
    ShapeDef def;
    std::string type;
    if (isObject(c, s, w) && c.string(s, "type", w, &type, true) == Got::kOk) {
      static const json kEmpty = json::object();
      const json* p = &kEmpty;
      if (c.object(s, type.c_str(), w, &p) != Got::kBad)
        shapeParameters(c, *p, type, w, &def);
    }
    doc->shapes.push_back(def);
  }
}

Material validateMaterial(Checker& c, const json& m, std::size_t i) {
  const std::string w = "physicsMaterial " + std::to_string(i);
  Material mat;
  mat.name = "material" + std::to_string(i);
  // the extension's defaults for a declared material
  mat.static_friction = 0.6;
  mat.dynamic_friction = 0.6;
  if (!isObject(c, m, w))
    return mat;
  c.string(m, "name", w, &mat.name);
  c.bounded(m, "staticFriction", w, &mat.static_friction, 0.0, false);
  c.bounded(m, "dynamicFriction", w, &mat.dynamic_friction, 0.0, false);
  c.bounded(m, "restitution", w, &mat.restitution, 0.0, false);
  mat.friction_combine = combineOf(c, m, "frictionCombine", w);
  mat.restitution_combine = combineOf(c, m, "restitutionCombine", w);
  mat.friction_combine_declared = Checker::find(m, "frictionCombine") != nullptr;
  mat.restitution_combine_declared = Checker::find(m, "restitutionCombine") != nullptr;
  return mat;
}

FilterDef validateFilter(Checker& c, const json& f, std::size_t i) {
  const std::string w = "collisionFilter " + std::to_string(i);
  FilterDef def;
  if (!isObject(c, f, w))
    return def;
  c.strings(f, "collisionSystems", w, &def.systems);
  const Got with = c.strings(f, "collideWithSystems", w, &def.collide_with);
  const Got not_with = c.strings(f, "notCollideWithSystems", w, &def.not_collide_with);
  if (with == Got::kOk && not_with == Got::kOk)
    c.add(w, "give collideWithSystems or notCollideWithSystems, not both");
  return def;
}

/// A limit's axis list (1 to 3 distinct axes in 0..2) into bits; false when absent. OMI allows
/// an empty list (no axis of that kind).
bool limitAxes(Checker& c,
               const json& l,
               const char* key,
               const std::string& w,
               JointDialect dialect,
               std::uint8_t* bits) {
  const json* a = nullptr;
  if (c.array(l, key, w, &a) != Got::kOk)
    return false;
  if ((a->empty() && dialect == JointDialect::kKhr) || a->size() > 3)
    c.add(w, std::string(key) + " must list 1 to 3 axes");
  for (const json& e : *a) {
    std::int32_t axis = 0;
    if (c.indexValue(e, key, 3, "axes", w, &axis) != Got::kOk)
      continue;
    const auto bit = static_cast<std::uint8_t>(1u << axis);
    if (*bits & bit)
      c.add(w, std::string(key) + " lists axis " + std::to_string(axis) + " twice");
    *bits = static_cast<std::uint8_t>(*bits | bit);
  }
  return !a->empty();
}

/// A stiffness or force bound: KHR refuses a negative one; OMI reads it as none (infinitely stiff,
/// not limited).
std::optional<double> unbounded(Checker& c,
                                const json& o,
                                const char* key,
                                const std::string& w,
                                JointDialect dialect) {
  double v = 0.0;
  if (dialect == JointDialect::kOmi) {
    if (c.number(o, key, w, &v) == Got::kOk && v >= 0.0)
      return v;
    return std::nullopt;
  }
  if (c.bounded(o, key, w, &v, 0.0, false) == Got::kOk)
    return v;
  return std::nullopt;
}

/// One declared limit, appended to `out`: KHR limits one kind of axes; an OMI limit may name
/// linear and angular axes at once (a weld), kept as two limits with the same range.
void validateLimit(Checker& c,
                   const json& l,
                   const std::string& lw,
                   JointDialect dialect,
                   std::vector<JointLimit>* out) {
  if (!isObject(c, l, lw))
    return;
  JointLimit lim;
  const bool linear = limitAxes(c, l, "linearAxes", lw, dialect, &lim.linear_axes);
  const bool angular = limitAxes(c, l, "angularAxes", lw, dialect, &lim.angular_axes);
  if (dialect == JointDialect::kKhr && linear == angular)
    c.add(lw, "give exactly one of linearAxes and angularAxes");
  if (dialect == JointDialect::kOmi && !linear && !angular)
    c.add(lw, "give linearAxes or angularAxes (a limit must limit some axis)");
  double v = 0.0;
  if (c.number(l, "min", lw, &v) == Got::kOk)
    lim.min = v;
  if (c.number(l, "max", lw, &v) == Got::kOk)
    lim.max = v;
  if (lim.min && lim.max && *lim.min > *lim.max)
    c.add(lw, "min " + formatNumber(*lim.min) + " is above max " + formatNumber(*lim.max));
  lim.stiffness = unbounded(c, l, "stiffness", lw, dialect);
  c.bounded(l, "damping", lw, &lim.damping, 0.0, false);
  if (lim.linear_axes && lim.angular_axes) {
    JointLimit angular_part = lim;
    lim.angular_axes = 0;
    angular_part.linear_axes = 0;
    out->push_back(lim);
    out->push_back(angular_part);
    return;
  }
  out->push_back(lim);
}

std::optional<JointDrive> validateDrive(Checker& c,
                                        const json& d,
                                        const std::string& dw,
                                        JointDialect dialect) {
  static const std::vector<std::string> kTypes = {"linear", "angular"};
  static const std::vector<std::string> kModes = {"force", "acceleration"};
  if (!isObject(c, d, dw))
    return std::nullopt;
  JointDrive drive;
  std::size_t type = 0, mode = 0;
  std::int32_t axis = 0;
  const Got gt = c.choice(d, "type", dw, kTypes, &type);
  const Got gm = c.choice(d, "mode", dw, kModes, &mode);
  const Got ga = c.index(d, "axis", 3, "axes", dw, &axis, true);
  for (const auto& [got, key] : {std::pair{gt, "type"}, std::pair{gm, "mode"}}) {
    if (got == Got::kAbsent)
      c.add(dw, std::string("required property ") + key + " is missing");
  }
  if (gt != Got::kOk || gm != Got::kOk || ga != Got::kOk)
    return std::nullopt;
  drive.angular = type == 1;
  drive.acceleration = mode == 1;
  drive.axis = static_cast<std::uint8_t>(axis);
  double v = 0.0;
  drive.max_force = unbounded(c, d, "maxForce", dw, dialect);
  if (c.number(d, "positionTarget", dw, &v) == Got::kOk)
    drive.position_target = v;
  if (c.number(d, "velocityTarget", dw, &v) == Got::kOk)
    drive.velocity_target = v;
  c.bounded(d, "stiffness", dw, &drive.stiffness, 0.0, false);
  c.bounded(d, "damping", dw, &drive.damping, 0.0, false);
  return drive;
}

JointDef validateJoint(Checker& c, const json& j, const std::string& w, JointDialect dialect) {
  JointDef def;
  if (!isObject(c, j, w))
    return def;
  const json* drives = nullptr;
  if (c.array(j, "drives", w, &drives) == Got::kOk) {
    for (std::size_t k = 0; k < drives->size(); ++k) {
      if (auto drive = validateDrive(c, (*drives)[k], w + " drive " + std::to_string(k), dialect))
        def.drives.push_back(*drive);
    }
  }
  const json* limits = nullptr;
  if (c.array(j, "limits", w, &limits) == Got::kOk) {
    for (std::size_t k = 0; k < limits->size(); ++k)
      validateLimit(c, (*limits)[k], w + " limit " + std::to_string(k), dialect, &def.limits);
  }
  return def;
}

void validateRigidBodiesRoot(Checker& c, const json& ext, Document* doc) {
  validateMaterialsAndFilters(c, ext, "KHR_physics_rigid_bodies", doc);
  validateJoints(c, ext, JointDialect::kKhr, doc);
}

MotionDef validateMotion(Checker& c, const json& motion, const std::string& mw) {
  MotionDef m;
  c.boolean(motion, "isKinematic", mw, &m.kinematic);
  double v = 0.0;
  if (c.bounded(motion, "mass", mw, &v, 0.0, false) == Got::kOk)
    m.mass = v;
  Vec3 vec{0.0};
  if (c.vec3(motion, "centerOfMass", mw, &vec) == Got::kOk)
    m.center_of_mass = vec;
  if (c.vec3(motion, "inertiaDiagonal", mw, &vec) == Got::kOk) {
    if (vec.x < 0.0 || vec.y < 0.0 || vec.z < 0.0)
      c.add(mw, "inertiaDiagonal must not be negative");
    else
      m.inertia_diagonal = vec;
  }
  c.quaternion(motion, "inertiaOrientation", mw, &m.inertia_orientation);
  c.vec3(motion, "linearVelocity", mw, &m.linear_velocity);
  c.vec3(motion, "angularVelocity", mw, &m.angular_velocity);
  c.number(motion, "gravityFactor", mw, &m.gravity_factor);
  return m;
}

/// A collider's or trigger's `geometry` (a shape or a mesh node; `convexHull`).
void validateGeometry(Checker& c,
                      const json& geometry,
                      const std::string& gw,
                      const Document& doc,
                      ColliderDef* def) {
  const Got shape =
      c.index(geometry, "shape", doc.omi_shape_base, "KHR_implicit_shapes shapes", gw, &def->shape);
  const Got mesh_node =
      c.index(geometry, "node", doc.nodes.size(), "nodes", gw, &def->geometry_node);
  if ((shape == Got::kAbsent) == (mesh_node == Got::kAbsent))
    c.add(gw, "give exactly one of shape and node");
  c.boolean(geometry, "convexHull", gw, &def->convex_hull);
}

ColliderDef validateCollider(Checker& c,
                             const json& collider,
                             const std::string& cw,
                             const Document& doc) {
  ColliderDef def;
  const json* geometry = nullptr;
  if (c.object(collider, "geometry", cw, &geometry, true) == Got::kOk)
    validateGeometry(c, *geometry, cw + " geometry", doc, &def);
  c.index(collider, "physicsMaterial", doc.omi_material_base, "physicsMaterials", cw,
          &def.material);
  c.index(collider, "collisionFilter", doc.omi_filter_base, "collisionFilters", cw, &def.filter);
  return def;
}

/// A trigger: `geometry` (the README) or `shape` (the schema), or a compound trigger's `nodes`.
std::optional<ColliderDef> validateTrigger(Checker& c,
                                           const json& trigger,
                                           const std::string& tw,
                                           const Document& doc) {
  ColliderDef def;
  const json* geometry = nullptr;
  std::vector<std::int32_t> nodes;
  validateNodeList(c, trigger, "nodes", tw, doc, &nodes);
  c.index(trigger, "collisionFilter", doc.omi_filter_base, "collisionFilters", tw, &def.filter);
  if (c.object(trigger, "geometry", tw, &geometry) == Got::kOk) {
    validateGeometry(c, *geometry, tw + " geometry", doc, &def);
    return def;
  }
  if (Checker::find(trigger, "shape")) {
    c.index(trigger, "shape", doc.omi_shape_base, "KHR_implicit_shapes shapes", tw, &def.shape);
    return def.shape >= 0 ? std::optional(def) : std::nullopt;
  }
  if (nodes.empty())
    c.add(tw, "give geometry (or shape), or the nodes of a compound trigger");
  return std::nullopt;
}

}  // namespace

void validateMaterialsAndFilters(Checker& c,
                                 const json& ext,
                                 const std::string& name,
                                 Document* doc) {
  const std::size_t material_base = doc->materials.size(), filter_base = doc->filters.size();
  const json* arr = nullptr;
  if (c.array(ext, "physicsMaterials", name, &arr) == Got::kOk) {
    for (std::size_t i = 0; i < arr->size(); ++i)
      doc->materials.push_back(validateMaterial(c, (*arr)[i], material_base + i));
  }
  if (c.array(ext, "collisionFilters", name, &arr) == Got::kOk) {
    for (std::size_t i = 0; i < arr->size(); ++i)
      doc->filters.push_back(validateFilter(c, (*arr)[i], filter_base + i));
  }
}

void validateJoints(Checker& c, const json& ext, JointDialect dialect, Document* doc) {
  const json* arr = nullptr;
  const bool omi = dialect == JointDialect::kOmi;
  if (c.array(ext, "physicsJoints", omi ? "OMI_physics_joint" : "KHR_physics_rigid_bodies", &arr) !=
      Got::kOk) {
    return;
  }
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const std::string w =
        (omi ? "OMI_physics_joint physicsJoint " : "physicsJoint ") + std::to_string(i);
    doc->joints.push_back(validateJoint(c, (*arr)[i], w, dialect));
  }
}

void validatePhysicsRoot(Checker& c, const json& root, Document* doc) {
  // shapes first, then materials, filters, joints (nodes index them); the OMI ones after KHR's
  const json* extensions = nullptr;
  if (c.object(root, "extensions", "extensions", &extensions) != Got::kOk)
    return;
  const json* shapes = nullptr;
  if (c.object(*extensions, "KHR_implicit_shapes", "extensions", &shapes) == Got::kOk)
    validateShapes(c, *shapes, doc);
  const json* physics = nullptr;
  if (c.object(*extensions, "KHR_physics_rigid_bodies", "extensions", &physics) == Got::kOk)
    validateRigidBodiesRoot(c, *physics, doc);
  doc->omi_joint_base = doc->joints.size();
  validateOmiRoot(c, *extensions, doc);
}

void validateNodeList(Checker& c,
                      const json& o,
                      const char* key,
                      const std::string& where,
                      const Document& doc,
                      std::vector<std::int32_t>* out) {
  const json* list = nullptr;
  if (c.array(o, key, where, &list) != Got::kOk)
    return;
  for (const json& e : *list) {
    std::int32_t index = -1;
    if (c.indexValue(e, key, doc.nodes.size(), "nodes", where, &index) == Got::kOk)
      out->push_back(index);
  }
}

void validateNodePhysics(Checker& c,
                         const json& ext,
                         const std::string& w,
                         const Document& doc,
                         NodeDef* node) {
  const json* motion = nullptr;
  if (c.object(ext, "motion", w, &motion) == Got::kOk)
    node->motion = validateMotion(c, *motion, w + " motion");
  const json* collider = nullptr;
  if (c.object(ext, "collider", w, &collider) == Got::kOk)
    node->collider = validateCollider(c, *collider, w + " collider", doc);
  const json* trigger = nullptr;
  if (c.object(ext, "trigger", w, &trigger) == Got::kOk)
    node->trigger = validateTrigger(c, *trigger, w + " trigger", doc);
  const json* joint = nullptr;
  if (c.object(ext, "joint", w, &joint) == Got::kOk) {
    const std::string jw = w + " joint";
    JointRef ref;
    c.index(*joint, "connectedNode", doc.nodes.size(), "nodes", jw, &ref.connected_node, true);
    c.index(*joint, "joint", doc.omi_joint_base, "physicsJoints", jw, &ref.joint, true);
    c.boolean(*joint, "enableCollision", jw, &ref.enable_collision);
    node->joint = ref;
  }
}

void validateHapticExtras(Checker& c,
                          const json& owner,
                          const std::string& where,
                          HapticExtras* out) {
  const json* extras = Checker::find(owner, "extras");
  if (!extras || !extras->is_object())
    return;  // extras are free-form; only ours are checked
  const json* haptic = nullptr;
  if (c.object(*extras, "haptic", where + " extras", &haptic) != Got::kOk)
    return;
  const std::string w = where + " extras.haptic";
  for (auto it = haptic->begin(); it != haptic->end(); ++it) {
    const std::string& key = it.key();
    const bool known =
        out->node ? key == "probe" || key == "stiffness" || key == "active" || key == "concavity"
                  : key == "gravity";
    if (!known)
      c.add(w, "unknown property " + inQuotes(key));
  }
  double k = 0.0;
  Vec3 g{0.0};
  bool on = true;
  if (!out->node) {
    if (c.vec3(*haptic, "gravity", w, &g) == Got::kOk)
      out->gravity = g;
    return;
  }
  c.boolean(*haptic, "probe", w, &out->probe);
  if (c.bounded(*haptic, "stiffness", w, &k, 0.0, true) == Got::kOk)
    out->stiffness = k;
  if (c.boolean(*haptic, "active", w, &on) == Got::kOk)
    out->active = on;
  double concavity = 0.0;
  if (c.bounded(*haptic, "concavity", w, &concavity, 0.0, true) == Got::kOk) {
    if (concavity < 1.0)
      out->concavity = concavity;
    else
      c.add(w, "concavity " + formatNumber(concavity) +
                   " must be in (0, 1) (a fraction of the mesh's bounding-box diagonal)");
  }
}

}  // namespace hapticd::scene::detail
