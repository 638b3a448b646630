// glTF as exporters write it: extensions by what they change (appearance ignored with a note,
// unknown required ones refused by name), quantized positions of every component type, sparse
// accessors, Draco and meshopt compressed geometry (the same model as the plain data), buffers
// beside a file, the bundle hapticctl load sends, plain models as static geometry.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "core/scene/bundle.h"
#include "core/scene/glb.h"
#include "core/scene/loader.h"
#include "tests/core/scene/corpus.h"
#include "tests/core/scene/encoded_mesh.h"
#include "tests/core/scene/scene_test_util.h"

namespace hapticd::scene {
namespace {

using testing::GltfBuilder;
using testing::hasProblem;
using testing::json;
using testing::load;
using testing::notesOf;

/// A static node whose collider is the mesh `mesh` (its own node).
/// A static node whose collider is its own mesh (its convex hull when `hull`).
void meshNode(GltfBuilder& b,
              int mesh,
              const std::string& name,
              Vec3 t = Vec3{0.0},
              bool hull = false) {
  json n = GltfBuilder::node(name, t);
  n["mesh"] = mesh;
  const auto index = static_cast<int>(b.doc["nodes"].size());
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", index}}}};
  if (hull)
    GltfBuilder::physics(n)["collider"]["geometry"]["convexHull"] = true;
  b.addNode(n);
  b.useExtension("KHR_physics_rigid_bodies", false);
}

/// The hull vertices of a body's only primitive, in the scene frame, sorted.
std::vector<Vec3> hullOf(const LoadReport& r, std::size_t body = 0) {
  EXPECT_TRUE(r.ok()) << r.message();
  if (!r.ok())
    return {};
  const Body& b = r.scene->bodies[body];
  std::vector<Vec3> out;
  for (const auto& v : b.primitives.at(0).shape->vertices())
    out.push_back(b.X_WB.toTransform().apply(b.primitives[0].X_BP.toTransform().apply(v.p)));
  std::sort(out.begin(), out.end(), [](const Vec3& a, const Vec3& c) {
    return std::tie(a.x, a.y, a.z) < std::tie(c.x, c.y, c.z);
  });
  return out;
}

void expectSameHull(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_LE(glm::length(a[i] - b[i]), tol) << i;
}

TEST(SceneFormats, AppearanceExtensionsAreIgnoredWithANoteUnknownRequiredOnesRefused) {
  GltfBuilder b = testing::baseScene();
  for (const char* e : {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                        "KHR_texture_transform", "KHR_materials_variants"})
    b.useExtension(e, true);
  b.useExtension("ACME_sparkles", false);  // unknown but optional: noted
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const std::string notes = notesOf(*r.scene);
  EXPECT_NE(notes.find("ignored (appearance only): KHR_lights_punctual, "
                       "KHR_materials_emissive_strength, KHR_texture_transform, "
                       "KHR_materials_variants"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("not read (unknown, not required): ACME_sparkles"), std::string::npos);
  EXPECT_NE(describePlan(r.scene->plan).find("notes:\n  ignored (appearance only)"),
            std::string::npos);

  b.useExtension("EXT_mesh_gpu_instancing", true);
  const LoadReport refused = load(b);
  EXPECT_FALSE(refused.ok());
  EXPECT_TRUE(hasProblem(refused,
                         "extensionsRequired: unsupported required extension "
                         "'EXT_mesh_gpu_instancing' (it may change what is touched"))
      << refused.message();
}

TEST(SceneFormats, QuantizedPositionsOfEveryComponentTypeGiveTheSameHull) {
  // a unit cube [-0.5, 0.5]^3 as float, then quantized: normalized signed types store the
  // coordinates (the node scales 1); unsigned normalized ones a cube [0, 1]^3 moved back by the
  // node; unnormalized ones integers scaled down by the node (as gltfpack writes them)
  GltfBuilder ref;
  meshNode(ref, ref.addMesh(testing::cubeMesh(), "Cube"), "Cube");
  const std::vector<Vec3> expected = hullOf(load(ref));
  for (const std::uint32_t component : {5120u, 5121u, 5122u, 5123u}) {
    for (const bool normalized : {true, false}) {
      SCOPED_TRACE(std::to_string(component) + (normalized ? " normalized" : ""));
      // stored values that are exact: normalized signed +-1 (the node halves them), unsigned
      // [0, 1] or [0, unit] moved back by -0.5; unnormalized integers scaled down by the node
      const bool is_signed = component == 5120 || component == 5122;
      const double unit = normalized ? 1.0 : (component <= 5121 ? 100.0 : 10000.0);
      const double half = normalized && is_signed ? 1.0 : 0.5 * unit;
      const double scale = normalized ? (is_signed ? 0.5 : 1.0) : 1.0 / unit;
      testing::Mesh m = testing::cubeMesh(half);
      if (!is_signed) {
        for (Vec3& v : m.vertices)
          v += Vec3{half};
      }
      GltfBuilder b;
      const int mesh = testing::addQuantizedMesh(b, m, component, normalized, "Q");
      json n = GltfBuilder::node("Cube", is_signed ? Vec3{0.0} : Vec3{-0.5});
      n["mesh"] = mesh;
      n["scale"] = {scale, scale, scale};
      GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}}}};
      b.addNode(n);
      expectSameHull(hullOf(load(b)), expected, 1e-6);
    }
  }
  // what the extension does not allow: UNSIGNED_INT positions, normalized floats
  for (const auto& [key, value] : {std::pair<const char*, json>{"componentType", 5125},
                                   std::pair<const char*, json>{"normalized", true}}) {
    GltfBuilder bad;
    meshNode(bad, bad.addMesh(testing::cubeMesh(), "Cube"), "Cube");
    bad.doc["accessors"][0][key] = value;
    const LoadReport r = load(bad);
    EXPECT_TRUE(hasProblem(r, "must be VEC3 of FLOAT, or (KHR_mesh_quantization) of BYTE"))
        << r.message();
  }
}

