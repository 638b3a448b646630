#include "client/import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include "client/check.h"
#include "client/ply.h"
#include "client/polygon.h"
#include "core/common/sanitizers.h"
#include "core/decomp/quickhull.h"
#include "core/scene/glb.h"
#include "core/scene/loader.h"
#include "core/scene/triangles.h"
#include "scenes/glb_builder.h"

namespace hapticd::client {
namespace {

namespace fs = std::filesystem;
using decomp::TriangleMesh;
using decomp::Vec3;
using Json = nlohmann::json;

std::string lower(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// the glTF reader: the scene loader's own (core/scene/triangles.h), so that what `hapticctl check`
// reads (quantized, sparse, Draco, meshopt geometry, external and data-URI buffers) imports
// alike, refused in the loader's words. Its limits are for scenes the daemon serves; a model to
// decompose may be larger (as from the other formats, which have none).
Result<TriangleMesh> readGltfTriangles(const std::string& path) {
  scene::TrianglesOptions options;
  options.keep_bad_indices = true;  // dropped and counted by the repair
  scene::SceneLimits& limits = options.load.limits;
  limits.max_file_bytes = 2ull << 30;
  limits.max_nodes = 1u << 20;
  limits.max_hull_input_points = 1u << 26;
  limits.max_total_hull_input_points = 1ull << 26;
  scene::TrianglesReport read = scene::readSceneTrianglesFile(path, options);
  if (!read.ok()) {
    std::string m = read.message();
    if (!m.empty() && m.back() == '\n')
      m.pop_back();
    return Error{path + ": " + m};
  }
  TriangleMesh mesh;
  mesh.positions = std::move(read.triangles->positions);
  mesh.triangles = std::move(read.triangles->triangles);
  return mesh;
}

Result<TriangleMesh> readWithAssimp(const std::string& path) {
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (scene == nullptr)
    return Error{path + ": " + importer.GetErrorString()};
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.positions.push_back({am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z});
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices == 3)
        mesh.triangles.push_back(
            {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  return mesh;
}

// readWithAssimp in a child process, the mesh sent back through a pipe. Debian's assimp (5.2.5)
// dies on some malformed files (a segfault on a binary PLY whose header is cut short, an assertion
// on a binary PLY whose data starts with a newline byte: PLY is now read by client/ply.h, but the
// other formats' readers are no safer) and grows without bound on an OFF whose
// header counts more vertices than it holds: the child runs under an address-space limit, and its
// death becomes an error that names the file. Called before any thread is started.

Result<TriangleMesh> readWithAssimpIsolated(const std::string& path) {
  int fds[2];
  if (::pipe(fds) != 0)
    return readWithAssimp(path);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return readWithAssimp(path);
  }
  if (pid == 0) {
    ::close(fds[0]);
    // half the machine's memory: no model file within reach needs more to be read (not under
    // AddressSanitizer, whose shadow memory alone is terabytes of address space)
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0 && !kAddressSanitizer) {
      rlimit lim{};
      lim.rlim_cur = lim.rlim_max = static_cast<rlim_t>(pages) * static_cast<rlim_t>(page) / 2;
      ::setrlimit(RLIMIT_AS, &lim);
    }
    std::vector<std::uint8_t> out;
    auto put = [&](const void* data, std::size_t n) {
      const auto* b = static_cast<const std::uint8_t*>(data);
      out.insert(out.end(), b, b + n);
    };
    try {
      const Result<TriangleMesh> r = readWithAssimp(path);
      const std::uint8_t ok = r.ok() ? 1 : 0;
      put(&ok, 1);
      if (r.ok()) {
        const std::uint64_t nv = r.value().positions.size(), nt = r.value().triangles.size();
        put(&nv, 8);
        put(r.value().positions.data(), nv * sizeof(Vec3));
        put(&nt, 8);
        put(r.value().triangles.data(), nt * sizeof(decomp::Triangle));
      } else {
        const std::string& m = r.error().message;
        const std::uint64_t n = m.size();
        put(&n, 8);
        put(m.data(), n);
      }
    } catch (const std::exception& e) {
      out.clear();
      const std::uint8_t ok = 0;
      const std::string m = path + ": " + e.what();
      const std::uint64_t n = m.size();
      put(&ok, 1);
      put(&n, 8);
      put(m.data(), n);
    }
    for (std::size_t at = 0; at < out.size();) {
      const ssize_t w = ::write(fds[1], out.data() + at, out.size() - at);
      if (w <= 0)
        ::_exit(3);
      at += static_cast<std::size_t>(w);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::vector<std::uint8_t> in;
  std::uint8_t buf[65536];
  while (true) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      break;
    in.insert(in.end(), buf, buf + n);
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string ext = lower(fs::path(path).extension().string());
  if (WIFSIGNALED(status))
    return Error{path + ": the " + ext + " reader (assimp) died on this file (" +
                 ::strsignal(WTERMSIG(status)) + "): the file is malformed or beyond the reader"};
  std::size_t at = 0;
  auto get = [&](void* data, std::size_t n) {
    if (at + n > in.size())
      return false;
    std::memcpy(data, in.data() + at, n);
    at += n;
    return true;
  };
  std::uint8_t ok = 0;
  std::uint64_t n = 0;
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) || !get(&ok, 1) || !get(&n, 8))
    return Error{path + ": the " + ext + " reader (assimp) ended without a result"};
  if (ok == 0) {
    std::string m(n <= in.size() - at ? n : 0, '\0');
    get(m.data(), m.size());
    if (m.find("bad_alloc") != std::string::npos)
      m = path +
          ": reading it needs more memory than allowed (a count in the file is larger "
          "than the file holds?)";
    return Error{m};
  }
  TriangleMesh mesh;
  std::uint64_t nt = 0;
  if (n > (in.size() - at) / sizeof(Vec3))
    return Error{path + ": the " + ext + " reader (assimp) ended without a result"};
  mesh.positions.resize(n);
  get(mesh.positions.data(), n * sizeof(Vec3));
  if (!get(&nt, 8) || nt > (in.size() - at) / sizeof(decomp::Triangle))
    return Error{path + ": the " + ext + " reader (assimp) ended without a result"};
  mesh.triangles.resize(nt);
  get(mesh.triangles.data(), nt * sizeof(decomp::Triangle));
  return mesh;
}

struct Parsed {
  double scale = 1.0;  // to metres
  std::string units;
  bool units_assumed = false;
  decomp::DecompOptions decomp;
  std::optional<double> mass_kg, density;
  std::vector<double> at;
  std::vector<double> gravity;  // empty: the default (see ImportOptions::gravity)
};

std::optional<double> number(const std::string& s) {
  if (s.empty())
    return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !std::isfinite(v))
    return std::nullopt;
  return v;
}

// every option checked; the first mistake as a message
Result<Parsed> parse(const ImportOptions& o) {
  Parsed p;
  if (o.model.empty())
    return Error{"give the MODEL file"};
  if (o.output.empty())
    return Error{"give the output scene with -o SCENE.glb"};
  if (lower(fs::path(o.output).extension().string()) != ".glb")
    return Error{"-o must name a .glb file, got " + o.output};
  p.units = o.units.empty() ? "m" : o.units;
  p.units_assumed = o.units.empty();
  const std::pair<const char*, double> units[] = {
      {"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"in", 0.0254}};
  const auto u = std::find_if(std::begin(units), std::end(units),
                              [&](const auto& x) { return p.units == x.first; });
  if (u == std::end(units))
    return Error{"--units must be m, cm, mm or in, got '" + p.units + "'"};
  p.scale = u->second;
  if (o.role != "static" && o.role != "dynamic" && o.role != "kinematic" && o.role != "probe")
    return Error{"--role must be static, dynamic, kinematic or probe, got '" + o.role + "'"};
  const auto c = number(o.concavity);
  if (!c || !(*c > 0.0 && *c < 1.0))
    return Error{"--concavity must be a number in (0, 1) (a fraction of the diagonal), got '" +
                 o.concavity + "'"};
  p.decomp.concavity = *c;
  const auto mp = number(o.max_pieces);
  if (!mp || *mp < 1.0 || *mp > 10000.0 || std::floor(*mp) != *mp)
    return Error{"--max-pieces must be an integer from 1 to 10000, got '" + o.max_pieces + "'"};
  p.decomp.max_pieces = static_cast<std::size_t>(*mp);
  const auto tl = number(o.time_limit);
  if (!tl || *tl < 0.0)
    return Error{"--time-limit must be seconds >= 0 (0: none), got '" + o.time_limit + "'"};
  p.decomp.time_limit_s = *tl;
  if (!o.mass.empty() && !o.density.empty())
    return Error{"give --mass or --density, not both"};
  if ((!o.mass.empty() || !o.density.empty()) && o.role != "dynamic")
    return Error{"--mass and --density need --role dynamic"};
  if (!o.mass.empty()) {
    p.mass_kg = number(o.mass);
    if (!p.mass_kg || !(*p.mass_kg > 0.0))
      return Error{"--mass must be kg > 0, got '" + o.mass + "'"};
  }
  if (!o.density.empty()) {
    p.density = number(o.density);
    if (!p.density || !(*p.density > 0.0))
      return Error{"--density must be kg/m3 > 0, got '" + o.density + "'"};
  }
  if (!o.gravity.empty()) {
    if (o.gravity.size() != 3)
      return Error{"--gravity needs X Y Z (m/s2)"};
    for (const std::string& g : o.gravity) {
      const auto v = number(g);
      if (!v)
        return Error{"--gravity: '" + g + "' is not a number"};
      p.gravity.push_back(*v);
    }
  }
  if (!o.at.empty() && o.add.empty())
    return Error{"--at needs --add SCENE.glb"};
  if (!o.add.empty()) {
    if (o.at.size() != 3 && o.at.size() != 7)
      return Error{"--add needs --at X Y Z [QX QY QZ QW]"};
    for (const std::string& s : o.at) {
      const auto v = number(s);
      if (!v)
        return Error{"--at: '" + s + "' is not a number"};
      p.at.push_back(*v);
    }
  }
  return p;
}

// the model's node tree: a body node holding the visual mesh and one collider node per piece
// (each naming a geometry node, outside the scene, that holds the piece's hull)
std::vector<std::uint8_t> buildScene(const std::string& name,
                                     const TriangleMesh& visual,
                                     const decomp::DecompResult& r,
                                     const ImportOptions& o,
                                     const Parsed& p,
                                     double mass_kg) {
  scenes::GltfBuilder b;
  const int grey = b.addRenderMaterial("model", {0.7, 0.7, 0.72, 1.0}, 0.1, 0.6);
  scenes::MeshData vm;
  vm.positions = visual.positions;
  vm.triangles = visual.triangles;
  const int mesh = b.addMesh(name, vm, grey);
  Json body = {{"name", name}};
  Json motion;
  if (o.role == "dynamic")
    motion = mass_kg > 0.0 ? Json{{"mass", scenes::quantize(mass_kg)}} : Json::object();
  if (o.role == "kinematic" || o.role == "probe")
    motion = {{"isKinematic", true}};
  if (!motion.is_null())
    body["extensions"] = {{"KHR_physics_rigid_bodies", {{"motion", motion}}}};
  if (o.role == "probe")
    body["extras"] = {{"haptic", {{"probe", true}}}};
  if (!p.at.empty()) {
    body["translation"] = scenes::jsonVec({p.at[0], p.at[1], p.at[2]});
    if (p.at.size() == 7) {
      const glm::dquat q = glm::normalize(glm::dquat(p.at[6], p.at[3], p.at[4], p.at[5]));
      body["rotation"] = {scenes::quantize(q.x), scenes::quantize(q.y), scenes::quantize(q.z),
                          scenes::quantize(q.w)};
    }
  }
  const int root = b.addNode(body);
  b.addRoot(root);
  b.addChild(root, b.addNode({{"name", name + "_visual"}, {"mesh", mesh}}));
  for (std::size_t i = 0; i < r.pieces.size(); ++i) {
    scenes::MeshData pm;
    for (const Vec3& v : r.pieces[i].vertices)
      pm.positions.push_back(v * p.scale);
    pm.triangles = r.pieces[i].triangles;
    const std::string piece = name + "_piece" + std::to_string(i);
    const int geometry = b.addNode({{"name", piece + "_hull"}, {"mesh", b.addMesh(piece, pm, -1)}});
    const Json collider = {{"geometry", {{"node", geometry}, {"convexHull", true}}}};
    b.addChild(
        root,
        b.addNode({{"name", piece},
                   {"extensions", {{"KHR_physics_rigid_bodies", {{"collider", collider}}}}}}));
  }
  return b.finish(name);
}

// a GLB's JSON and BIN chunks
Result<std::pair<Json, std::vector<std::uint8_t>>> splitGlb(const std::vector<std::uint8_t>& glb,
                                                            const std::string& what) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  if (glb.size() < 20 || u32(0) != 0x46546C67u || u32(4) != 2)
    return Error{what + ": not a glTF 2.0 binary (.glb)"};
  const std::size_t json_len = u32(12);
  if (u32(16) != 0x4E4F534Au || 20 + json_len > glb.size())
    return Error{what + ": the GLB's first chunk is not JSON"};
  Json doc = Json::parse(glb.begin() + 20, glb.begin() + static_cast<std::ptrdiff_t>(20 + json_len),
                         nullptr, false);
  if (doc.is_discarded())
    return Error{what + ": the GLB's JSON does not parse"};
  std::vector<std::uint8_t> bin;
  const std::size_t at = 20 + json_len;
  if (at + 8 <= glb.size() && u32(at + 4) == 0x004E4942u) {
    const std::size_t len = u32(at);
    if (at + 8 + len > glb.size())
      return Error{what + ": the GLB's BIN chunk runs past the end"};
    bin.assign(glb.begin() + static_cast<std::ptrdiff_t>(at + 8),
               glb.begin() + static_cast<std::ptrdiff_t>(at + 8 + len));
  }
  return std::make_pair(std::move(doc), std::move(bin));
}

// appends the model's document `add` (one root node) to `base`
void mergeInto(Json& base,
               std::vector<std::uint8_t>& bin,
               const Json& add,
               const std::vector<std::uint8_t>& add_bin) {
  auto count = [&](const char* key) {
    return base.contains(key) ? static_cast<int>(base[key].size()) : 0;
  };
  const int nodes = count("nodes"), meshes = count("meshes"), accessors = count("accessors"),
            views = count("bufferViews"), materials = count("materials");
  while (bin.size() % 4 != 0)
    bin.push_back(0);
  const auto offset = static_cast<long long>(bin.size());
  bin.insert(bin.end(), add_bin.begin(), add_bin.end());
  if (!base.contains("buffers") || base["buffers"].empty())
    base["buffers"] = Json::array({Json::object()});
  base["buffers"][0]["byteLength"] = bin.size();
  for (Json v : add.value("bufferViews", Json::array())) {
    v["buffer"] = 0;
    v["byteOffset"] = v.value("byteOffset", 0ll) + offset;
    base["bufferViews"].push_back(v);
  }
  for (Json a : add.value("accessors", Json::array())) {
    if (a.contains("bufferView"))
      a["bufferView"] = a["bufferView"].get<int>() + views;
    base["accessors"].push_back(a);
  }
  for (const Json& m : add.value("materials", Json::array()))
    base["materials"].push_back(m);
  for (Json m : add.value("meshes", Json::array())) {
    for (Json& prim : m["primitives"]) {
      for (auto& [key, value] : prim["attributes"].items())
        value = value.get<int>() + accessors;
      if (prim.contains("indices"))
        prim["indices"] = prim["indices"].get<int>() + accessors;
      if (prim.contains("material"))
        prim["material"] = prim["material"].get<int>() + materials;
    }
    base["meshes"].push_back(m);
  }
  for (Json n : add.value("nodes", Json::array())) {
    if (n.contains("mesh"))
      n["mesh"] = n["mesh"].get<int>() + meshes;
    if (n.contains("children"))
      for (Json& c : n["children"])
        c = c.get<int>() + nodes;
    auto* geometry = n.contains("extensions") ? &n["extensions"] : nullptr;
    if (geometry != nullptr && geometry->contains("KHR_physics_rigid_bodies") &&
        (*geometry)["KHR_physics_rigid_bodies"].contains("collider")) {
      Json& g = (*geometry)["KHR_physics_rigid_bodies"]["collider"]["geometry"];
      if (g.contains("node"))
        g["node"] = g["node"].get<int>() + nodes;
    }
    base["nodes"].push_back(n);
  }
  const int scene = base.value("scene", 0);
  if (!base.contains("scenes") || base["scenes"].empty())
    base["scenes"] = Json::array({Json::object()});
  for (const Json& r : add["scenes"][0]["nodes"])
    base["scenes"][static_cast<std::size_t>(scene)]["nodes"].push_back(r.get<int>() + nodes);
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    for (const Json& e : add.value(key, Json::array()))
      if (!base.contains(key) ||
          std::find(base[key].begin(), base[key].end(), e) == base[key].end())
        base[key].push_back(e);
  }
}

Result<std::vector<std::uint8_t>> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return Error{path + ": cannot open: " + std::strerror(errno)};
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
}

