#include "tests/scenes/glb_reader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <utility>

#include "core/scene/glb.h"

namespace hapticd::scenes::testing {
namespace {

std::size_t sizeOf(const Json& array) {
  return array.is_array() ? array.size() : 0;
}

bool inRange(const Json& v, std::size_t n) {
  return v.is_number_integer() && v.get<long long>() >= 0 &&
         static_cast<std::size_t>(v.get<long long>()) < n;
}

/// The raw bytes of an accessor's elements, or empty on any range problem.
std::vector<std::uint8_t> accessorBytes(const Glb& glb, int accessor, std::size_t& elem_size) {
  const Json& a = glb.json["accessors"][static_cast<std::size_t>(accessor)];
  const Json& v = glb.json["bufferViews"][a["bufferView"].get<std::size_t>()];
  elem_size = scene::componentBytes(a["componentType"].get<std::uint64_t>()) *
              scene::typeComponents(a["type"].get<std::string>());
  const std::size_t offset =
      v.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
  const std::size_t bytes = elem_size * a["count"].get<std::size_t>();
  if (offset + bytes > glb.bin.size())
    return {};
  return {glb.bin.begin() + static_cast<std::ptrdiff_t>(offset),
          glb.bin.begin() + static_cast<std::ptrdiff_t>(offset + bytes)};
}

}  // namespace

std::vector<std::uint8_t> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::optional<Glb> splitGlb(const std::vector<std::uint8_t>& b,
                            std::vector<std::string>& problems) {
  // the container as the loader reads it, then what the generator promises beyond it
  const auto chunks = scene::splitGlb(b);
  if (!chunks) {
    problems.push_back(chunks.error().message);
    return std::nullopt;
  }
  const std::string_view text = chunks.value().json;
  const auto last = text.find_last_not_of(' ');
  if (last == std::string_view::npos || text.size() - last - 1 > 3)
    problems.push_back("JSON chunk padding is more than 3 spaces");
  const std::span<const std::uint8_t> bin = chunks.value().bin;
  if (!bin.empty() && bin.data() + bin.size() != b.data() + b.size())
    problems.push_back("BIN chunk does not end the file");
  Glb glb;
  try {
    glb.json = Json::parse(text);
  } catch (const Json::exception& e) {
    problems.push_back(std::string("JSON does not parse: ") + e.what());
    return std::nullopt;
  }
  glb.bin.assign(bin.begin(), bin.end());
  return glb;
}

std::vector<int> parents(const Glb& glb) {
  const Json& nodes = glb.json["nodes"];
  std::vector<int> parent(nodes.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (const Json& c : nodes[i].value("children", Json::array()))
      if (inRange(c, nodes.size()))
        parent[c.get<std::size_t>()] = static_cast<int>(i);
  return parent;
}

std::vector<std::string> checkReferences(const Glb& glb) {
  std::vector<std::string> p;
  const Json& j = glb.json;
  auto need = [&](bool ok, const std::string& what) {
    if (!ok)
      p.push_back(what);
  };
  const std::size_t n_nodes = sizeOf(j.value("nodes", Json()));
  const std::size_t n_meshes = sizeOf(j.value("meshes", Json()));
  const std::size_t n_acc = sizeOf(j.value("accessors", Json()));
  const std::size_t n_views = sizeOf(j.value("bufferViews", Json()));
  const std::size_t n_buffers = sizeOf(j.value("buffers", Json()));
  const std::size_t n_materials = sizeOf(j.value("materials", Json()));

  need(j.contains("asset") && j["asset"].value("version", "") == "2.0", "asset.version is not 2.0");
  need(inRange(j.value("scene", Json()), sizeOf(j.value("scenes", Json()))), "scene out of range");
  for (const Json& s : j.value("scenes", Json::array()))
    for (const Json& n : s.value("nodes", Json::array()))
      need(inRange(n, n_nodes), "scene node out of range");

  // buffers and views
  if (n_buffers > 0) {
    need(n_buffers == 1, "more than one buffer");
    need(!j["buffers"][0].contains("uri"), "the GLB buffer has a uri");
    const std::size_t len = j["buffers"][0]["byteLength"].get<std::size_t>();
    need(len <= glb.bin.size() && glb.bin.size() - len < 4, "buffer byteLength does not match BIN");
  }
  for (std::size_t i = 0; i < n_views; ++i) {
    const Json& v = j["bufferViews"][i];
    need(inRange(v["buffer"], n_buffers),
         "bufferView " + std::to_string(i) + ": buffer out of range");
    const std::size_t end =
        v.value("byteOffset", std::size_t{0}) + v["byteLength"].get<std::size_t>();
    need(end <= glb.bin.size(), "bufferView " + std::to_string(i) + " runs past the buffer");
  }
  for (std::size_t i = 0; i < n_acc; ++i) {
    const Json& a = j["accessors"][i];
    if (!inRange(a["bufferView"], n_views)) {
      p.push_back("accessor " + std::to_string(i) + ": bufferView out of range");
      continue;
    }
    const Json& v = j["bufferViews"][a["bufferView"].get<std::size_t>()];
    const std::size_t elem = scene::componentBytes(a["componentType"].get<std::uint64_t>()) *
                             scene::typeComponents(a["type"].get<std::string>());
    need(elem > 0, "accessor " + std::to_string(i) + ": bad type");
    const std::size_t end =
        a.value("byteOffset", std::size_t{0}) + elem * a["count"].get<std::size_t>();
    need(end <= v["byteLength"].get<std::size_t>(),
         "accessor " + std::to_string(i) + " runs past its view");
    need(a["count"].get<std::size_t>() > 0, "accessor " + std::to_string(i) + " is empty");
  }
  // meshes: positions finite with exact min/max, indices below the vertex count
  for (std::size_t m = 0; m < n_meshes; ++m) {
    for (const Json& prim : j["meshes"][m]["primitives"]) {
      const Json& pos = prim["attributes"]["POSITION"];
      need(inRange(pos, n_acc), "mesh " + std::to_string(m) + ": POSITION out of range");
      need(inRange(prim["indices"], n_acc), "mesh " + std::to_string(m) + ": indices out of range");
      if (prim.contains("material"))
        need(inRange(prim["material"], n_materials), "mesh material out of range");
      if (!p.empty())
        continue;
      const Json& a = j["accessors"][pos.get<std::size_t>()];
      need(a["componentType"] == 5126 && a["type"] == "VEC3", "POSITION is not float VEC3");
      const Mesh mesh = readMesh(glb, static_cast<int>(m));
      need(mesh.positions.size() == a["count"].get<std::size_t>(),
           "mesh " + std::to_string(m) + ": positions unreadable");
      Vec3 lo{1e300}, hi{-1e300};
      for (const Vec3& q : mesh.positions) {
        need(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z), "non-finite position");
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
      }
      for (int k = 0; k < 3; ++k) {
        need(a["min"][static_cast<std::size_t>(k)].get<double>() == lo[k],
             "mesh " + std::to_string(m) + ": POSITION min differs from the data");
        need(a["max"][static_cast<std::size_t>(k)].get<double>() == hi[k],
             "mesh " + std::to_string(m) + ": POSITION max differs from the data");
      }
      for (const auto& t : mesh.triangles)
        for (std::uint32_t i : t)
          need(i < mesh.positions.size(),
               "mesh " + std::to_string(m) + ": vertex index out of range");
      need(mesh.triangles.size() * 3 ==
               j["accessors"][prim["indices"].get<std::size_t>()]["count"].get<std::size_t>(),
           "mesh " + std::to_string(m) + ": index count not a multiple of 3");
    }
  }
  // nodes: references, one parent at most, no cycles
  std::vector<int> parent_count(n_nodes, 0);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    const Json& n = j["nodes"][i];
    if (n.contains("mesh"))
      need(inRange(n["mesh"], n_meshes), "node " + std::to_string(i) + ": mesh out of range");
    for (const Json& c : n.value("children", Json::array())) {
      need(inRange(c, n_nodes), "node " + std::to_string(i) + ": child out of range");
      if (inRange(c, n_nodes))
        ++parent_count[c.get<std::size_t>()];
    }
  }
  for (std::size_t i = 0; i < n_nodes; ++i)
    need(parent_count[i] <= 1, "node " + std::to_string(i) + " has two parents");
  const std::vector<int> parent = parents(glb);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    std::size_t steps = 0;
    for (int k = static_cast<int>(i); k >= 0 && steps <= n_nodes;
         k = parent[static_cast<std::size_t>(k)])
      ++steps;
    need(steps <= n_nodes, "node " + std::to_string(i) + " is in a cycle");
  }
  // the physics extensions
  const Json ext = j.value("extensions", Json::object());
  const Json rb = ext.value("KHR_physics_rigid_bodies", Json::object());
  const std::size_t n_shapes =
      sizeOf(ext.value("KHR_implicit_shapes", Json::object()).value("shapes", Json()));
  const std::size_t n_pmat = sizeOf(rb.value("physicsMaterials", Json()));
  const std::size_t n_joints = sizeOf(rb.value("physicsJoints", Json()));
  const Json used = j.value("extensionsUsed", Json::array());
  auto listed = [&](const char* name) {
    return std::find(used.begin(), used.end(), name) != used.end();
  };
  need(listed("KHR_physics_rigid_bodies"), "KHR_physics_rigid_bodies not in extensionsUsed");
  if (n_shapes > 0)
    need(listed("KHR_implicit_shapes"), "KHR_implicit_shapes not in extensionsUsed");
  for (const Json& r : j.value("extensionsRequired", Json::array()))
    need(std::find(used.begin(), used.end(), r) != used.end(), "a required extension is not used");
  for (std::size_t i = 0; i < n_nodes; ++i) {
    const Json* body = physicsOf(j["nodes"][i]);
    if (body == nullptr)
      continue;
    const std::string at = "node " + std::to_string(i) + ": ";
    if (body->contains("collider")) {
      const Json& c = (*body)["collider"];
      const Json& g = c["geometry"];
      need(g.contains("shape") != g.contains("node"),
           at + "collider needs exactly one of shape, node");
      if (g.contains("shape"))
        need(inRange(g["shape"], n_shapes), at + "shape out of range");
      if (g.contains("node")) {
        need(inRange(g["node"], n_nodes), at + "geometry node out of range");
        if (inRange(g["node"], n_nodes))
          need(j["nodes"][g["node"].get<std::size_t>()].contains("mesh"),
               at + "geometry node has no mesh");
        need(g.value("convexHull", false), at + "mesh collider without convexHull");
      }
      if (c.contains("physicsMaterial"))
        need(inRange(c["physicsMaterial"], n_pmat), at + "physicsMaterial out of range");
    }
    if (body->contains("joint")) {
      const Json& jt = (*body)["joint"];
      need(inRange(jt["connectedNode"], n_nodes), at + "connectedNode out of range");
      need(inRange(jt["joint"], n_joints), at + "joint out of range");
    }
  }
  return p;
}

