// The validation walk over the OMI physics extensions that Godot 4 exports (document.h):
// OMI_physics_shape (shapes), OMI_physics_body (a node's motion, collider and trigger; document
// physics materials and collision filters like KHR's), and the older OMI_collider (shapes with
// isTrigger) and OMI_physics_body `type` (static, kinematic, character, rigid, vehicle, trigger),
// and OMI_physics_joint (joints as KHR's, JointDialect::kOmi).
// They map onto the same Document as KHR_physics_rigid_bodies: OMI shapes are appended to
// Document::shapes, OMI materials and filters to Document::materials and filters.
#include "core/scene/document.h"

namespace hapticd::scene::detail {
namespace {

/// An OMI capsule or cylinder: `radius` (the older form: capsule `height` is the whole height)
/// or `radiusTop` / `radiusBottom` (capsule `height` between the cap centres); cylinder `height`
/// is the whole height in both.
void roundShape(Checker& c,
                const json& p,
                const std::string& type,
                const std::string& w,
                ShapeDef* def) {
  const bool capsule = type == "capsule";
  def->type = capsule ? ShapeType::kCapsule : ShapeType::kCylinder;
  double radius = 0.5, height = capsule && !Checker::find(p, "radius") ? 1.0 : 2.0;
  c.bounded(p, "height", w, &height, 0.0, false);
  if (Checker::find(p, "radius")) {
    c.bounded(p, "radius", w, &radius, 0.0, true);
    def->radius_top = def->radius_bottom = radius;
    def->height = capsule ? height - 2.0 * radius : height;
  } else {
    def->radius_top = def->radius_bottom = 0.5;
    c.bounded(p, "radiusTop", w, &def->radius_top, 0.0, false);
    c.bounded(p, "radiusBottom", w, &def->radius_bottom, 0.0, false);
    def->height = height;
  }
  if (!(def->radius_top > 0.0) && !(def->radius_bottom > 0.0))
    c.add(w, "both radii are 0 (degenerate shapes are prohibited)");
  if (capsule && def->height < 0.0) {
    c.add(w, "height " + formatNumber(height) + " is less than the two caps (2 x radius " +
                 formatNumber(radius) + ")");
  }
  if (!capsule && !(def->height > 0.0))
    c.add(w, "height must be > 0");
  if (capsule && def->height == 0.0 && def->radius_top == def->radius_bottom) {
    def->type = ShapeType::kSphere;  // a capsule with no middle
    def->radius = def->radius_top;
  }
}

/// One OMI shape (OMI_physics_shape shape or OMI_collider collider): parameters in the object
/// named after the type, or (OMI_collider, Godot) beside `type`.
ShapeDef omiShape(Checker& c, const json& s, const std::string& w, const Document& doc) {
  ShapeDef def;
  std::string type;
  if (!s.is_object()) {
    c.add(w, "must be an object");
    return def;
  }
  if (c.string(s, "type", w, &type, true) != Got::kOk)
    return def;
  if (type == "hull")
    type = "convex";  // OMI_collider's name
  const json* p = &s;
  if (c.object(s, type.c_str(), w, &p) == Got::kBad)
    return def;
  const std::string tw = w + " " + type;
  c.boolean(s, "isTrigger", w, &def.trigger);
  if (type == "box") {
    def.type = ShapeType::kBox;
    if (c.vec3(*p, "size", tw, &def.size) == Got::kOk &&
        !(def.size.x > 0.0 && def.size.y > 0.0 && def.size.z > 0.0)) {
      c.add(tw, "size must be positive on every axis (degenerate shapes are prohibited)");
    }
  } else if (type == "sphere") {
    def.type = ShapeType::kSphere;
    c.bounded(*p, "radius", tw, &def.radius, 0.0, true);
  } else if (type == "capsule" || type == "cylinder") {
    roundShape(c, *p, type, tw, &def);
  } else if (type == "convex" || type == "trimesh") {
    def.type = ShapeType::kMesh;
    def.convex_hull = type == "convex";
    c.index(*p, "mesh", doc.meshes.size(), "meshes", tw, &def.mesh, true);
  } else {
    c.add(w, "shape type " + inQuotes(type) +
                 " is not supported (box, sphere, capsule, cylinder, convex, trimesh)");
  }
  return def;
}

void appendShapes(Checker& c,
                  const json& ext,
                  const char* list,
                  const std::string& name,
                  Document* doc) {
  const json* shapes = nullptr;
  if (c.array(ext, list, name, &shapes) != Got::kOk)
    return;
  for (std::size_t i = 0; i < shapes->size(); ++i) {
    const std::string w = name + " " + std::string(list).substr(0, std::string(list).size() - 1) +
                          " " + std::to_string(i);
    doc->shapes.push_back(omiShape(c, (*shapes)[i], w, *doc));
  }
}

/// OMI motion: `type` static (no motion), kinematic or character (kinematic), dynamic, rigid or
/// vehicle (dynamic), trigger (the older form: a trigger body); without a type, dynamic (the
/// schema requires one, but Godot's importer reads a motion without it as a rigid body, and the
/// extension's own examples write one: a motion object is there to move); mass 1 kg when not
/// given; an inertia of zeros means computed (OMI), not infinite (KHR).
void omiMotion(Checker& c, const json& m, const std::string& w, NodeDef* node) {
  static const std::vector<std::string> kTypes = {"static", "kinematic", "character", "dynamic",
                                                  "rigid",  "vehicle",   "trigger"};
  std::size_t type = 3;
  const Got got = c.choice(m, "type", w, kTypes, &type);
  if (got == Got::kBad)
    return;
  if (got == Got::kAbsent)
    c.problems().note(w + ": no type: read as dynamic (as Godot reads it)");
  if (type == 6) {
    node->trigger_body = true;
    return;
  }
  if (type == 0)
    return;  // static: colliders without a motion
  MotionDef def;
  def.kinematic = type <= 2;
  double mass = 1.0;
  c.bounded(m, "mass", w, &mass, 0.0, true);
  def.mass = mass;
  c.vec3(m, "linearVelocity", w, &def.linear_velocity);
  c.vec3(m, "angularVelocity", w, &def.angular_velocity);
  Vec3 v{0.0};
  if (c.vec3(m, "centerOfMass", w, &v) == Got::kOk)
    def.center_of_mass = v;
  const json* inertia = Checker::find(m, "inertiaDiagonal");
  if (inertia && inertia->is_array() && inertia->size() == 4) {
    // Godot writes its inertia orientation under this key: no diagonal was kept
    c.problems().note(w +
                      ": inertiaDiagonal has 4 numbers (an exporter wrote the inertia "
                      "orientation there): the inertia is computed");
  } else if (c.vec3(m, "inertiaDiagonal", w, &v) == Got::kOk && v != Vec3{0.0}) {
    if (v.x <= 0.0 || v.y <= 0.0 || v.z <= 0.0)
      c.add(w, "inertiaDiagonal must be positive (or all 0: computed)");
    else
      def.inertia_diagonal = v;
  }
  c.quaternion(m, "inertiaOrientation", w, &def.inertia_orientation);
  node->motion = def;
}

/// An OMI collider or trigger: `shape` into the OMI shapes (-1 or absent: none).
std::optional<ColliderDef> omiCollider(Checker& c,
                                       const json& o,
                                       const std::string& w,
                                       const Document& doc) {
  ColliderDef def;
  std::int32_t shape = -1;
  const json* j = Checker::find(o, "shape");
  if (j && j->is_number_integer() && j->get<std::int64_t>() == -1)
    return std::nullopt;  // OMI: -1 is no shape
  const std::size_t omi_shapes = doc.omi_collider_base - doc.omi_shape_base;
  if (c.index(o, "shape", omi_shapes, "OMI_physics_shape shapes", w, &shape) != Got::kOk)
    return std::nullopt;
  def.shape = static_cast<std::int32_t>(doc.omi_shape_base) + shape;
  std::int32_t index = -1;
  if (c.index(o, "physicsMaterial", doc.materials.size() - doc.omi_material_base,
              "OMI_physics_body physicsMaterials", w, &index) == Got::kOk) {
    def.material = static_cast<std::int32_t>(doc.omi_material_base) + index;
  }
  if (c.index(o, "collisionFilter", doc.filters.size() - doc.omi_filter_base,
              "OMI_physics_body collisionFilters", w, &index) == Got::kOk) {
    def.filter = static_cast<std::int32_t>(doc.omi_filter_base) + index;
  }
  return def;
}

}  // namespace

void validateOmiRoot(Checker& c, const json& extensions, Document* doc) {
  doc->omi_shape_base = doc->shapes.size();
  const json* ext = nullptr;
  if (c.object(extensions, "OMI_physics_shape", "extensions", &ext) == Got::kOk)
    appendShapes(c, *ext, "shapes", "OMI_physics_shape", doc);
  doc->omi_collider_base = doc->shapes.size();
  if (c.object(extensions, "OMI_collider", "extensions", &ext) == Got::kOk)
    appendShapes(c, *ext, "colliders", "OMI_collider", doc);
  doc->omi_material_base = doc->materials.size();
  doc->omi_filter_base = doc->filters.size();
  if (c.object(extensions, "OMI_physics_body", "extensions", &ext) == Got::kOk)
    validateMaterialsAndFilters(c, *ext, "OMI_physics_body", doc);
  if (c.object(extensions, "OMI_physics_joint", "extensions", &ext) == Got::kOk)
    validateJoints(c, *ext, JointDialect::kOmi, doc);
}

void validateOmiNode(Checker& c,
                     const json& extensions,
                     const std::string& w,
                     const Document& doc,
                     NodeDef* node) {
  const json* body = nullptr;
  if (c.object(extensions, "OMI_physics_body", w + " extensions", &body) == Got::kOk) {
    const std::string bw = w + " OMI_physics_body";
    const json* part = nullptr;
    // the older form has the motion's members in the body object itself
    if (c.object(*body, "motion", bw, &part) == Got::kOk)
      omiMotion(c, *part, bw + " motion", node);
    else if (Checker::find(*body, "type"))
      omiMotion(c, *body, bw, node);
    if (c.object(*body, "collider", bw, &part) == Got::kOk)
      node->collider = omiCollider(c, *part, bw + " collider", doc);
    if (c.object(*body, "trigger", bw, &part) == Got::kOk) {
      node->trigger = omiCollider(c, *part, bw + " trigger", doc);
      std::vector<std::int32_t> nodes;
      validateNodeList(c, *part, "nodes", bw + " trigger", doc, &nodes);
      if (!node->trigger && nodes.empty())
        node->trigger_body = true;  // Godot's Area3D: the triggers are its children
    }
  }
  const json* joint = nullptr;
  if (c.object(extensions, "OMI_physics_joint", w + " extensions", &joint) == Got::kOk) {
    // the same node object as KHR's joint, its joint settings in OMI_physics_joint physicsJoints
    const std::string jw = w + " OMI_physics_joint";
    JointRef ref;
    std::int32_t index = -1;
    c.index(*joint, "connectedNode", doc.nodes.size(), "nodes", jw, &ref.connected_node, true);
    if (c.index(*joint, "joint", doc.joints.size() - doc.omi_joint_base,
                "OMI_physics_joint physicsJoints", jw, &index, true) == Got::kOk) {
      ref.joint = static_cast<std::int32_t>(doc.omi_joint_base) + index;
    }
    c.boolean(*joint, "enableCollision", jw, &ref.enable_collision);
    node->joint = ref;
  }
  const json* collider = nullptr;
  if (c.object(extensions, "OMI_collider", w + " extensions", &collider) == Got::kOk) {
    const std::string cw = w + " OMI_collider";
    std::int32_t index = -1;
    const std::size_t count = doc.shapes.size() - doc.omi_collider_base;
    if (c.index(*collider, "collider", count, "OMI_collider colliders", cw, &index) == Got::kOk) {
      ColliderDef def;
      def.shape = static_cast<std::int32_t>(doc.omi_collider_base) + index;
      if (doc.shapes[static_cast<std::size_t>(def.shape)].trigger)
        node->trigger = def;
      else
        node->collider = def;
    }
  }
}

}  // namespace hapticd::scene::detail