Json reportJson(const decomp::DecompReport& r) {
  const decomp::RepairCounts& c = r.repairs;
  return {{"pieces", r.pieces},
          {"concavity", r.concavity},
          {"concavity_bound", r.concavity_bound},
          {"concavity_target", r.concavity_target},
          {"volume_ratio", r.closed && r.volume_ratio > 0.0 ? Json(r.volume_ratio) : Json(nullptr)},
          {"union_ratio", r.closed && r.union_ratio > 0.0 ? Json(r.union_ratio) : Json(nullptr)},
          {"closed", r.closed},
          {"seconds", r.seconds},
          {"cuts", r.cuts},
          {"merges", r.merges},
          {"time_limit_hit", r.time_limit_hit},
          {"warnings", r.warnings},
          {"repairs",
           {{"input_vertices", c.input_vertices},
            {"input_triangles", c.input_triangles},
            {"non_finite_vertices", c.non_finite_vertices},
            {"bad_index_triangles", c.bad_index_triangles},
            {"duplicate_vertices", c.duplicate_vertices},
            {"unreferenced_vertices", c.unreferenced_vertices},
            {"degenerate_triangles", c.degenerate_triangles},
            {"duplicate_triangles", c.duplicate_triangles},
            {"boundary_edges", c.boundary_edges},
            {"holes_filled", c.holes_filled},
            {"non_manifold_edges", c.non_manifold_edges},
            {"flipped_triangles", c.flipped_triangles},
            {"inverted_components", c.inverted_components},
            {"components", c.components},
            {"open_components", c.open_components},
            {"self_intersections", c.self_intersections},
            {"decimated_from", c.decimated_from}}}};
}

}  // namespace