TEST(SceneFormats, SparseAccessorsReplaceTheirElements) {
  // a cube whose vertex 7 is pulled out to (1, 1, 1) by sparse storage
  testing::Mesh cube = testing::cubeMesh();
  GltfBuilder b;
  const int pa = testing::addSparsePositions(b, cube.vertices, true, {7}, {Vec3{1.0}});
  const int iv = b.addView(cube.triangles.data(), cube.triangles.size() * 4);
  const int ia = b.addAccessor(
      {{"bufferView", iv}, {"componentType", 5125}, {"count", 36}, {"type", "SCALAR"}});
  b.doc["meshes"].push_back(
      {{"primitives", json::array({{{"attributes", {{"POSITION", pa}}}, {"indices", ia}}})}});
  json n = GltfBuilder::node("Pulled");
  n["mesh"] = 0;
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}, {"convexHull", true}}}};
  b.addNode(n);
  const std::vector<Vec3> hull = hullOf(load(b));
  ASSERT_FALSE(hull.empty());
  EXPECT_EQ(hull.back(), Vec3{1.0});
  // no base bufferView: zeros under the sparse values (a tetrahedron with one point at 0)
  GltfBuilder z;
  const int za = testing::addSparsePositions(z, std::vector<Vec3>(4, Vec3{0.0}), false, {1, 2, 3},
                                             {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}});
  z.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", za}}}}})}});
  json zn = GltfBuilder::node("Tet");
  zn["mesh"] = 0;
  GltfBuilder::physics(zn)["collider"] = {{"geometry", {{"node", 0}, {"convexHull", true}}}};
  z.addNode(zn);
  EXPECT_EQ(hullOf(load(z)).size(), 4u);
  // indices past the base, or not increasing: refused
  GltfBuilder past = b;
  const std::uint16_t nine = 9;
  std::memcpy(past.bin.data() + past.doc["bufferViews"][1]["byteOffset"].get<std::size_t>(), &nine,
              2);
  EXPECT_TRUE(hasProblem(load(past), "sparse index 9 (entry 0) runs past the base (8 elements)"))
      << load(past).message();
}

TEST(SceneFormats, DracoAndMeshoptGiveTheModelOfThePlainData) {
  // the hull of the decoded vertices is the plain data's; the decoded surface is as non-convex as
  // the plain one (the decomposition's pieces depend on the triangles' order, which the codecs
  // may change, so they are not compared)
  const testing::Mesh dented = testing::dentedCubeMesh();
  GltfBuilder ref;
  meshNode(ref, ref.addMesh(dented, "Dented"), "Dented", Vec3{0.0}, true);
  const std::vector<Vec3> expected = hullOf(load(ref));
  const auto check = [&](const std::function<int(GltfBuilder&)>& add, double tol) {
    GltfBuilder h, s;
    meshNode(h, add(h), "Dented", Vec3{0.0}, true);
    const LoadReport rh = loadScene(h.glb(), "hull.glb");
    ASSERT_TRUE(rh.ok()) << rh.message();
    expectSameHull(hullOf(rh), expected, tol);
    meshNode(s, add(s), "Dented");
    const LoadReport rs = loadScene(s.glb(), "surface.glb");
    ASSERT_TRUE(rs.ok()) << rs.message();
    ASSERT_GE(rs.scene->bodies[0].primitives.size(), 2u);
    for (const Primitive& p : rs.scene->bodies[0].primitives)
      EXPECT_EQ(p.source, ShapeSource::kMeshPiece);
  };
  {
    SCOPED_TRACE("Draco");
    check([&](GltfBuilder& b) { return testing::addDracoMesh(b, dented, "Dented"); },
          1e-4);  // 16-bit Draco quantization
  }
  for (const char* filter : {"NONE", "EXPONENTIAL"}) {
    for (const char* indices : {"TRIANGLES", "INDICES"}) {
      SCOPED_TRACE(std::string(filter) + " " + indices);
      check(
          [&](GltfBuilder& b) {
            return testing::addMeshoptMesh(b, dented, "Dented", filter, indices);
          },
          1e-6);
    }
  }
}

