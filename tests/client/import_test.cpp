// hapticctl import, run as the built binary: every input format, the exit codes and messages, the
// options, --add, and the round trip through `hapticctl check` and a headless hapticd replay that
// presses the probe onto the imported model.
#include "client/import.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/sanitizers.h"
#include "core/decomp/quickhull.h"
#include "scenes/glb_builder.h"
#include "tests/client/command_dir.h"
#include "tests/core/decomp/models.h"
#include "tests/core/scene/encoded_mesh.h"

namespace {

namespace fs = std::filesystem;
using hapticd::decomp::TriangleMesh;
using hapticd::decomp::Vec3;

class ImportTest : public hapticd::testing::CommandDirTest {
 protected:
  ImportTest() : CommandDirTest("hapticd_import") {}
  int import(const std::vector<std::string>& args) {
    std::vector<std::string> all{"import"};
    all.insert(all.end(), args.begin(), args.end());
    return run(HAPTICCTL, all);
  }
};

void writeObj(const TriangleMesh& m, const std::string& p) {
  std::ofstream f(p);
  f << "# an L-block\n";
  for (const Vec3& v : m.positions)
    f << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
  for (const auto& t : m.triangles)
    f << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

Vec3 normalOf(const TriangleMesh& m, const hapticd::decomp::Triangle& t) {
  return glm::normalize(
      glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]));
}

void writeAsciiStl(const TriangleMesh& m, const std::string& p) {
  std::ofstream f(p);
  f << "solid lblock\n";
  for (const auto& t : m.triangles) {
    const Vec3 n = normalOf(m, t);
    f << " facet normal " << n.x << ' ' << n.y << ' ' << n.z << "\n  outer loop\n";
    for (std::uint32_t v : t)
      f << "   vertex " << m.positions[v].x << ' ' << m.positions[v].y << ' ' << m.positions[v].z
        << '\n';
    f << "  endloop\n endfacet\n";
  }
  f << "endsolid lblock\n";
}