namespace {

// the first bytes of a file (at most n)
std::string headOf(const std::string& path, std::size_t n) {
  std::ifstream f(path, std::ios::binary);
  std::string head(n, '\0');
  f.read(head.data(), static_cast<std::streamsize>(n));
  head.resize(static_cast<std::size_t>(std::max<std::streamsize>(f.gcount(), 0)));
  return head;
}

// what the readers would misread, or refuse in their own words: said plainly before them
std::optional<Error> sniff(const std::string& path, const std::string& ext) {
  const std::string head = headOf(path, 65536);
  const bool text_format = ext == ".obj" || ext == ".off" || ext == ".gltf" || ext == ".ply";
  if (text_format && head.size() >= 2 &&
      ((head[0] == '\xFE' && head[1] == '\xFF') || (head[0] == '\xFF' && head[1] == '\xFE')))
    return Error{path + ": UTF-16 text: save the file as UTF-8 (or ASCII)"};
  if (ext == ".glb" && head.size() >= 8 && head.compare(0, 4, "glTF") == 0 &&
      static_cast<unsigned char>(head[4]) == 1 && head[5] == 0 && head[6] == 0 && head[7] == 0)
    return Error{path + ": glTF 1.0 is not read: convert it to glTF 2.0 (e.g. with Blender)"};
  if (ext == ".gltf") {
    const Json doc =
        Json::parse(head.size() < 65536 ? head : headOf(path, 1u << 30), nullptr, false);
    const bool v1 = doc.is_object() &&
                    ((doc.contains("asset") && doc["asset"].is_object() &&
                      doc["asset"].contains("version") && doc["asset"]["version"].is_string() &&
                      doc["asset"]["version"].get<std::string>().rfind("1", 0) == 0) ||
                     (doc.contains("scene") && doc["scene"].is_string()));
    if (v1)
      return Error{path + ": glTF 1.0 is not read: convert it to glTF 2.0 (e.g. with Blender)"};
  }
  return std::nullopt;
}

// Wavefront OBJ's v and f lines alone (f with v, v/vt, v//vn, v/vt/vn, negative indices;
// polygons ear-clipped where a fan would fold, client/polygon.h): for files whose faces the full
// reader drops (faces naming texture coordinates that the file does not have)
TriangleMesh readObjPositions(const std::string& path) {
  TriangleMesh mesh;
  std::ifstream f(path);
  std::string line;
  constexpr std::uint32_t kBad = std::numeric_limits<std::uint32_t>::max();
  while (std::getline(f, line)) {
    std::istringstream words(line);
    std::string w;
    if (!(words >> w))
      continue;
    if (w == "v") {
      Vec3 v{std::numeric_limits<double>::quiet_NaN()};
      words >> v.x >> v.y >> v.z;
      mesh.positions.push_back(v);
    } else if (w == "f") {
      std::vector<std::uint32_t> poly;
      std::string t;
      while (words >> t) {
        char* end = nullptr;
        const long long i = std::strtoll(t.c_str(), &end, 10);
        const long long n = static_cast<long long>(mesh.positions.size());
        const long long at = i > 0 ? i - 1 : i < 0 ? n + i : -1;
        poly.push_back(end != t.c_str() && at >= 0 && at < n ? static_cast<std::uint32_t>(at)
                                                             : kBad);
      }
      triangulatePolygon(mesh.positions, poly, mesh.triangles);
    }
  }
  return mesh;
}

}  // namespace