TEST(SceneFormats, MalformedCompressedDataIsRefusedWithItsName) {
  GltfBuilder d;
  meshNode(d, testing::addDracoMesh(d, testing::cubeMesh(), "Cube"), "Cube");
  for (std::size_t i = 8; i < d.bin.size(); ++i)
    d.bin[i] = static_cast<std::uint8_t>(i * 37);
  const LoadReport rd = load(d);
  EXPECT_FALSE(rd.ok());
  EXPECT_TRUE(hasProblem(rd, "KHR_draco_mesh_compression: Draco:")) << rd.message();

  GltfBuilder m;
  meshNode(m, testing::addMeshoptMesh(m, testing::cubeMesh(), "Cube"), "Cube");
  m.bin[0] ^= 0xFF;  // the attribute stream's header
  const LoadReport rm = load(m);
  EXPECT_FALSE(rm.ok());
  EXPECT_TRUE(hasProblem(rm, "bufferView 0 meshopt: meshopt: the attribute codec refused"))
      << rm.message();

  GltfBuilder s;
  meshNode(s, testing::addMeshoptMesh(s, testing::cubeMesh(), "Cube"), "Cube");
  s.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6;
  s.doc["bufferViews"][0]["byteStride"] = 6;
  EXPECT_TRUE(hasProblem(load(s), "byteStride 6 must be a multiple of 4")) << load(s).message();
}

class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hapticd_formats_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "scene");
    std::filesystem::create_directories(dir_ / "daemon");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::filesystem::path& p, const std::vector<std::uint8_t>& bytes) {
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
  /// A .gltf whose buffer is `bin` beside it, the cube of half size `h`.
  void writeBeside(double h) {
    GltfBuilder b;
    meshNode(b, b.addMesh(testing::cubeMesh(h), "Cube"), "Cube");
    json d = b.doc;
    d["buffers"] = json::array({json{{"byteLength", b.bin.size()}, {"uri", "cube.bin"}}});
    write(dir_ / "scene" / "cube.gltf", testing::bytesOf(d.dump()));
    write(dir_ / "scene" / "cube.bin", b.bin);
  }
  std::filesystem::path dir_;
};

TEST_F(SceneFiles, ABufferBesideTheFileIsReadWithTheGuards) {
  writeBeside(0.005);
  const LoadReport r = loadSceneFile(dir_ / "scene" / "cube.gltf");
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_NEAR(r.scene->length_scale, std::sqrt(3.0) * 0.01, 1e-9);
  // the guards still hold beside the file
  std::ifstream in(dir_ / "scene" / "cube.gltf");
  const std::string text(std::istreambuf_iterator<char>(in), {});
  const std::size_t at = text.find("cube.bin");
  for (const char* uri : {"../daemon/cube.bin", "/etc/passwd", "file:cube.bin"}) {
    std::string t = text;
    t.replace(at, 8, uri);
    write(dir_ / "scene" / "escape.gltf", testing::bytesOf(t));
    EXPECT_FALSE(loadSceneFile(dir_ / "scene" / "escape.gltf").ok()) << uri;
  }
  std::filesystem::create_symlink(dir_ / "daemon", dir_ / "scene" / "out");
  std::string t = text;
  t.replace(at, 8, "out/cube.bin");
  write(dir_ / "daemon" / "cube.bin", std::vector<std::uint8_t>(96 + 144, 0));
  write(dir_ / "scene" / "escape.gltf", testing::bytesOf(t));
  EXPECT_TRUE(hasProblem(loadSceneFile(dir_ / "scene" / "escape.gltf"),
                         "resolves outside the allowed folder"));
}

