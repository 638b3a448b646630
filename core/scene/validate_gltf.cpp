// The validation walk over core glTF: the top level and its extensions, meshes (with Draco),
// nodes and their hierarchy, scenes (document.h). The data (buffers, views, accessors) is
// validate_data.cpp's.
#include <algorithm>

#include "core/scene/document.h"
#include "core/scene/extensions.h"

namespace hapticd::scene::detail {
namespace {

/// KHR_draco_mesh_compression on a primitive: the stream's bufferView and POSITION's Draco id.
std::optional<DracoDef> validateDraco(Checker& c,
                                      const json& p,
                                      const std::string& where,
                                      const Document& doc) {
  const json* ext = nullptr;
  const json* draco = nullptr;
  if (c.object(p, "extensions", where, &ext) != Got::kOk ||
      c.object(*ext, "KHR_draco_mesh_compression", where + " extensions", &draco) != Got::kOk) {
    return std::nullopt;
  }
  const std::string w = where + " KHR_draco_mesh_compression";
  DracoDef def;
  const json* attributes = nullptr;
  std::uint64_t id = 0;
  if (c.index(*draco, "bufferView", doc.views.size(), "bufferViews", w, &def.view, true) !=
          Got::kOk ||
      c.object(*draco, "attributes", w, &attributes, true) != Got::kOk ||
      c.uinteger(*attributes, "POSITION", w + " attributes", &id, true) != Got::kOk) {
    return std::nullopt;
  }
  if (id > 0xFFFFFFFFull) {
    c.add(w, "attributes POSITION id " + std::to_string(id) + " is out of range");
    return std::nullopt;
  }
  def.position_id = static_cast<std::uint32_t>(id);
  return def;
}

MeshPrimitiveDef validatePrimitive(Checker& c,
                                   const json& p,
                                   const std::string& where,
                                   std::size_t material_count,
                                   const Document& doc) {
  MeshPrimitiveDef pd;
  const json* attributes = nullptr;
  if (c.object(p, "attributes", where, &attributes, true) == Got::kOk) {
    for (auto it = attributes->begin(); it != attributes->end(); ++it) {
      std::int32_t idx = -1;
      if (c.indexValue(it.value(), "attribute " + it.key(), doc.accessors.size(), "accessors",
                       where, &idx) == Got::kOk &&
          it.key() == "POSITION") {
        pd.position = idx;
      }
    }
  }
  c.index(p, "indices", doc.accessors.size(), "accessors", where, &pd.indices);
  pd.draco = validateDraco(c, p, where, doc);
  std::int32_t material = -1;
  c.index(p, "material", material_count, "materials", where, &material);
  std::uint64_t mode = 4;
  if (c.uinteger(p, "mode", where, &mode) == Got::kOk && mode > 6)
    c.add(where, "mode " + std::to_string(mode) + " is not a glTF primitive mode");
  pd.mode = static_cast<std::int32_t>(std::min<std::uint64_t>(mode, 7));
  return pd;
}

/// A node's children (no self), mesh and transform.
void validateNodeShape(Checker& c,
                       const json& n,
                       std::size_t i,
                       std::size_t node_count,
                       const Document& doc,
                       NodeDef* def) {
  const std::string w = nodeWhere(doc, i);
  const json* children = nullptr;
  if (c.array(n, "children", w, &children) == Got::kOk) {
    for (const json& e : *children) {
      std::int32_t child = -1;
      if (c.indexValue(e, "children", node_count, "nodes", w, &child) != Got::kOk)
        continue;
      if (static_cast<std::size_t>(child) == i) {
        c.add(w, "lists itself as a child (a node cycle)");
        continue;
      }
      def->children.push_back(static_cast<std::uint32_t>(child));
    }
  }
  c.index(n, "mesh", doc.meshes.size(), "meshes", w, &def->mesh);
  double m[16];
  const Got matrix = c.vector(n, "matrix", 16, w, m);
  const Got t = c.vec3(n, "translation", w, &def->translation);
  const Got r = c.quaternion(n, "rotation", w, &def->rotation);
  const Got s = c.vec3(n, "scale", w, &def->scale);
  if (matrix != Got::kOk)
    return;
  if (t != Got::kAbsent || r != Got::kAbsent || s != Got::kAbsent)
    c.add(w, "has both matrix and translation/rotation/scale");
  if (m[3] != 0.0 || m[7] != 0.0 || m[11] != 0.0 || m[15] != 1.0)
    c.add(w, "matrix is not affine (its last row must be 0 0 0 1)");
  def->has_matrix = true;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row)
      def->matrix[col][row] = m[col * 4 + row];
  }
}