// a binary STL whose 80-byte header starts with "solid" (as many exporters write it)
void writeBinaryStl(const TriangleMesh& m, const std::string& p) {
  std::ofstream f(p, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "solid exported by a CAD tool, binary anyway", sizeof header);
  f.write(header, 80);
  const auto count = static_cast<std::uint32_t>(m.triangles.size());
  f.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : m.triangles) {
    const Vec3 n = normalOf(m, t);
    float rec[12] = {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        rec[3 + 3 * k + a] = static_cast<float>(m.positions[t[static_cast<std::size_t>(k)]][a]);
    f.write(reinterpret_cast<const char*>(rec), sizeof rec);
    const std::uint16_t attr = 0;
    f.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

void writePly(const TriangleMesh& m, const std::string& p) {
  std::ofstream f(p);
  f << "ply\nformat ascii 1.0\nelement vertex " << m.positions.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangles.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : m.positions)
    f << v.x << ' ' << v.y << ' ' << v.z << '\n';
  for (const auto& t : m.triangles)
    f << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void writeOff(const TriangleMesh& m, const std::string& p) {
  std::ofstream f(p);
  f << "OFF\n" << m.positions.size() << ' ' << m.triangles.size() << " 0\n";
  for (const Vec3& v : m.positions)
    f << v.x << ' ' << v.y << ' ' << v.z << '\n';
  for (const auto& t : m.triangles)
    f << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

// a glTF binary with the mesh on a node translated by (1, 0, 0): read in world coordinates
void writeGlb(const TriangleMesh& m, const std::string& p) {
  hapticd::scenes::GltfBuilder b;
  hapticd::scenes::MeshData md{m.positions, m.triangles};
  const int mesh = b.addMesh("lblock", md, -1);
  const int node =
      b.addNode({{"name", "lblock"}, {"mesh", mesh}, {"translation", {1.0, 0.0, 0.0}}});
  b.addRoot(node);
  const auto bytes = b.finish("model");
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

TEST_F(ImportTest, EveryFormatImportsAndChecks) {
  const TriangleMesh m = hapticd::decomp::models::lBlock();
  const std::vector<std::pair<std::string, void (*)(const TriangleMesh&, const std::string&)>>
      formats{{"l.obj", writeObj},
              {"l_ascii.stl", writeAsciiStl},
              {"l_binary.stl", writeBinaryStl},
              {"l.ply", writePly},
              {"l.off", writeOff},
              {"l.glb", writeGlb}};
  for (const auto& [file, write] : formats) {
    write(m, path(file));
    ASSERT_EQ(import({path(file), "-o", path("out.glb"), "--json"}), 0) << file << ": " << err();
    const auto report = nlohmann::json::parse(out());
    // two boxes; float32 coordinates (the glTF file) may take one more cut
    const int pieces = report["pieces"].get<int>();
    EXPECT_GE(pieces, 2) << file;
    EXPECT_LE(pieces, 3) << file;
    EXPECT_LE(report["concavity"].get<double>(), 0.01) << file;
    EXPECT_EQ(report["repairs"]["input_triangles"], 112) << file;
    EXPECT_NE(err().find("units: m (assumed"), std::string::npos) << err();
    ASSERT_EQ(run(HAPTICCTL, {"check", path("out.glb"), "--json"}), 0)
        << file << ": " << out() << err();
    const auto check = nlohmann::json::parse(out());
    EXPECT_EQ(check["bodies"][0]["primitives"], pieces) << file;
    EXPECT_EQ(check["primitives"][0]["source"], "mesh hull");
  }
}

TEST_F(ImportTest, BadArgumentsExitTwoWithTheReason) {
  writeObj(hapticd::decomp::models::lBlock(), path("l.obj"));
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{path("l.obj")}, "-o SCENE.glb"},
      {{path("l.obj"), "-o", path("x.gltf")}, ".glb"},
      {{path("l.obj"), "-o", path("x.glb"), "--units", "furlong"},
       "--units must be m, cm, mm or in"},
      {{path("l.obj"), "-o", path("x.glb"), "--role", "ghost"}, "--role must be"},
      {{path("l.obj"), "-o", path("x.glb"), "--concavity", "2"}, "--concavity must be"},
      {{path("l.obj"), "-o", path("x.glb"), "--concavity", "abc"}, "--concavity must be"},
      {{path("l.obj"), "-o", path("x.glb"), "--max-pieces", "0"}, "--max-pieces must be"},
      {{path("l.obj"), "-o", path("x.glb"), "--time-limit", "-1"}, "--time-limit must be"},
      {{path("l.obj"), "-o", path("x.glb"), "--mass", "2"}, "--role dynamic"},
      {{path("l.obj"), "-o", path("x.glb"), "--role", "dynamic", "--mass", "2", "--density", "3"},
       "not both"},
      {{path("l.obj"), "-o", path("x.glb"), "--at", "1", "2", "3"}, "--at needs --add"},
      {{path("l.obj"), "-o", path("x.glb"), "--add", path("s.glb")}, "--add needs --at"}};
  for (const auto& [args, message] : cases) {
    EXPECT_EQ(import(args), 2) << message;
    EXPECT_NE(err().find(message), std::string::npos) << err();
    EXPECT_FALSE(fs::exists(path("x.glb")));
  }
}

TEST_F(ImportTest, UnusableInputExitsOneNamingTheFile) {
  std::ofstream(path("empty.obj")) << "# nothing\n";
  std::ofstream(path("junk.stl")) << "this is not an STL file at all";
  std::ofstream(path("model.xyz")) << "1 2 3\n";
  std::ofstream(path("flat.obj")) << "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {path("missing.obj"), "no such file"},
      {path("empty.obj"), "empty.obj"},
      {path("junk.stl"), "junk.stl"},
      {path("model.xyz"), "unsupported format '.xyz'"},
      {path("flat.obj"), "no usable triangle"}};
  for (const auto& [file, message] : cases) {
    EXPECT_EQ(import({file, "-o", path("x.glb")}), 1) << file << ": " << err();
    EXPECT_NE(err().find(message), std::string::npos) << err();
    EXPECT_FALSE(fs::exists(path("x.glb")));
  }
}

TEST_F(ImportTest, UnitsRoleMassAndJson) {
  TriangleMesh m = hapticd::decomp::models::lBlock();
  for (Vec3& v : m.positions)
    v *= 1000.0;  // the same block in millimetres
  writeObj(m, path("l_mm.obj"));
  ASSERT_EQ(import({path("l_mm.obj"), "-o", path("out.glb"), "--units", "mm", "--role", "dynamic",
                    "--density", "2000", "--json"}),
            0)
      << err();
  const auto j = nlohmann::json::parse(out());
  EXPECT_EQ(j["units"], "mm");
  EXPECT_FALSE(j["units_assumed"].get<bool>());
  EXPECT_EQ(j["pieces"], 2);
  // the block is 0.003 m3 of material: 6 kg at 2000 kg/m3
  EXPECT_NEAR(j["mass_kg"].get<double>(), 6.0, 1e-6);
  EXPECT_EQ(err().find("assumed"), std::string::npos);
  ASSERT_EQ(run(HAPTICCTL, {"check", path("out.glb"), "--json"}), 0) << err();
  const auto c = nlohmann::json::parse(out());
  EXPECT_EQ(c["bodies"][0]["motion"], "dynamic");
  EXPECT_NEAR(c["bodies"][0]["mass_kg"].get<double>(), 6.0, 1e-5);
  EXPECT_NEAR(c["length_scale_m"].get<double>(), 0.3, 1e-6);  // metres in the scene
}

TEST_F(ImportTest, OverlappingPiecesWeighWhatTheModelWeighs) {
  // the gear at concavity 0.05: merged pieces reach into their neighbours, so the pieces' own
  // volumes sum to more than the model's; --density weighs their union, which the concavity
  // keeps near the model's volume, and the loader's mass from the scene agrees
  const TriangleMesh m = hapticd::decomp::models::gear();
  writeObj(m, path("gear.obj"));
  ASSERT_EQ(import({path("gear.obj"), "-o", path("gear.glb"), "--concavity", "0.05", "--role",
                    "dynamic", "--density", "1000", "--json"}),
            0)
      << err();
  const auto j = nlohmann::json::parse(out());
  const double model_m3 = hapticd::decomp::meshVolume(m.positions, m.triangles);
  ASSERT_GT(j["volume_ratio"].get<double>(), 1.05);
  const double union_ratio = j["union_ratio"].get<double>();
  EXPECT_GE(union_ratio, 1.0 - 1e-9);
  EXPECT_LT(union_ratio, j["volume_ratio"].get<double>() - 0.05);
  // (the file's six digits and assimp's floats move the model's volume by about 1e-7)
  EXPECT_NEAR(j["mass_kg"].get<double>(), 1000.0 * union_ratio * model_m3,
              1e-6 * model_m3 * 1000.0);
  ASSERT_EQ(run(HAPTICCTL, {"check", path("gear.glb"), "--json"}), 0) << err();
  const auto c = nlohmann::json::parse(out());
  EXPECT_NEAR(c["bodies"][0]["mass_kg"].get<double>(), j["mass_kg"].get<double>(),
              1e-6 * j["mass_kg"].get<double>());
}

TEST_F(ImportTest, AddAppendsTheModelToAScene) {
  writeObj(hapticd::decomp::models::lBlock(), path("l.obj"));
  writeObj(hapticd::decomp::models::box({0, 0, 0}, {0.1, 0.1, 0.1}), path("box.obj"));
  ASSERT_EQ(import({path("box.obj"), "-o", path("scene.glb")}), 0) << err();
  ASSERT_EQ(
      import({path("l.obj"), "-o", path("scene.glb"), "--add", path("scene.glb"), "--at", "1", "0",
              "0", "0", "0", "0.7071067811865476", "0.7071067811865476", "--role", "kinematic"}),
      0)
      << err();
  ASSERT_EQ(run(HAPTICCTL, {"check", path("scene.glb"), "--json"}), 0) << out() << err();
  const auto c = nlohmann::json::parse(out());
  ASSERT_EQ(c["bodies"].size(), 2u);
  for (const auto& body : c["bodies"]) {
    if (body["name"] == "box") {
      EXPECT_EQ(body["motion"], "static");
      EXPECT_EQ(body["primitives"], 1);
    } else {
      EXPECT_EQ(body["name"], "l");
      EXPECT_EQ(body["motion"], "kinematic");
      EXPECT_EQ(body["primitives"], 2);
    }
  }
}

// a stack built by import as a user would: one file added three times is three bodies with their
// own names (--record-bodies tells them apart), and a scene with a dynamic body gets standard
// gravity unless it declares one or --gravity says otherwise
TEST_F(ImportTest, AddingOneModelThriceNamesThreeBodiesAndDynamicBodiesFall) {
  writeObj(hapticd::decomp::models::box({0, 0, 0}, {0.1, 0.1, 0.1}), path("box.obj"));
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb")}), 0) << err();
  EXPECT_EQ(out().find("gravity"), std::string::npos) << out();  // static only: none written
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb"), "--add", path("s.glb"), "--at", "0",
                    "0.1", "0", "--role", "dynamic", "--json"}),
            0)
      << err();
  auto j = nlohmann::json::parse(out());
  EXPECT_EQ(j["body"], "box_2");
  ASSERT_TRUE(j.contains("gravity"));
  EXPECT_EQ(j["gravity"], nlohmann::json::parse("[0,-9.81,0]"));
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb"), "--add", path("s.glb"), "--at", "0",
                    "0.2", "0", "--role", "dynamic", "--json"}),
            0)
      << err();
  j = nlohmann::json::parse(out());
  EXPECT_EQ(j["body"], "box_3");
  EXPECT_FALSE(j.contains("gravity"));  // declared already: left as it is
  ASSERT_EQ(run(HAPTICCTL, {"check", path("s.glb"), "--json"}), 0) << err();
  auto c = nlohmann::json::parse(out());
  std::vector<std::string> names;
  for (const auto& body : c["bodies"])
    names.push_back(body["name"]);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"box", "box_2", "box_3"}));
  EXPECT_EQ(c["plan"]["gravity"], true);
  // --gravity 0 0 0: a dynamic body that floats, as asked
  ASSERT_EQ(import({path("box.obj"), "-o", path("f.glb"), "--role", "dynamic", "--gravity", "0",
                    "0", "0"}),
            0)
      << err();
  ASSERT_EQ(run(HAPTICCTL, {"check", path("f.glb"), "--json"}), 0) << err();
  c = nlohmann::json::parse(out());
  EXPECT_EQ(c["plan"]["gravity"], false);
  EXPECT_EQ(import({path("box.obj"), "-o", path("f.glb"), "--gravity", "0", "x", "0"}), 2);
  EXPECT_NE(err().find("--gravity"), std::string::npos) << err();
}