TEST_F(SceneFiles, TheBundleCarriesTheClientsBufferWhateverTheOtherFolderHolds) {
  writeBeside(0.005);
  // the daemon's folder holds a file of the same name: a 20 mm cube
  GltfBuilder other;
  other.addMesh(testing::cubeMesh(0.01), "Cube");
  write(dir_ / "daemon" / "cube.bin", other.bin);
  auto bundled = bundleSceneFile(dir_ / "scene" / "cube.gltf");
  ASSERT_TRUE(bundled) << bundled.error().message;
  ASSERT_TRUE(isGlb(bundled.value()));
  // loaded as an upload would be, with the daemon's folder allowed: the client's 10 mm cube
  LoadOptions daemon;
  daemon.allowed_uri_dir = dir_ / "daemon";
  const LoadReport r = loadScene(bundled.value(), "cube.gltf", daemon);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_NEAR(r.scene->length_scale, std::sqrt(3.0) * 0.01, 1e-9);
  // a self-contained GLB comes back byte for byte
  GltfBuilder glb;
  meshNode(glb, glb.addMesh(testing::cubeMesh(), "Cube"), "Cube");
  EXPECT_EQ(bundleScene(glb.glb(), daemon).value(), glb.glb());
  // an escaping buffer is refused by the bundler, naming the buffer
  std::ifstream in(dir_ / "scene" / "cube.gltf");
  std::string text(std::istreambuf_iterator<char>(in), {});
  text.replace(text.find("cube.bin"), 8, "../daemon/cube.bin");
  write(dir_ / "scene" / "escape.gltf", testing::bytesOf(text));
  auto escape = bundleSceneFile(dir_ / "scene" / "escape.gltf");
  ASSERT_FALSE(escape);
  EXPECT_NE(escape.error().message.find("buffer 0: external URI '../daemon/cube.bin' traverses"),
            std::string::npos)
      << escape.error().message;
}

TEST(SceneFormats, APlainModelIsStaticGeometryOneBodyPerMeshNode) {
  GltfBuilder b;
  const int cube = b.addMesh(testing::cubeMesh(0.1), "Cube");
  const int dented = b.addMesh(testing::dentedCubeMesh(0.1), "Dented");
  testing::Mesh quad;
  quad.vertices = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  quad.triangles = {0, 2, 1, 0, 3, 2};  // facing +y
  const int floor = b.addMesh(quad, "Floor");
  const int group = b.addNode(GltfBuilder::node("Group", {0.0, 0.0, 0.0}));
  for (const auto& [mesh, name, t] :
       {std::tuple{cube, "A", Vec3{0.5, 0.1, 0.0}}, std::tuple{cube, "B", Vec3{-0.5, 0.1, 0.0}},
        std::tuple{dented, "C", Vec3{0.0, 0.1, 0.5}}, std::tuple{floor, "F", Vec3{0.0}}}) {
    json n = GltfBuilder::node(name, t);
    n["mesh"] = mesh;
    b.addNode(n, group);
  }
  const LoadReport r = load(b);
  ASSERT_TRUE(r.ok()) << r.message();
  const SceneModel& s = *r.scene;
  ASSERT_EQ(s.bodies.size(), 4u);
  for (const Body& body : s.bodies)
    EXPECT_EQ(body.motion, Motion::kStatic);
  EXPECT_EQ(testing::bodyNamed(s, "A").primitives[0].source, ShapeSource::kConvexMesh);
  EXPECT_EQ(testing::bodyNamed(s, "A").primitives[0].shape,
            testing::bodyNamed(s, "B").primitives[0].shape);  // one hull for the same mesh
  EXPECT_EQ(testing::bodyNamed(s, "C").primitives[0].source, ShapeSource::kMeshPiece);
  // the flat floor: a slab behind its front face (below), its top at y = 0
  const Body& f = testing::bodyNamed(s, "F");
  double top = -1e9, bottom = 1e9;
  for (const auto& v : f.primitives[0].shape->vertices()) {
    top = std::max(top, v.p.y);
    bottom = std::min(bottom, v.p.y);
  }
  EXPECT_NEAR(top, 0.0, 1e-12);
  EXPECT_NEAR(bottom, -0.05 * std::sqrt(8.0), 1e-9);
  const std::string notes = notesOf(s);
  EXPECT_NE(notes.find("no physics extension: 4 meshes as static geometry"), std::string::npos)
      << notes;
  EXPECT_NE(notes.find("mesh 1 'Dented' primitive 0 (node 3 'C'): not convex"), std::string::npos);
  EXPECT_NE(notes.find("mesh 2 'Floor' primitive 0 (node 4 'F'): flat, given a thickness"),
            std::string::npos);
  EXPECT_TRUE(s.plan.probe_sphere);
  EXPECT_NE(describePlan(s.plan).find("1 moving primitives (one the probe sphere of the config)"),
            std::string::npos);

  // a document with physics keeps to its declared colliders; nothing to touch is a warning
  GltfBuilder declared = b;
  declared.useExtension("KHR_physics_rigid_bodies", false);
  const LoadReport none = load(declared);
  ASSERT_TRUE(none.ok()) << none.message();
  EXPECT_TRUE(none.scene->bodies.empty());
  EXPECT_NE(notesOf(*none.scene).find("warning: nothing to touch"), std::string::npos);
}

}  // namespace
}  // namespace hapticd::scene
