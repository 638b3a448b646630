#include "scenes/glb_builder.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/scene/glb.h"

namespace hapticd::scenes {
namespace {

// a last-bit difference in a libm result changes the rounded float only when the double lies
// within that bit of a float rounding boundary (about 2^-29 of all values): the float cast is the
// quantization
float vertexCoordinate(double x) {
  return static_cast<float>(x);
}

}  // namespace

double quantize(double x) {
  if (!std::isfinite(x))
    throw std::invalid_argument("scene generator: non-finite number");
  if (std::fabs(x) < 1e-12)
    return 0.0;
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::scientific, 9);
  double y = 0.0;
  std::from_chars(buf, r.ptr, y, std::chars_format::scientific);
  return y;
}

Json jsonVec(const Vec3& v) {
  return Json::array({quantize(v.x), quantize(v.y), quantize(v.z)});
}

Json jsonQuatAxisAngle(const Vec3& axis, double angle_rad) {
  const Vec3 a = glm::normalize(axis);
  const double s = std::sin(0.5 * angle_rad);
  return Json::array({quantize(a.x * s), quantize(a.y * s), quantize(a.z * s),
                      quantize(std::cos(0.5 * angle_rad))});
}

int GltfBuilder::addRenderMaterial(const std::string& name,
                                   const std::array<double, 4>& rgba,
                                   double metallic,
                                   double roughness) {
  Json m;
  m["name"] = name;
  m["pbrMetallicRoughness"] = {
      {"baseColorFactor",
       Json::array({quantize(rgba[0]), quantize(rgba[1]), quantize(rgba[2]), quantize(rgba[3])})},
      {"metallicFactor", quantize(metallic)},
      {"roughnessFactor", quantize(roughness)}};
  render_materials_.push_back(std::move(m));
  return static_cast<int>(render_materials_.size()) - 1;
}