/// One parent per node, and no cycle (walks up the parent links; a walk that meets its own trail
/// is a cycle).
void validateHierarchy(Checker& c, Document* doc) {
  const std::size_t node_count = doc->nodes.size();
  for (std::size_t i = 0; i < node_count; ++i) {
    for (std::uint32_t child : doc->nodes[i].children) {
      NodeDef& cn = doc->nodes[child];
      if (cn.parent == static_cast<std::int32_t>(i)) {
        c.add(nodeWhere(*doc, child),
              "is listed twice among the children of " + nodeWhere(*doc, i));
      } else if (cn.parent >= 0) {
        c.add(nodeWhere(*doc, child), "has two parents (" +
                                          nodeWhere(*doc, static_cast<std::size_t>(cn.parent)) +
                                          " and " + nodeWhere(*doc, i) + ")");
      } else {
        cn.parent = static_cast<std::int32_t>(i);
      }
    }
  }
  std::vector<std::uint8_t> state(node_count, 0);  // 0 new, 1 on the current walk, 2 done
  std::vector<std::size_t> trail;
  for (std::size_t i = 0; i < node_count; ++i) {
    trail.clear();
    std::size_t k = i;
    bool cycle = false;
    while (state[k] != 2) {
      if (state[k] == 1) {
        cycle = true;
        break;
      }
      state[k] = 1;
      trail.push_back(k);
      if (doc->nodes[k].parent < 0)
        break;
      k = static_cast<std::size_t>(doc->nodes[k].parent);
    }
    if (cycle)
      c.add(nodeWhere(*doc, k), "is in a cycle of node children");
    for (std::size_t t : trail)
      state[t] = 2;
  }
}

/// A scene's root list: in range, no parent, listed once.
std::vector<std::uint32_t> sceneRoots(Checker& c,
                                      const json& s,
                                      const std::string& where,
                                      const Document& doc) {
  std::vector<std::uint32_t> roots;
  std::vector<bool> listed(doc.nodes.size(), false);
  const json* list = nullptr;
  if (c.array(s, "nodes", where, &list) != Got::kOk)
    return roots;
  for (const json& e : *list) {
    std::int32_t idx = -1;
    if (c.indexValue(e, "nodes", doc.nodes.size(), "nodes", where, &idx) != Got::kOk)
      continue;
    const auto k = static_cast<std::size_t>(idx);
    if (doc.nodes[k].parent >= 0) {
      c.add(where, nodeWhere(doc, k) + " is listed as a root but has a parent");
    } else if (listed[k]) {
      c.add(where, nodeWhere(doc, k) + " is listed twice");
    } else {
      listed[k] = true;
      roots.push_back(static_cast<std::uint32_t>(idx));
    }
  }
  return roots;
}

/// extensionsRequired and extensionsUsed by what each changes: physics and geometry ones are
/// read; appearance-only ones ignored with a note; an unknown required one is refused by name,
/// an unknown used one noted.
void validateExtensionLists(Checker& c, const json& root, TopLevel* top, Document* doc) {
  std::vector<std::string> required, used;
  c.strings(root, "extensionsRequired", "extensionsRequired", &required);
  c.strings(root, "extensionsUsed", "extensionsUsed", &used);
  std::string ignored, unknown;
  for (const std::string& e : required) {
    if (extensionKind(e) != ExtensionKind::kUnknown)
      continue;
    std::string readable;
    for (const ExtensionKind k : {ExtensionKind::kPhysics, ExtensionKind::kGeometry}) {
      for (const std::string_view n : extensionsOf(k))
        readable += (readable.empty() ? "" : ", ") + std::string(n);
    }
    c.add("extensionsRequired", "unsupported required extension " + inQuotes(e) +
                                    " (it may change what is touched; hapticd reads " + readable +
                                    " and ignores the appearance-only ones listed in "
                                    "docs/scenes.md)");
  }
  for (const std::string& e : used) {
    const ExtensionKind kind = extensionKind(e);
    if (kind == ExtensionKind::kAppearance)
      ignored += (ignored.empty() ? "" : ", ") + e;
    else if (kind == ExtensionKind::kUnknown)
      unknown += (unknown.empty() ? "" : ", ") + e;
    if (declaresPhysics(e))
      doc->physics = true;
    top->meshopt_used |= e == kMeshoptNames[0] || e == kMeshoptNames[1];
  }
  if (!ignored.empty())
    c.problems().note("ignored (appearance only): " + ignored);
  if (!unknown.empty())
    c.problems().note("not read (unknown, not required): " + unknown);
}

}  // namespace

bool validateTopLevel(Checker& c, const json& root, TopLevel* top, Document* doc) {
  if (c.object(root, "asset", "asset", &top->asset, true) == Got::kOk) {
    std::string version;
    if (c.string(*top->asset, "version", "asset", &version, true) == Got::kOk &&
        version.rfind("2.", 0) != 0) {
      c.add("asset", "glTF version " + inQuotes(version) + " is not 2.x");
    }
  }
  validateExtensionLists(c, root, top, doc);
  bool structure_ok = true;
  const auto arrayOfObjects = [&](const char* key) -> const json* {
    const json* a = nullptr;
    const Got got = c.array(root, key, key, &a);
    if (got == Got::kBad)
      structure_ok = false;
    if (got != Got::kOk)
      return nullptr;
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (!(*a)[i].is_object()) {
        structure_ok = false;
        c.add(std::string(key) + " " + std::to_string(i),
              "must be an object, got " + std::string((*a)[i].type_name()));
        return nullptr;
      }
    }
    return a;
  };
  top->buffers = arrayOfObjects("buffers");
  top->views = arrayOfObjects("bufferViews");
  top->accessors = arrayOfObjects("accessors");
  top->meshes = arrayOfObjects("meshes");
  top->nodes = arrayOfObjects("nodes");
  top->scenes = arrayOfObjects("scenes");
  top->materials = arrayOfObjects("materials");
  top->images = arrayOfObjects("images");
  return structure_ok;
}

