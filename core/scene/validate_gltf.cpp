// The validation walk over core glTF: the top level, buffers, views, accessors, meshes, nodes and
// their hierarchy, scenes (document.h).
#include <algorithm>

#include "core/scene/document.h"
#include "core/scene/glb.h"
#include "core/scene/uri.h"

namespace hapticd::scene::detail {
namespace {

const char* const kSupportedExtensions[] = {"KHR_physics_rigid_bodies", "KHR_implicit_shapes"};

/// a + b and a * b, false on 64-bit overflow
bool addU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_add_overflow(a, b, out);
}
bool mulU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_mul_overflow(a, b, out);
}

/// An external URI checked against the folder policy: the resolved file, or a problem.
std::string checkUri(Checker& c,
                     const std::string& uri,
                     const LoadOptions& options,
                     const std::string& where) {
  std::string why;
  const auto path = resolveUri(uri, options, &why);
  if (!path)
    c.add(where, why);
  return path.value_or("");
}

void validateBuffers(Checker& c, const json& buffers, const LoadOptions& options, Document* doc) {
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const json& b = buffers[i];
    const std::string w = "buffer " + std::to_string(i);
    BufferDef def;
    if (c.uinteger(b, "byteLength", w, &def.byte_length, true) == Got::kOk &&
        def.byte_length == 0) {
      c.add(w, "byteLength must be at least 1");
    }
    if (c.string(b, "uri", w, &def.uri) == Got::kOk) {
      if (!isDataUri(def.uri))
        def.path = checkUri(c, def.uri, options, w);
    } else if (!(doc->glb && i == 0)) {
      c.add(w, "has no uri and is not the GLB binary chunk");
    } else if (def.byte_length > doc->bin.size()) {
      c.add(w, "byteLength " + std::to_string(def.byte_length) + " exceeds the GLB BIN chunk (" +
                   std::to_string(doc->bin.size()) + " bytes)");
    }
    doc->buffers.push_back(def);
  }
}

void validateViews(Checker& c, const json& views, Document* doc) {
  for (std::size_t i = 0; i < views.size(); ++i) {
    const json& v = views[i];
    const std::string w = "bufferView " + std::to_string(i);
    ViewDef def;
    std::int32_t buffer = -1;
    const Got gb = c.index(v, "buffer", doc->buffers.size(), "buffers", w, &buffer, true);
    c.uinteger(v, "byteOffset", w, &def.byte_offset);
    const Got gl = c.uinteger(v, "byteLength", w, &def.byte_length, true);
    if (c.uinteger(v, "byteStride", w, &def.byte_stride) == Got::kOk &&
        (def.byte_stride < 4 || def.byte_stride > 252 || def.byte_stride % 4 != 0)) {
      c.add(w, "byteStride " + std::to_string(def.byte_stride) +
                   " must be a multiple of 4 in [4, 252]");
    }
    if (gb == Got::kOk && gl == Got::kOk) {
      def.buffer = static_cast<std::uint32_t>(buffer);
      std::uint64_t end = 0;
      const std::uint64_t blen = doc->buffers[def.buffer].byte_length;
      if (!addU64(def.byte_offset, def.byte_length, &end) || end > blen) {
        c.add(w, "byteOffset " + std::to_string(def.byte_offset) + " + byteLength " +
                     std::to_string(def.byte_length) + " runs past the end of buffer " +
                     std::to_string(def.buffer) + " (" + std::to_string(blen) + " bytes)");
      }
    }
    doc->views.push_back(def);
  }
}

/// The accessor's data lies inside its view: offset + (count - 1) * stride + element <= length,
/// in 64 bits with overflow checks (a count near 2^32 must not wrap).
void checkAccessorRange(Checker& c,
                        const AccessorDef& def,
                        const Document& doc,
                        const std::string& where) {
  if (def.view < 0 || def.component_type == 0 || def.components == 0 || def.count == 0)
    return;
  const ViewDef& view = doc.views[static_cast<std::size_t>(def.view)];
  const std::uint64_t element = def.elementBytes();
  const std::uint64_t stride = def.strideBytes(doc.views);
  std::uint64_t span = 0, end = 0;
  const bool fits = mulU64(def.count - 1, stride, &span) && addU64(span, element, &span) &&
                    addU64(span, def.byte_offset, &end);
  if (!fits || end > view.byte_length) {
    c.add(where, "byteOffset " + std::to_string(def.byte_offset) + " + count " +
                     std::to_string(def.count) + " x stride " + std::to_string(stride) +
                     (fits ? " = " + std::to_string(end) : std::string(" overflows and")) +
                     " runs past the end of bufferView " + std::to_string(def.view) + " (" +
                     std::to_string(view.byte_length) + " bytes)");
  }
  if (def.byte_offset % componentBytes(def.component_type) != 0) {
    c.add(where, "byteOffset " + std::to_string(def.byte_offset) +
                     " is not a multiple of the component size");
  }
}