Mesh readMesh(const Glb& glb, int mesh_index) {
  Mesh out;
  const Json& prim = glb.json["meshes"][static_cast<std::size_t>(mesh_index)]["primitives"][0];
  std::size_t elem = 0;
  const std::vector<std::uint8_t> pos =
      accessorBytes(glb, prim["attributes"]["POSITION"].get<int>(), elem);
  for (std::size_t i = 0; i + 12 <= pos.size(); i += 12) {
    float f[3];
    std::memcpy(f, pos.data() + i, 12);
    out.positions.push_back({f[0], f[1], f[2]});
  }
  const int idx_accessor = prim["indices"].get<int>();
  const std::vector<std::uint8_t> idx = accessorBytes(glb, idx_accessor, elem);
  std::vector<std::uint32_t> flat;
  for (std::size_t i = 0; i + elem <= idx.size() && elem > 0; i += elem) {
    if (elem == 2) {
      std::uint16_t v;
      std::memcpy(&v, idx.data() + i, 2);
      flat.push_back(v);
    } else {
      std::uint32_t v;
      std::memcpy(&v, idx.data() + i, 4);
      flat.push_back(v);
    }
  }
  for (std::size_t i = 0; i + 3 <= flat.size(); i += 3)
    out.triangles.push_back({flat[i], flat[i + 1], flat[i + 2]});
  return out;
}