void validateMeshes(Checker& c, const TopLevel& top, Document* doc) {
  if (!top.meshes)
    return;
  const std::size_t material_count = top.materials ? top.materials->size() : 0;
  for (std::size_t i = 0; i < top.meshes->size(); ++i) {
    const json& m = (*top.meshes)[i];
    MeshDef def;
    c.string(m, "name", "mesh " + std::to_string(i), &def.name);
    const std::string w =
        "mesh " + std::to_string(i) + (def.name.empty() ? "" : " " + inQuotes(def.name));
    const json* prims = nullptr;
    if (c.array(m, "primitives", w, &prims, true) == Got::kOk) {
      if (prims->empty())
        c.add(w, "primitives is empty");
      for (std::size_t k = 0; k < prims->size(); ++k) {
        const std::string pw = w + " primitive " + std::to_string(k);
        if (!(*prims)[k].is_object()) {
          c.add(pw, "must be an object");
          continue;
        }
        def.primitives.push_back(validatePrimitive(c, (*prims)[k], pw, material_count, *doc));
      }
    }
    doc->meshes.push_back(def);
  }
}

bool validateNodes(Checker& c, const TopLevel& top, const SceneLimits& limits, Document* doc) {
  const std::size_t node_count = top.nodes ? top.nodes->size() : 0;
  if (node_count > limits.max_nodes) {
    c.add("nodes", std::to_string(node_count) + " nodes exceeds max_nodes (" +
                       std::to_string(limits.max_nodes) + ")");
    return false;
  }
  doc->nodes.resize(node_count);
  // names first: every message about a node names it
  for (std::size_t i = 0; i < node_count; ++i)
    c.string((*top.nodes)[i], "name", "node " + std::to_string(i), &doc->nodes[i].name);
  for (std::size_t i = 0; i < node_count; ++i) {
    const json& n = (*top.nodes)[i];
    NodeDef& def = doc->nodes[i];
    validateNodeShape(c, n, i, node_count, *doc, &def);
    const std::string w = nodeWhere(*doc, i);
    const json* ext = nullptr;
    if (c.object(n, "extensions", w, &ext) == Got::kOk) {
      const json* physics = nullptr;
      if (c.object(*ext, "KHR_physics_rigid_bodies", w + " extensions", &physics) == Got::kOk) {
        validateNodePhysics(c, *physics, w, *doc, &def);
        doc->physics = true;
      } else {
        validateOmiNode(c, *ext, w, *doc, &def);
        doc->physics |= Checker::find(*ext, "OMI_physics_body") != nullptr ||
                        Checker::find(*ext, "OMI_collider") != nullptr;
      }
    }
    HapticExtras extras;
    validateHapticExtras(c, n, w, &extras);
    def.probe = extras.probe;
    def.stiffness = extras.stiffness;
    def.active = extras.active;
    def.concavity = extras.concavity;
  }
  validateHierarchy(c, doc);
  return true;
}

void validateScenes(Checker& c, const json& root, const TopLevel& top, Document* doc) {
  std::vector<std::vector<std::uint32_t>> scene_nodes;
  if (top.scenes) {
    for (std::size_t i = 0; i < top.scenes->size(); ++i)
      scene_nodes.push_back(sceneRoots(c, (*top.scenes)[i], "scene " + std::to_string(i), *doc));
  }
  std::int32_t scene = scene_nodes.empty() ? -1 : 0;
  c.index(root, "scene", scene_nodes.size(), "scenes", "file", &scene);
  if (scene >= 0) {
    const auto si = static_cast<std::size_t>(scene);
    doc->scene_roots = scene_nodes[si];
    HapticExtras extras;
    extras.node = false;
    const std::string w = "scene " + std::to_string(scene);
    validateHapticExtras(c, (*top.scenes)[si], w, &extras);
    if (extras.gravity) {
      doc->gravity = extras.gravity;
      doc->gravity_where = w;
    }
  } else {
    // no scenes: every root node is in the scene
    for (std::size_t i = 0; i < doc->nodes.size(); ++i) {
      if (doc->nodes[i].parent < 0)
        doc->scene_roots.push_back(static_cast<std::uint32_t>(i));
    }
  }
  if (top.asset) {
    HapticExtras extras;
    extras.node = false;
    validateHapticExtras(c, *top.asset, "asset", &extras);
    const std::optional<Vec3>& g = extras.gravity;
    if (g && doc->gravity && *g != *doc->gravity) {
      c.add("asset", "gravity differs from the gravity of " + doc->gravity_where);
    } else if (g && !doc->gravity) {
      doc->gravity = g;
      doc->gravity_where = "asset";
    }
  }
}

}  // namespace hapticd::scene::detail