// a model added where it overlaps a body of the scene (--at places its origin, not its bottom: the
// npm teapot, its origin at its middle, placed at a floor's height started 6 cm into it) is
// written, with a warning naming the body and the depth (and `overlaps` in the JSON); one placed
// touching has none
TEST_F(ImportTest, AddingAModelIntoABodyOfTheSceneSaysSo) {
  writeObj(hapticd::decomp::models::box({0, 0, 0}, {0.1, 0.1, 0.1}), path("box.obj"));
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb")}), 0) << err();
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb"), "--add", path("s.glb"), "--at", "0.03",
                    "0.05", "0", "--role", "dynamic", "--json"}),
            0)
      << err();
  EXPECT_NE(err().find("warning: 'box_2' starts 0.05 m into 'box' (--at places the model's "
                       "origin, not its bottom)"),
            std::string::npos)
      << err();
  auto j = nlohmann::json::parse(out());
  ASSERT_EQ(j["overlaps"].size(), 1u) << out();
  EXPECT_EQ(j["overlaps"][0]["body"], "box");
  EXPECT_NEAR(j["overlaps"][0]["depth_m"].get<double>(), 0.05, 1e-6);
  ASSERT_EQ(import({path("box.obj"), "-o", path("s.glb"), "--add", path("s.glb"), "--at", "0.5",
                    "0", "0", "--role", "dynamic", "--json"}),
            0)
      << err();
  EXPECT_EQ(err().find("warning"), std::string::npos) << err();
  j = nlohmann::json::parse(out());
  EXPECT_EQ(j["overlaps"], nlohmann::json::array());
  ASSERT_EQ(run(HAPTICCTL, {"check", path("s.glb")}), 0) << err();
  EXPECT_NE(out().find("'box_2' (dynamic) overlaps 'box' (static) by 0.05 m"), std::string::npos)
      << out();
}