void validateAccessors(Checker& c, const json& accessors, Document* doc) {
  for (std::size_t i = 0; i < accessors.size(); ++i) {
    const json& a = accessors[i];
    const std::string w = "accessor " + std::to_string(i);
    AccessorDef def;
    std::string name;
    c.string(a, "name", w, &name);
    const std::string wn = name.empty() ? w : w + " " + inQuotes(name);
    c.index(a, "bufferView", doc->views.size(), "bufferViews", wn, &def.view);
    c.uinteger(a, "byteOffset", wn, &def.byte_offset);
    std::uint64_t ct = 0;
    if (c.uinteger(a, "componentType", wn, &ct, true) == Got::kOk) {
      if (componentBytes(ct) == 0)
        c.add(wn, "componentType " + std::to_string(ct) + " is not a glTF component type");
      else
        def.component_type = static_cast<std::uint32_t>(ct);
    }
    if (c.uinteger(a, "count", wn, &def.count, true) == Got::kOk && def.count == 0)
      c.add(wn, "count must be at least 1");
    if (c.string(a, "type", wn, &def.type, true) == Got::kOk) {
      def.components = typeComponents(def.type);
      if (def.components == 0)
        c.add(wn, "type " + inQuotes(def.type) + " is not a glTF type");
    }
    c.boolean(a, "normalized", wn, &def.normalized);
    if (Checker::find(a, "sparse"))
      c.add(wn, "sparse accessors are not supported");
    checkAccessorRange(c, def, *doc, wn);
    doc->accessors.push_back(def);
  }
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

}  // namespace

bool validateTopLevel(Checker& c, const json& root, TopLevel* top) {
  if (c.object(root, "asset", "asset", &top->asset, true) == Got::kOk) {
    std::string version;
    if (c.string(*top->asset, "version", "asset", &version, true) == Got::kOk &&
        version.rfind("2.", 0) != 0) {
      c.add("asset", "glTF version " + inQuotes(version) + " is not 2.x");
    }
  }
  std::vector<std::string> required;
  if (c.strings(root, "extensionsRequired", "extensionsRequired", &required) == Got::kOk) {
    for (const std::string& e : required) {
      if (std::find(std::begin(kSupportedExtensions), std::end(kSupportedExtensions), e) ==
          std::end(kSupportedExtensions)) {
        c.add("extensionsRequired", "unsupported required extension " + inQuotes(e) +
                                        " (supported: KHR_physics_rigid_bodies, "
                                        "KHR_implicit_shapes)");
      }
    }
  }
  std::vector<std::string> used;
  c.strings(root, "extensionsUsed", "extensionsUsed", &used);

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

void validateData(Checker& c, const TopLevel& top, const LoadOptions& options, Document* doc) {
  if (top.buffers)
    validateBuffers(c, *top.buffers, options, doc);
  if (top.images) {
    for (std::size_t i = 0; i < top.images->size(); ++i) {
      std::string uri;
      const std::string w = "image " + std::to_string(i);
      if (c.string((*top.images)[i], "uri", w, &uri) == Got::kOk && !isDataUri(uri))
        checkUri(c, uri, options, w);
    }
  }
  if (top.views)
    validateViews(c, *top.views, doc);
  if (top.accessors)
    validateAccessors(c, *top.accessors, doc);
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
      if (c.object(*ext, "KHR_physics_rigid_bodies", w + " extensions", &physics) == Got::kOk)
        validateNodePhysics(c, *physics, w, *doc, &def);
    }
    HapticExtras extras;
    validateHapticExtras(c, n, w, &extras);
    def.probe = extras.probe;
    def.stiffness = extras.stiffness;
    def.active = extras.active;
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