Result<TriangleMesh> readModel(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return Error{path + ": no such file"};
  const std::string ext = lower(fs::path(path).extension().string());
  const bool mesh_format = ext == ".obj" || ext == ".stl" || ext == ".ply" || ext == ".off";
  if (!mesh_format && ext != ".gltf" && ext != ".glb")
    return Error{path + ": unsupported format '" + ext +
                 "' (give .obj, .stl, .ply, .off, .gltf or .glb)"};
  if (std::optional<Error> refused = sniff(path, ext))
    return *refused;
  Result<TriangleMesh> mesh = ext == ".ply" ? readPly(path)
                              : mesh_format ? readWithAssimpIsolated(path)
                                            : readGltfTriangles(path);
  // the reader kept no face (assimp says "No meshes remaining" or "all meshes are orphaned"):
  // an OBJ is read again by its v and f lines alone
  const bool none = mesh.ok()
                        ? mesh.value().triangles.empty()
                        : mesh.error().message.find("No meshes") != std::string::npos ||
                              mesh.error().message.find("No output meshes") != std::string::npos ||
                              mesh.error().message.find("orphaned") != std::string::npos;
  if (none && ext == ".obj") {
    TriangleMesh plain = readObjPositions(path);
    if (!plain.triangles.empty())
      return plain;
  }
  if (none)
    return Error{path + ": the file has no triangles (only points or lines, or faces the reader " +
                 "could not use)"};
  return mesh;
}