// what the readers would misread or refuse in their own words is said plainly (found on others'
// files): an OBJ whose faces name texture coordinates it does not have is read by its v and f
// lines; a PLY of triangle strips (assimp read it as one triangle) is read by our own PLY reader;
// UTF-16 text and glTF 1.0 are refused naming what to do
TEST_F(ImportTest, FilesTheReadersWouldMisreadAreReadOrRefusedSayingWhy) {
  const TriangleMesh cube = hapticd::decomp::models::box({0, 0, 0}, {1, 1, 1});
  {
    std::ofstream f(path("novt.obj"));
    for (const Vec3& v : cube.positions)
      f << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    f << "vn 0 0 1\n";
    for (const auto& t : cube.triangles)
      f << "f " << t[0] + 1 << "/1/1 " << t[1] + 1 << "/1/1 " << t[2] + 1 << "/1/1\n";
  }
  ASSERT_EQ(import({path("novt.obj"), "-o", path("x.glb"), "--json"}), 0) << err();
  EXPECT_EQ(nlohmann::json::parse(out())["repairs"]["input_triangles"], 12);
  {
    std::ofstream f(path("utf16.obj"), std::ios::binary);
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    f << '\xFE' << '\xFF';
    for (char c : text)
      f << '\0' << c;
  }
  {
    std::ofstream f(path("strips.ply"));
    f << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n6 0 1 2 3 0 1\n";
  }
  ASSERT_EQ(import({path("strips.ply"), "-o", path("x.glb"), "--json"}), 0) << err();
  {
    const nlohmann::json j = nlohmann::json::parse(out());
    EXPECT_EQ(j["repairs"]["input_triangles"], 4) << j.dump();
    EXPECT_TRUE(j["closed"].get<bool>()) << j.dump();
  }
  std::ofstream(path("v1.gltf")) << R"({"asset":{"version":"1.0"},"scene":"defaultScene",)"
                                 << R"("scenes":{"defaultScene":{"nodes":[]}}})";
  {
    std::ofstream f(path("v1.glb"), std::ios::binary);
    const std::uint32_t header[3] = {0x46546C67u, 1u, 20u};  // "glTF", version 1
    f.write(reinterpret_cast<const char*>(header), sizeof header);
    f << "\0\0\0\0\0\0\0\0";
  }
  const std::pair<const char*, const char*> refused[] = {
      {"utf16.obj", "UTF-16"}, {"v1.gltf", "glTF 1.0"}, {"v1.glb", "glTF 1.0"}};
  for (const auto& [file, why] : refused) {
    fs::remove(path("x.glb"));
    EXPECT_EQ(import({path(file), "-o", path("x.glb")}), 1) << file << ": " << out();
    EXPECT_NE(err().find(path(file)), std::string::npos) << err();
    EXPECT_NE(err().find(why), std::string::npos) << file << ": " << err();
    EXPECT_FALSE(fs::exists(path("x.glb"))) << file;
  }
}