int GltfBuilder::addView(const void* data, std::size_t bytes, int target) {
  // every view starts on a 4-byte boundary (float and uint32 alignment)
  while (bin_.size() % 4 != 0)
    bin_.push_back(0);
  const std::size_t offset = bin_.size();
  bin_.resize(offset + bytes);
  std::memcpy(bin_.data() + offset, data, bytes);
  buffer_views_.push_back(
      {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
  return static_cast<int>(buffer_views_.size()) - 1;
}

int GltfBuilder::addMesh(const std::string& name, const MeshData& mesh, int render_material) {
  if (mesh.positions.empty() || mesh.triangles.empty())
    throw std::invalid_argument("scene generator: empty mesh " + name);

  std::vector<float> xyz;
  xyz.reserve(mesh.positions.size() * 3);
  std::array<float, 3> lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                          std::numeric_limits<float>::max()};
  std::array<float, 3> hi{-lo[0], -lo[1], -lo[2]};
  for (const Vec3& p : mesh.positions) {
    for (int k = 0; k < 3; ++k) {
      const float f = vertexCoordinate(p[k]);
      xyz.push_back(f);
      lo[static_cast<std::size_t>(k)] = std::min(lo[static_cast<std::size_t>(k)], f);
      hi[static_cast<std::size_t>(k)] = std::max(hi[static_cast<std::size_t>(k)], f);
    }
  }
  const int pos_view = addView(xyz.data(), xyz.size() * sizeof(float), scene::kTargetArrayBuffer);
  Json pos_accessor = {{"bufferView", pos_view},
                       {"componentType", scene::kComponentFloat},
                       {"count", mesh.positions.size()},
                       {"type", "VEC3"},
                       {"min", Json::array({lo[0], lo[1], lo[2]})},
                       {"max", Json::array({hi[0], hi[1], hi[2]})}};
  accessors_.push_back(std::move(pos_accessor));
  const int pos_index = static_cast<int>(accessors_.size()) - 1;

  const std::size_t n_index = mesh.triangles.size() * 3;
  int index_view = 0;
  std::uint32_t component = 0;
  if (mesh.positions.size() <= 65535) {
    std::vector<std::uint16_t> idx;
    idx.reserve(n_index);
    for (const auto& t : mesh.triangles)
      for (std::uint32_t i : t) {
        if (i >= mesh.positions.size())
          throw std::invalid_argument("scene generator: index out of range in " + name);
        idx.push_back(static_cast<std::uint16_t>(i));
      }
    index_view =
        addView(idx.data(), idx.size() * sizeof(std::uint16_t), scene::kTargetElementArrayBuffer);
    component = scene::kComponentUnsignedShort;
  } else {
    std::vector<std::uint32_t> idx;
    idx.reserve(n_index);
    for (const auto& t : mesh.triangles)
      for (std::uint32_t i : t)
        idx.push_back(i);
    index_view =
        addView(idx.data(), idx.size() * sizeof(std::uint32_t), scene::kTargetElementArrayBuffer);
    component = scene::kComponentUnsignedInt;
  }
  accessors_.push_back({{"bufferView", index_view},
                        {"componentType", component},
                        {"count", n_index},
                        {"type", "SCALAR"}});
  const int index_accessor = static_cast<int>(accessors_.size()) - 1;

  Json prim = {{"attributes", {{"POSITION", pos_index}}},
               {"indices", index_accessor},
               {"mode", scene::kModeTriangles}};
  if (render_material >= 0)
    prim["material"] = render_material;
  meshes_.push_back({{"name", name}, {"primitives", Json::array({std::move(prim)})}});
  return static_cast<int>(meshes_.size()) - 1;
}

int GltfBuilder::addNode(Json node) {
  nodes_.push_back(std::move(node));
  return static_cast<int>(nodes_.size()) - 1;
}

void GltfBuilder::addChild(int parent, int child) {
  Json& p = node(parent);
  if (!p.contains("children"))
    p["children"] = Json::array();
  p["children"].push_back(child);
}

int GltfBuilder::addShape(Json shape) {
  shapes_.push_back(std::move(shape));
  return static_cast<int>(shapes_.size()) - 1;
}

int GltfBuilder::addPhysicsMaterial(Json material) {
  physics_materials_.push_back(std::move(material));
  return static_cast<int>(physics_materials_.size()) - 1;
}

int GltfBuilder::addPhysicsJoint(Json joint) {
  physics_joints_.push_back(std::move(joint));
  return static_cast<int>(physics_joints_.size()) - 1;
}

std::vector<std::uint8_t> GltfBuilder::finish(const std::string& scene_name) const {
  Json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "hapticd make_scenes"}};
  Json used = Json::array();
  if (!shapes_.empty())
    used.push_back("KHR_implicit_shapes");
  used.push_back("KHR_physics_rigid_bodies");
  doc["extensionsUsed"] = used;
  doc["extensionsRequired"] = used;

  Json physics = Json::object();
  if (!physics_materials_.empty())
    physics["physicsMaterials"] = physics_materials_;
  if (!physics_joints_.empty())
    physics["physicsJoints"] = physics_joints_;
  Json extensions = Json::object();
  if (!physics.empty())
    extensions["KHR_physics_rigid_bodies"] = physics;
  if (!shapes_.empty())
    extensions["KHR_implicit_shapes"] = {{"shapes", shapes_}};
  if (!extensions.empty())
    doc["extensions"] = extensions;

  Json nodes = Json::array();
  for (const Json& n : nodes_)
    nodes.push_back(n);
  doc["nodes"] = nodes;
  Json scene = {{"name", scene_name}, {"nodes", roots_}};
  if (!scene_extras_.is_null())
    scene["extras"] = scene_extras_;
  doc["scenes"] = Json::array({scene});
  doc["scene"] = 0;
  if (!meshes_.empty())
    doc["meshes"] = meshes_;
  if (!render_materials_.empty())
    doc["materials"] = render_materials_;
  if (!accessors_.empty())
    doc["accessors"] = accessors_;
  if (!buffer_views_.empty())
    doc["bufferViews"] = buffer_views_;
  std::vector<std::uint8_t> bin = bin_;
  while (bin.size() % 4 != 0)
    bin.push_back(0);
  if (!bin.empty())
    doc["buffers"] = Json::array({{{"byteLength", bin.size()}}});
  return scene::packGlb(doc.dump(), bin);
}

}  // namespace hapticd::scenes