CLI::App* defineImport(CLI::App& app, ImportOptions& o) {
  CLI::App* sub = app.add_subcommand(
      "import",
      "Decompose a polygonal model (.obj .stl .ply .off .gltf .glb) into convex pieces and "
      "write a scene with its colliders (docs/decomposition.md); exit 0 written, 1 bad "
      "input, 2 bad arguments");
  sub->add_option("MODEL", o.model, "the model file");
  sub->add_option("-o,--output", o.output, "the scene to write (.glb)");
  sub->add_option("--units", o.units,
                  "the model's length unit: m, cm, mm, in (default m, said when assumed)");
  sub->add_option("--role", o.role, "static, dynamic, kinematic or probe (default static)");
  sub->add_option("--mass", o.mass, "dynamic: mass, kg (default: density x volume)");
  sub->add_option("--density", o.density, "dynamic: density, kg/m3 (default 1000)");
  sub->add_option("--concavity", o.concavity,
                  "target concavity, fraction of the bounding-box diagonal (default 0.01)");
  sub->add_option("--max-pieces", o.max_pieces, "at most this many pieces (default 64)");
  sub->add_option("--time-limit", o.time_limit,
                  "seconds; then the best so far, with a warning (default 0: none)");
  sub->add_flag("--json", o.json, "print the report as JSON");
  sub->add_option("--add", o.add,
                  "append the model to this scene (.glb); -o may name the same file");
  sub->add_option("--at", o.at, "with --add: X Y Z [QX QY QZ QW], the model's pose in the scene")
      ->expected(3, 7);
  sub->add_option("--gravity", o.gravity,
                  "X Y Z m/s2, the scene's gravity (default: 0 -9.81 0 when the scene has a "
                  "dynamic body and declares none; 0 0 0 for none)")
      ->expected(3);
  sub->allow_extras();
  return sub;
}