// an L prism whose two caps are hexagons listed from a corner whose fan folds over the notch (the
// caps then reach over it, once each way): as PLY faces, and as OBJ faces naming texture
// coordinates the file lacks (read by the v and f lines): the polygons are ear-clipped, and the
// L decomposes into its two boxes, exactly (before: 6 pieces, 1.11 x the volume)
TEST_F(ImportTest, NonConvexPolygonsAreNotFoldedByOurReaders) {
  const double corner[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<std::vector<int>> faces;
  std::vector<int> bottom, top;
  for (int k = 0; k < 6; ++k) {
    bottom.push_back((2 - k + 6) % 6);
    top.push_back((2 + k) % 6 + 6);
  }
  faces.push_back(bottom);
  faces.push_back(top);
  for (int i = 0; i < 6; ++i)
    faces.push_back({i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6});
  {
    std::ofstream f(path("l.ply"));
    f << "ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\n"
         "property float z\nelement face 8\nproperty list uchar int vertex_indices\n"
         "end_header\n";
    for (int z = 0; z < 2; ++z)
      for (const auto& c : corner)
        f << c[0] << ' ' << c[1] << ' ' << z << '\n';
    for (const auto& face : faces) {
      f << face.size();
      for (int i : face)
        f << ' ' << i;
      f << '\n';
    }
  }
  {
    std::ofstream f(path("l_novt.obj"));
    for (int z = 0; z < 2; ++z)
      for (const auto& c : corner)
        f << "v " << c[0] << ' ' << c[1] << ' ' << z << '\n';
    for (const auto& face : faces) {
      f << 'f';
      for (int i : face)
        f << ' ' << i + 1 << "/1";
      f << '\n';
    }
  }
  for (const char* file : {"l.ply", "l_novt.obj"}) {
    ASSERT_EQ(import({path(file), "-o", path("x.glb"), "--json"}), 0) << file << ": " << err();
    const nlohmann::json j = nlohmann::json::parse(out());
    EXPECT_EQ(j["repairs"]["input_triangles"], 20) << file;
    EXPECT_EQ(j["pieces"], 2) << file << ": " << j.dump();
    EXPECT_NEAR(j["volume_ratio"].get<double>(), 1.0, 1e-3) << file;
  }
}

// the probe sphere (config default: radius 10 mm) comes down onto the block's top face (z = 0.1)
// and presses 5 mm past it, then leaves
TEST_F(ImportTest, RoundTripThroughTheDaemonTouchesTheModel) {
  writeObj(hapticd::decomp::models::lBlock(), path("l.obj"));
  ASSERT_EQ(import({path("l.obj"), "-o", path("scene.glb")}), 0) << err();
  {
    std::ofstream s(path("stream.csv"));
    s << "t,px,py,pz,qx,qy,qz,qw,buttons\n";
    const double top = 0.1 + 0.01;
    s << "0,0.05,0.05," << top + 0.05 << ",0,0,0,1,0\n";
    s << "1,0.05,0.05," << top - 0.005 << ",0,0,0,1,0\n";
    s << "2,0.05,0.05," << top - 0.005 << ",0,0,0,1,0\n";
    s << "3,0.05,0.05," << top + 0.05 << ",0,0,0,1,0\n";
  }
  ASSERT_EQ(run(HAPTICD_BINARY, {"--scene", path("scene.glb"), "--device",
                                 "replay:" + path("stream.csv"), "--clock", "virtual", "--record",
                                 path("r.csv"), "--udp", "127.0.0.1:0", "--shm", ""}),
            0)
      << err();
  std::istringstream rows(slurp(path("r.csv")));
  std::string line;
  std::getline(rows, line);
  ASSERT_EQ(line.rfind("tick,t,dev_px", 0), 0u);
  std::size_t n = 0, touching = 0;
  double max_force = 0.0, max_depth = 0.0;
  while (std::getline(rows, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ','))
      v.push_back(std::strtod(cell.c_str(), nullptr));
    ASSERT_GE(v.size(), 24u);
    for (double x : v)
      ASSERT_TRUE(std::isfinite(x)) << line;
    const double f = std::sqrt(v[16] * v[16] + v[17] * v[17] + v[18] * v[18]);
    max_force = std::max(max_force, f);
    max_depth = std::max(max_depth, v[23]);
    if (v[22] > 0)
      ++touching;
    ++n;
  }
  EXPECT_GT(n, 2900u);
  EXPECT_GT(touching, 500u);            // the probe rests on the block for over a second
  EXPECT_GT(max_force, 1.0);            // and is pushed back
  EXPECT_LE(max_force, 10.0 + 1e-9);    // [device] max_force_n
  EXPECT_LE(max_depth, 0.0005 + 1e-6);  // [response] penetration_allowance_m
}

}  // namespace

namespace {

std::string base64(const std::vector<std::uint8_t>& in) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string s;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t{in[i]} << 16) |
                            (i + 1 < in.size() ? std::uint32_t{in[i + 1]} << 8 : 0u) |
                            (i + 2 < in.size() ? std::uint32_t{in[i + 2]} : 0u);
    s += kAlphabet[(n >> 18) & 63];
    s += kAlphabet[(n >> 12) & 63];
    s += i + 1 < in.size() ? kAlphabet[(n >> 6) & 63] : '=';
    s += i + 2 < in.size() ? kAlphabet[n & 63] : '=';
  }
  return s;
}

// a .gltf (buffer as a data URI) whose one mesh has a primitive per (mode, indices) over the
// same float positions, on the nodes given
void writeGltf(const std::vector<Vec3>& positions,
               const std::vector<std::pair<int, std::vector<std::uint32_t>>>& primitives,
               const nlohmann::json& nodes,
               const std::string& p) {
  std::vector<std::uint8_t> bin;
  auto put = [&](const void* data, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(data);
    bin.insert(bin.end(), b, b + n);
  };
  for (const Vec3& v : positions) {
    const float f[3] = {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
    put(f, sizeof f);
  }
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array(),
                 prims = nlohmann::json::array();
  views.push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", bin.size()}});
  accessors.push_back({{"bufferView", 0},
                       {"componentType", 5126},
                       {"count", positions.size()},
                       {"type", "VEC3"},
                       {"min", {0.0, 0.0, 0.0}},
                       {"max", {1.0, 1.0, 1.0}}});
  for (const auto& [mode, indices] : primitives) {
    const std::size_t at = bin.size();
    put(indices.data(), indices.size() * 4);
    views.push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", indices.size() * 4}});
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", 5125},
                         {"count", indices.size()},
                         {"type", "SCALAR"}});
    prims.push_back(
        {{"attributes", {{"POSITION", 0}}}, {"indices", accessors.size() - 1}, {"mode", mode}});
  }
  const nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                              {"scene", 0},
                              {"scenes", {{{"nodes", {0}}}}},
                              {"nodes", nodes},
                              {"meshes", {{{"primitives", prims}}}},
                              {"accessors", accessors},
                              {"bufferViews", views},
                              {"buffers",
                               {{{"byteLength", bin.size()},
                                 {"uri", "data:application/octet-stream;base64," + base64(bin)}}}}};
  std::ofstream(p) << doc.dump();
}