std::vector<std::string> checkClosedConvex(const Mesh& mesh) {
  std::vector<std::string> p;
  Vec3 lo{1e300}, hi{-1e300};
  for (const Vec3& q : mesh.positions) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  const double size = glm::length(hi - lo);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      ++directed[{t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]}];
  for (const auto& [edge, count] : directed) {
    if (count != 1)
      p.push_back("edge used twice the same way");
    if (directed.find({edge.second, edge.first}) == directed.end())
      p.push_back("open edge");
  }
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Vec3 n = glm::cross(b - a, c - a);
    if (!(glm::length(n) > 1e-12 * size * size)) {
      p.push_back("degenerate triangle");
      continue;
    }
    const Vec3 u = glm::normalize(n);
    for (const Vec3& q : mesh.positions)
      if (glm::dot(q - a, u) > 1e-6 * size) {
        p.push_back("not convex: a vertex in front of a triangle");
        return p;
      }
  }
  return p;
}

Rigid localTransform(const Json& node) {
  Rigid r;
  if (node.contains("translation")) {
    const Json& t = node["translation"];
    r.t = {t[0].get<double>(), t[1].get<double>(), t[2].get<double>()};
  }
  if (node.contains("rotation")) {
    const Json& q = node["rotation"];
    r.q = glm::normalize(
        Quat(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>()));
  }
  return r;
}

Rigid worldTransform(const Glb& glb, int node) {
  const std::vector<int> parent = parents(glb);
  Rigid r = localTransform(glb.json["nodes"][static_cast<std::size_t>(node)]);
  for (int k = parent[static_cast<std::size_t>(node)]; k >= 0;
       k = parent[static_cast<std::size_t>(k)])
    r = localTransform(glb.json["nodes"][static_cast<std::size_t>(k)]) * r;
  return r;
}

const Json* physicsOf(const Json& node) {
  if (!node.contains("extensions"))
    return nullptr;
  const Json& e = node["extensions"];
  if (!e.contains("KHR_physics_rigid_bodies"))
    return nullptr;
  return &e["KHR_physics_rigid_bodies"];
}

int nodeNamed(const Glb& glb, const std::string& name) {
  const Json& nodes = glb.json["nodes"];
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].value("name", "") == name)
      return static_cast<int>(i);
  return -1;
}

std::vector<int> collidersUnder(const Glb& glb, int node) {
  std::vector<int> out;
  std::vector<int> stack{node};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    const Json& nj = glb.json["nodes"][static_cast<std::size_t>(n)];
    const Json* body = physicsOf(nj);
    if (body != nullptr && body->contains("collider"))
      out.push_back(n);
    const Json children = nj.value("children", Json::array());
    for (auto it = children.rbegin(); it != children.rend(); ++it)
      stack.push_back(it->get<int>());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hapticd::scenes::testing