int runImport(const ImportOptions& o, std::ostream& out, std::ostream& err) {
  Result<Parsed> parsed = parse(o);
  if (!parsed) {
    err << "hapticctl import: " << parsed.error().message << '\n';
    return 2;
  }
  const Parsed& p = parsed.value();
  Result<TriangleMesh> read = readModel(o.model);
  if (!read) {
    err << "hapticctl import: " << read.error().message << '\n';
    return 1;
  }
  TriangleMesh mesh = std::move(read).value();
  if (p.units_assumed)
    err << "hapticctl import: units: m (assumed; give --units m|cm|mm|in)\n";
  const auto start = std::chrono::steady_clock::now();
  double last_line = 1.0;
  const auto progress = [&](const decomp::Progress& pr) {
    if (pr.elapsed_s < last_line)
      return;
    last_line = pr.elapsed_s + 1.0;
    char buf[160];
    std::snprintf(buf, sizeof buf, "hapticctl import: %zu pieces, concavity %.4f, %.1f s (%s)\n",
                  pr.pieces, pr.concavity, pr.elapsed_s, pr.stage);
    err << buf << std::flush;
  };
  auto result = decomp::decompose(mesh, p.decomp, progress);
  if (!result) {
    err << "hapticctl import: " << o.model << ": " << result.error().message << '\n';
    return 1;
  }
  (void)start;
  const decomp::DecompResult& r = result.value();
  // visual mesh in metres: finite triangles with valid indices only
  TriangleMesh visual;
  for (const Vec3& v : mesh.positions)
    visual.positions.push_back(std::isfinite(v.x + v.y + v.z) ? v * p.scale : Vec3{0.0});
  for (const decomp::Triangle& t : mesh.triangles)
    if (t[0] < mesh.positions.size() && t[1] < mesh.positions.size() &&
        t[2] < mesh.positions.size() &&
        std::isfinite(mesh.positions[t[0]].x + mesh.positions[t[1]].x + mesh.positions[t[2]].x +
                      mesh.positions[t[0]].y + mesh.positions[t[1]].y + mesh.positions[t[2]].y +
                      mesh.positions[t[0]].z + mesh.positions[t[1]].z + mesh.positions[t[2]].z))
      visual.triangles.push_back(t);
  // the union's: merged pieces overlap their neighbours, and their sum would count that twice
  const double volume_m3 = r.report.union_volume * p.scale * p.scale * p.scale;
  const double mass_kg = p.mass_kg ? *p.mass_kg : p.density ? *p.density * volume_m3 : 0.0;
  // the scene appended to, read first: the new body's name must differ from its nodes' (a model
  // added three times is three bodies, `box`, `box_2`, `box_3`, as --record-bodies names them)
  std::optional<std::pair<Json, std::vector<std::uint8_t>>> base;
  if (!o.add.empty()) {
    auto base_bytes = readFile(o.add);
    if (!base_bytes) {
      err << "hapticctl import: --add " << base_bytes.error().message << '\n';
      return 1;
    }
    auto split = splitGlb(base_bytes.value(), o.add);
    if (!split) {
      err << "hapticctl import: " << split.error().message << '\n';
      return 1;
    }
    base = std::move(split).value();
  }
  std::string name = fs::path(o.model).stem().string();
  if (base) {
    const auto taken = [&](const std::string& n) {
      if (!base->first.contains("nodes") || !base->first["nodes"].is_array())
        return false;
      for (const Json& node : base->first["nodes"]) {
        const std::string have = node.is_object() ? node.value("name", std::string{}) : "";
        if (have == n || have.rfind(n + "_", 0) == 0)
          return true;
      }
      return false;
    };
    const std::string stem = name;
    for (int k = 2; taken(name); ++k)
      name = stem + "_" + std::to_string(k);
  }
  std::vector<std::uint8_t> glb = buildScene(name, visual, r, o, p, mass_kg);
  auto mine = splitGlb(glb, "the new model");
  if (!mine) {
    err << "hapticctl import: " << mine.error().message << '\n';
    return 1;
  }
  std::pair<Json, std::vector<std::uint8_t>> scene_parts;
  if (base) {
    scene_parts = std::move(*base);
    mergeInto(scene_parts.first, scene_parts.second, mine.value().first, mine.value().second);
  } else {
    scene_parts = std::move(mine).value();
  }
  auto& [doc, bin] = scene_parts;
  // the scene's gravity: as given, else standard gravity along -Y for a scene with a dynamic body
  // and none declared (a dropped or stacked body should fall, as in every engine)
  std::string gravity_said;
  Json gravity_written;  // null: left as the scene had it
  {
    // `extras.haptic` of a scene or of the asset, when it is an object
    const auto haptic = [](Json& holder) -> Json* {
      if (!holder.is_object() || !holder.contains("extras") || !holder["extras"].is_object() ||
          !holder["extras"].contains("haptic") || !holder["extras"]["haptic"].is_object())
        return nullptr;
      return &holder["extras"]["haptic"];
    };
    Json& scenes = doc["scenes"];
    const std::size_t si = doc.contains("scene") && doc["scene"].is_number_unsigned()
                               ? doc["scene"].get<std::size_t>()
                               : 0;
    if (scenes.is_array() && si < scenes.size()) {
      Json& sc = scenes[si];
      Json* asset = doc.contains("asset") ? haptic(doc["asset"]) : nullptr;
      const bool declared = (haptic(sc) != nullptr && haptic(sc)->contains("gravity")) ||
                            (asset != nullptr && asset->contains("gravity"));
      std::vector<double> g = p.gravity;
      if (g.empty() && o.role == "dynamic" && !declared) {
        g = {0.0, -9.81, 0.0};
        gravity_said =
            "gravity 0 -9.81 0 m/s2 (a dynamic body and none declared: --gravity to change)";
      } else if (!g.empty()) {
        gravity_said = "gravity " + scenes::jsonVec({g[0], g[1], g[2]}).dump() + " m/s2";
      }
      if (!g.empty()) {
        gravity_written = scenes::jsonVec({g[0], g[1], g[2]});
        if (haptic(sc) == nullptr) {
          if (!sc.contains("extras") || !sc["extras"].is_object())
            sc["extras"] = Json::object();
          sc["extras"]["haptic"] = Json::object();
        }
        (*haptic(sc))["gravity"] = gravity_written;
        if (asset != nullptr)
          asset->erase("gravity");  // the two must agree: one place
      }
    }
  }
  glb = scene::packGlb(doc.dump(), bin);
  std::ofstream file(o.output, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(glb.data()), static_cast<std::streamsize>(glb.size()));
  if (!file) {
    err << "hapticctl import: cannot write " << o.output << ": " << std::strerror(errno) << '\n';
    return 1;
  }
  // added to a scene: the bodies it starts overlapping (--at places the model's origin, not its
  // bottom), said, not refused (a scene may mean it: a part inside a holder)
  Json overlaps = Json::array();
  if (base) {
    const scene::LoadReport written = scene::loadScene(glb, o.output);
    if (written.ok()) {
      const scene::SceneModel& sc = *written.scene;
      for (const Overlap& v : startingOverlaps(sc)) {
        const bool a_new = sc.bodies[v.a].name == name, b_new = sc.bodies[v.b].name == name;
        if (a_new == b_new)
          continue;
        const std::string& other = sc.bodies[a_new ? v.b : v.a].name;
        overlaps.push_back({{"body", other}, {"depth_m", v.depth_m}});
        err << "hapticctl import: warning: '" << name << "' starts " << v.depth_m << " m into '"
            << other << "' (--at places the model's origin, not its bottom)\n";
      }
    }
  }
  if (o.json) {
    Json j = reportJson(r.report);
    j["ok"] = true;
    if (base)
      j["overlaps"] = overlaps;
    j["output"] = o.output;
    j["units"] = p.units;
    j["units_assumed"] = p.units_assumed;
    j["role"] = o.role;
    j["body"] = name;
    if (!gravity_written.is_null())
      j["gravity"] = gravity_written;
    if (o.role == "dynamic")
      j["mass_kg"] = mass_kg > 0.0 ? Json(mass_kg) : Json(1000.0 * volume_m3);
    out << j.dump() << '\n';
  } else {
    out << "wrote " << o.output << " (" << o.role << " body '" << name << "', units " << p.units
        << (p.units_assumed ? " assumed" : "") << ")\n";
    if (!gravity_said.empty())
      out << gravity_said << '\n';
    out << decomp::describe(r.report);
  }
  return 0;
}

}  // namespace hapticd::client