// the unit cube's corners: bottom ring 0-3 (counter-clockwise seen from +z), top ring 4-7 above it
const std::vector<Vec3> kCube{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                              {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

// glTF's TRIANGLE_STRIP (5) and TRIANGLE_FAN (6) are triangles too (Khronos' asset generator and
// trimesh's test models have them): the cube as a strip round its sides and a fan on each cap,
// wound outward, reads as one closed, consistently wound cube (before: "the file has no triangles")
TEST_F(ImportTest, GltfStripsAndFansAreTriangles) {
  writeGltf(kCube,
            {{5, {4, 0, 5, 1, 6, 2, 7, 3, 4, 0}},  // sides: 8 triangles
             {6, {4, 5, 6, 7}},                    // top: 2
             {6, {0, 3, 2, 1}}},                   // bottom: 2
            nlohmann::json::array({{{"mesh", 0}}}), path("cube.gltf"));
  ASSERT_EQ(import({path("cube.gltf"), "-o", path("out.glb"), "--json"}), 0) << err();
  const auto j = nlohmann::json::parse(out());
  EXPECT_EQ(j["repairs"]["input_triangles"], 12);
  EXPECT_EQ(j["repairs"]["degenerate_triangles"], 0);
  EXPECT_EQ(j["repairs"]["boundary_edges"], 0);
  EXPECT_EQ(j["repairs"]["flipped_triangles"], 0);    // the strip's odd triangles keep the winding
  EXPECT_EQ(j["repairs"]["inverted_components"], 0);  // and it is outward
  EXPECT_TRUE(j["closed"].get<bool>());
  EXPECT_EQ(j["pieces"], 1);
  EXPECT_NEAR(j["volume_ratio"].get<double>(), 1.0, 1e-6);
}

// a node that is its own ancestor (assimp's glTF2/RecursiveNodes) is refused at once, in the scene
// loader's words; before, the walk went round the cycle for ever. `timeout` turns a hang into
// exit 124.
TEST_F(ImportTest, GltfNodeCycleIsRefusedNotFollowed) {
  writeGltf(kCube, {{4, {0, 1, 2, 0, 2, 3}}},
            nlohmann::json::array({{{"children", {1}}}, {{"children", {0}}, {"mesh", 0}}}),
            path("cycle.gltf"));
  EXPECT_EQ(run("timeout", {"60", HAPTICCTL, "import", path("cycle.gltf"), "-o", path("x.glb")}), 1)
      << err();
  EXPECT_NE(err().find("node 0: is in a cycle of node children"), std::string::npos) << err();
  EXPECT_FALSE(fs::exists(path("x.glb")));
}

// an index past its primitive's vertices is a bad index of that triangle (dropped and counted by
// the repair), not a vertex of whatever primitive comes next
TEST_F(ImportTest, GltfIndexPastItsPrimitiveIsABadIndex) {
  writeGltf(kCube,
            {{4, {0, 1, 9}},  // 9: no such vertex (8 in the accessor)
             {4, {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                  1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7}}},  // the cube, outward
            nlohmann::json::array({{{"mesh", 0}}}), path("cube.gltf"));
  ASSERT_EQ(import({path("cube.gltf"), "-o", path("out.glb"), "--json"}), 0) << err();
  const auto j = nlohmann::json::parse(out());
  EXPECT_EQ(j["repairs"]["input_triangles"], 13);
  EXPECT_EQ(j["repairs"]["bad_index_triangles"], 1);
  EXPECT_TRUE(j["closed"].get<bool>());
}

}  // namespace

namespace {

// files on which Debian's assimp 5.2.5 dies (a segfault, an assertion) or that ask it for more
// memory than the machine has: the import exits 1 naming the file, never by a signal

TEST_F(ImportTest, AReaderThatDiesOnAFileIsAnErrorNotACrash) {
  {
    // a binary PLY whose third property line is cut short, binary bytes where its type should be
    std::ofstream f(path("cut.ply"), std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty ";
    const char tail[] = {0, 0, 0, 9, 7, 0, 0, 0, 3, 0, 0, 0, 3, 3, 0, 0, 0, 7, 0, 0, 0};
    f.write(tail, sizeof tail);
  }
  {
    // a valid binary PLY tetrahedron whose data starts with the byte 0x0a (x = 0.01f)
    std::ofstream f(path("nl.ply"), std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
         "property float y\nproperty float z\nelement face 4\n"
         "property list uchar int vertex_indices\nend_header\n";
    const float v[4][3] = {{0.01f, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    f.write(reinterpret_cast<const char*>(v), sizeof v);
    const std::int32_t t[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    for (const auto& tri : t) {
      const char three = 3;
      f.write(&three, 1);
      f.write(reinterpret_cast<const char*>(tri), sizeof tri);
    }
  }
  for (const std::string file : {"cut.ply", "nl.ply"}) {
    const int rc = import({path(file), "-o", path("x.glb"), "--json"});
    ASSERT_TRUE(rc == 0 || rc == 1) << file << ": exit " << rc << ": " << err();
    if (rc == 1) {
      EXPECT_NE(err().find(path(file)), std::string::npos) << err();
      EXPECT_FALSE(fs::exists(path("x.glb")));
    } else {
      EXPECT_EQ(nlohmann::json::parse(out())["repairs"]["input_triangles"], 4) << file;
    }
  }
  // an OFF whose header counts 10^12 vertices: refused at once, saying why
  std::ofstream(path("huge.off")) << "OFF\n1000000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(run("timeout", {"60", HAPTICCTL, "import", path("huge.off"), "-o", path("x.glb")}), 1)
      << err();
  // (under AddressSanitizer the child has no address-space limit, its shadow memory being
  // terabytes: the sanitizer's allocator kills it instead, and the error only names the file)
  if (hapticd::kAddressSanitizer)
    EXPECT_NE(err().find(path("huge.off")), std::string::npos) << err();
  else
    EXPECT_NE(err().find("more memory than allowed"), std::string::npos) << err();
}

}  // namespace

namespace {

namespace st = hapticd::scene::testing;

// the L-block as the scene loader's test meshes hold it
st::Mesh lBlockMesh() {
  const TriangleMesh m = hapticd::decomp::models::lBlock();
  st::Mesh out;
  out.vertices = m.positions;
  for (const auto& t : m.triangles)
    out.triangles.insert(out.triangles.end(), t.begin(), t.end());
  return out;
}

void writeBytes(const std::vector<std::uint8_t>& bytes, const std::string& p) {
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

// a plain model: one node holding `mesh`, translated by (1, 0, 0) and scaled by `scale`
void addModelNode(st::GltfBuilder& b, int mesh, double scale = 1.0) {
  nlohmann::json node = {{"name", "lblock"}, {"mesh", mesh}, {"translation", {1.0, 0.0, 0.0}}};
  if (scale != 1.0)
    node["scale"] = {scale, scale, scale};
  b.addNode(node);
}

// `b` holds the same surface as `a`: as many triangles, each of a matched by its own triangle of
// b whose corners are within `tol` of a's in the same cyclic order (the same winding); the
// encoders may reorder vertices and triangles
void expectSameTriangles(const TriangleMesh& a,
                         const TriangleMesh& b,
                         double tol,
                         const std::string& what) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size()) << what;
  std::vector<bool> used(b.triangles.size(), false);
  double worst = 0.0;
  for (const auto& ta : a.triangles) {
    bool found = false;
    for (std::size_t j = 0; j < b.triangles.size() && !found; ++j) {
      if (used[j])
        continue;
      for (std::size_t r = 0; r < 3 && !found; ++r) {
        double d = 0.0;
        for (std::size_t k = 0; k < 3; ++k) {
          const Vec3 delta = a.positions[ta[k]] - b.positions[b.triangles[j][(k + r) % 3]];
          d = std::max({d, std::abs(delta.x), std::abs(delta.y), std::abs(delta.z)});
        }
        if (d <= tol) {
          found = used[j] = true;
          worst = std::max(worst, d);
        }
      }
    }
    EXPECT_TRUE(found) << what << ": no triangle of it matches (" << a.positions[ta[0]].x << ", "
                       << a.positions[ta[0]].y << ", " << a.positions[ta[0]].z << ")...";
  }
  EXPECT_LE(worst, tol) << what;
}

// the same model as plain floats, Draco-compressed, meshopt-compressed, quantized (SHORT
// normalized, the node scaled back), as a .gltf with its buffer in a .bin beside it and with
// sparse positions: read in world coordinates as the same triangles (within the quantization
// step), imported as a scene `hapticctl check` loads. Before, only the float files were read.
TEST_F(ImportTest, CompressedQuantizedAndExternalGltfGiveTheFloatTriangles) {
  const st::Mesh mesh = lBlockMesh();
  {
    st::GltfBuilder b;
    addModelNode(b, b.addMesh(mesh, "lblock"));
    writeBytes(b.glb(), path("float.glb"));
    // the same document with its buffer in a file beside it
    nlohmann::json doc = b.doc;
    doc["buffers"] = {{{"byteLength", b.bin.size()}, {"uri", "float_data.bin"}}};
    std::ofstream(path("external.gltf")) << doc.dump();
    writeBytes(b.bin, path("float_data.bin"));
  }
  {
    st::GltfBuilder b;
    addModelNode(b, st::addDracoMesh(b, mesh, "lblock", 16));
    writeBytes(b.glb(), path("draco.glb"));
  }
  {
    st::GltfBuilder b;
    addModelNode(b, st::addMeshoptMesh(b, mesh, "lblock"));
    writeBytes(b.glb(), path("meshopt.glb"));
  }
  const double scale = 0.5;  // stored at twice the size, in [-1, 1]; the node scales it back
  {
    st::Mesh doubled = mesh;
    for (Vec3& v : doubled.vertices)
      v /= scale;
    st::GltfBuilder b;
    addModelNode(b, st::addQuantizedMesh(b, doubled, 5122, true, "lblock"), scale);
    writeBytes(b.glb(), path("quantized.glb"));
  }
  {
    // the first three vertices wrong in the bufferView and put right by sparse storage
    st::GltfBuilder b;
    std::vector<Vec3> base = mesh.vertices;
    const std::vector<std::uint16_t> fixed{0, 1, 2};
    std::vector<Vec3> values;
    for (const std::uint16_t i : fixed) {
      values.push_back(base[i]);
      base[i] = Vec3{9.0};
    }
    const int pa = st::addSparsePositions(b, base, true, fixed, values);
    const int iv = b.addView(mesh.triangles.data(), mesh.triangles.size() * sizeof(std::uint32_t));
    const int ia = b.addAccessor({{"bufferView", iv},
                                  {"componentType", 5125},
                                  {"count", mesh.triangles.size()},
                                  {"type", "SCALAR"}});
    const nlohmann::json prim = {{"attributes", {{"POSITION", pa}}}, {"indices", ia}};
    b.doc["meshes"].push_back({{"primitives", nlohmann::json::array({prim})}});
    addModelNode(b, 0);
    writeBytes(b.glb(), path("sparse.glb"));
  }
  const auto plain = hapticd::client::readModel(path("float.glb"));
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  ASSERT_EQ(plain.value().triangles.size(), 112u);
  // in world coordinates: the node's translation applied
  EXPECT_NEAR(plain.value().positions[0].x, 1.0 + mesh.vertices[0].x, 1e-7);
  // the largest coordinate step of each encoding: Draco quantizes the bounding box (0.3 m at
  // most) to 16 bits; SHORT normalized is 1/32767 of the stored unit, here 1/scale; float32
  // rounding of values near 1.3 is 1.2e-7
  double extent = 0.0;
  for (const Vec3& v : mesh.vertices)
    extent = std::max({extent, v.x, v.y, v.z});
  const std::vector<std::pair<std::string, double>> files{
      {"external.gltf", 1e-12},
      {"meshopt.glb", 1e-12},
      {"sparse.glb", 1e-12},
      {"draco.glb", extent / 65535.0 + 2e-7},
      {"quantized.glb", scale / 32767.0 + 2e-7}};
  for (const auto& [file, tol] : files) {
    const auto read = hapticd::client::readModel(path(file));
    ASSERT_TRUE(read.ok()) << file << ": " << read.error().message;
    expectSameTriangles(plain.value(), read.value(), tol, file);
    fs::remove(path("out.glb"));
    ASSERT_EQ(import({path(file), "-o", path("out.glb"), "--json"}), 0) << file << ": " << err();
    const auto report = nlohmann::json::parse(out());
    EXPECT_EQ(report["repairs"]["input_triangles"], 112) << file;
    EXPECT_TRUE(report["closed"].get<bool>()) << file;
    EXPECT_GE(report["pieces"].get<int>(), 2) << file;
    EXPECT_LE(report["pieces"].get<int>(), 3) << file;
    ASSERT_EQ(run(HAPTICCTL, {"check", path("out.glb"), "--json"}), 0)
        << file << ": " << out() << err();
    EXPECT_EQ(nlohmann::json::parse(out())["bodies"][0]["name"], fs::path(file).stem().string());
  }
}

// a file the scene loader refuses is refused by import in the loader's words (what and where),
// naming the file: here POSITION of VEC2, and an external buffer that is not there
TEST_F(ImportTest, GltfTheLoaderRefusesIsRefusedInItsWords) {
  const st::Mesh mesh = lBlockMesh();
  {
    st::GltfBuilder b;
    addModelNode(b, b.addMesh(mesh, "lblock"));
    b.doc["accessors"][0]["type"] = "VEC2";
    b.doc["accessors"][0].erase("min");
    b.doc["accessors"][0].erase("max");
    writeBytes(b.glb(), path("vec2.glb"));
    nlohmann::json doc = b.doc;
    doc["accessors"][0]["type"] = "VEC3";
    doc["buffers"] = {{{"byteLength", b.bin.size()}, {"uri", "gone.bin"}}};
    std::ofstream(path("gone.gltf")) << doc.dump();
  }
  for (const std::string file : {"vec2.glb", "gone.gltf"}) {
    ASSERT_EQ(run(HAPTICCTL, {"check", path(file)}), 1) << file << ": " << out() << err();
    const std::string check = out() + err();
    EXPECT_EQ(import({path(file), "-o", path("x.glb")}), 1) << file;
    const std::string refused = err();
    EXPECT_NE(refused.find(path(file)), std::string::npos) << refused;
    // the problem line of check ("accessor 0: ..." or "buffer 0: ..."), word for word
    const std::string where = file == "vec2.glb" ? "accessor 0: " : "buffer 0: ";
    const std::size_t at = check.find(where);
    ASSERT_NE(at, std::string::npos) << check;
    const std::string line = check.substr(at, check.find('\n', at) - at);
    EXPECT_NE(refused.find(line), std::string::npos)
        << "check: " << line << "\nimport: " << refused;
    EXPECT_FALSE(fs::exists(path("x.glb")));
  }
}

// a node that mirrors (scale -1 on x) turns the winding round, as glTF says: the cube imports
// wound outward, not inside out
TEST_F(ImportTest, GltfMirroredNodeKeepsTheSurfaceOutward) {
  writeGltf(kCube, {{4, {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                         1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7}}},
            nlohmann::json::array({{{"mesh", 0}, {"scale", {-1.0, 1.0, 1.0}}}}),
            path("mirror.gltf"));
  ASSERT_EQ(import({path("mirror.gltf"), "-o", path("out.glb"), "--json"}), 0) << err();
  const auto j = nlohmann::json::parse(out());
  EXPECT_EQ(j["repairs"]["input_triangles"], 12);
  EXPECT_EQ(j["repairs"]["flipped_triangles"], 0);
  EXPECT_EQ(j["repairs"]["inverted_components"], 0);
  EXPECT_TRUE(j["closed"].get<bool>());
  EXPECT_NEAR(j["volume_ratio"].get<double>(), 1.0, 1e-6);
}

}  // namespace
