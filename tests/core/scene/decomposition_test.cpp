// Meshes that are not convex at load (issue 16 item 3): one code path for a TRIMESH collider, a
// mesh collider and a plain model's mesh; the options and the node's extras.haptic.concavity; the
// decomposition cache (a second load decomposes nothing; corrupt, truncated, foreign and old
// entries are refused and rebuilt; no cache folder; a folder that cannot be written); progress.
// Every test that may write a cache uses its own temporary folder.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/decomp_cache.h"
#include "core/scene/loader.h"
#include "tests/core/scene/gltf_builder.h"
#include "tests/core/scene/scene_test_util.h"

namespace hapticd::scene {
namespace {

using testing::GltfBuilder;
using testing::json;
using testing::load;
namespace fs = std::filesystem;

// a fresh folder under the system's temporary folder, removed at the end
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("hapticd_decomp_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// the cache's entries in `dir`
std::vector<fs::path> entries(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::exists(dir))
    return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".pieces")
      out.push_back(e.path());
  }
  return out;
}

LoadOptions withCache(const fs::path& dir) {
  LoadOptions o;
  o.decomposition.cache_dir = dir;
  return o;
}

// one static node whose collider is the dented cube (not convex); `concavity` on a parent node
// when set
GltfBuilder dentedScene(std::optional<double> parent_concavity = std::nullopt, double h = 0.5) {
  GltfBuilder b;
  json parent = GltfBuilder::node("Group");
  if (parent_concavity)
    parent["extras"]["haptic"]["concavity"] = *parent_concavity;
  const int p = b.addNode(parent);
  json n = GltfBuilder::node("Dented");
  n["mesh"] = b.addMesh(testing::dentedCubeMesh(h), "DentedMesh");
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 1}}}};
  b.addNode(n, p);
  return b;
}

// the pieces of every primitive's shape, vertex by vertex
std::vector<std::vector<Vec3>> shapesOf(const SceneModel& s) {
  std::vector<std::vector<Vec3>> out;
  for (const Body& body : s.bodies) {
    for (const Primitive& p : body.primitives) {
      std::vector<Vec3> v;
      for (const auto& x : p.shape->vertices())
        v.push_back(x.p);
      out.push_back(v);
    }
  }
  return out;
}

std::string warningsOf(const LoadReport& r) {
  std::string out;
  for (const std::string& w : r.warnings)
    out += w + "\n";
  return out;
}

TEST(SceneDecomposition, ASecondLoadReadsTheCacheAndDecomposesNothing) {
  const TempDir dir;
  const GltfBuilder b = dentedScene();
  const LoadReport first = load(b, withCache(dir.path()));
  ASSERT_TRUE(first.ok()) << first.message();
  EXPECT_EQ(first.decomposition.decomposed, 1u);
  EXPECT_EQ(first.decomposition.cache_hits, 0u);
  EXPECT_EQ(first.decomposition.cache_written, 1u);
  EXPECT_EQ(entries(dir.path()).size(), 1u);
  EXPECT_TRUE(first.warnings.empty()) << warningsOf(first);

  const LoadReport second = load(b, withCache(dir.path()));
  ASSERT_TRUE(second.ok()) << second.message();
  EXPECT_EQ(second.decomposition.decomposed, 0u);
  EXPECT_EQ(second.decomposition.cache_hits, 1u);
  EXPECT_EQ(second.decomposition.cache_written, 0u);
  // the same primitives, vertex for vertex, and the same note
  EXPECT_GE(second.scene->bodies[0].primitives.size(), 2u);
  EXPECT_EQ(shapesOf(*second.scene), shapesOf(*first.scene));
  EXPECT_EQ(testing::notesOf(*second.scene), testing::notesOf(*first.scene));
  for (const Primitive& p : second.scene->bodies[0].primitives)
    EXPECT_EQ(p.source, ShapeSource::kMeshPiece);
}

TEST(SceneDecomposition, OptionsThatChangeThePiecesMakeAnotherEntry) {
  const TempDir dir;
  const GltfBuilder b = dentedScene();
  ASSERT_TRUE(load(b, withCache(dir.path())).ok());
  LoadOptions other = withCache(dir.path());
  other.decomposition.max_pieces = 3;
  const LoadReport r = load(b, other);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r.decomposition.decomposed, 1u);
  EXPECT_EQ(r.decomposition.cache_hits, 0u);
  EXPECT_EQ(entries(dir.path()).size(), 2u);
  // the same mesh scaled is another mesh
  GltfBuilder scaled = dentedScene();
  scaled.doc["nodes"][1]["scale"] = {2.0, 2.0, 2.0};
  const LoadReport s = load(scaled, withCache(dir.path()));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(s.decomposition.decomposed, 1u);
}

// the entry rewritten by `damage`, then loaded: refused with a warning, decomposed again, written
// again, and the load after that reads it
void expectRefusedAndRebuilt(const std::string& what,
                             const std::function<void(const fs::path& entry)>& damage,
                             const std::string& why) {
  SCOPED_TRACE(what);
  const TempDir dir;
  const GltfBuilder b = dentedScene();
  const LoadReport first = load(b, withCache(dir.path()));
  ASSERT_TRUE(first.ok()) << first.message();
  const auto found = entries(dir.path());
  ASSERT_EQ(found.size(), 1u);
  damage(found[0]);

  const LoadReport r = load(b, withCache(dir.path()));
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r.decomposition.cache_refused, 1u);
  EXPECT_EQ(r.decomposition.cache_hits, 0u);
  EXPECT_EQ(r.decomposition.decomposed, 1u);
  EXPECT_EQ(r.decomposition.cache_written, 1u);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("decomposition cache: entry " + found[0].string()),
            std::string::npos)
      << r.warnings[0];
  EXPECT_NE(r.warnings[0].find(why), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("decomposing again"), std::string::npos) << r.warnings[0];
  EXPECT_EQ(shapesOf(*r.scene), shapesOf(*first.scene));

  const LoadReport again = load(b, withCache(dir.path()));
  ASSERT_TRUE(again.ok()) << again.message();
  EXPECT_EQ(again.decomposition.cache_hits, 1u);
  EXPECT_EQ(again.decomposition.decomposed, 0u);
  EXPECT_TRUE(again.warnings.empty()) << warningsOf(again);
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeAll(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(SceneDecomposition, CorruptTruncatedForeignAndOldEntriesAreRefusedAndRebuilt) {
  // header: magic 8, version 4, key 64, payload length 8, checksum 64
  constexpr std::size_t kVersionAt = 8, kHeader = 8 + 4 + 64 + 8 + 64;
  expectRefusedAndRebuilt(
      "a flipped payload byte",
      [](const fs::path& e) {
        std::string s = readAll(e);
        s[s.size() - 3] = static_cast<char>(s[s.size() - 3] ^ 0x40);
        writeAll(e, s);
      },
      "checksum mismatch");
  expectRefusedAndRebuilt(
      "truncated in the payload",
      [](const fs::path& e) {
        const std::string s = readAll(e);
        writeAll(e, s.substr(0, s.size() - 10));
      },
      "truncated");
  expectRefusedAndRebuilt(
      "truncated in the header", [](const fs::path& e) { writeAll(e, readAll(e).substr(0, 20)); },
      "truncated");
  expectRefusedAndRebuilt(
      "empty", [](const fs::path& e) { writeAll(e, ""); }, "truncated");
  expectRefusedAndRebuilt(
      "not an entry", [](const fs::path& e) { writeAll(e, std::string(300, 'x')); },
      "not a hapticd decomposition cache entry");
  expectRefusedAndRebuilt(
      "an older format version",
      [](const fs::path& e) {
        std::string s = readAll(e);
        s[kVersionAt] = 0;  // version 0 (the format is 1)
        writeAll(e, s);
      },
      "format version 0");
  expectRefusedAndRebuilt(
      "another mesh's entry under this name",
      [](const fs::path& e) {
        // a complete, valid entry of another key copied over this one
        detail::CachedPieces pieces;
        pieces.note = "touched through 1 convex piece";
        pieces.pieces = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
        const fs::path other = e.parent_path() / "other";
        ASSERT_TRUE(detail::writeCacheEntry(other, std::string(64, 'a'), pieces));
        fs::copy_file(detail::cacheEntryPath(other, std::string(64, 'a')), e,
                      fs::copy_options::overwrite_existing);
      },
      "made for another mesh");
  expectRefusedAndRebuilt(
      "a valid checksum over pieces of 3 vertices",
      [](const fs::path& e) {
        detail::CachedPieces pieces;
        pieces.pieces = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
        ASSERT_TRUE(detail::writeCacheEntry(e.parent_path(), e.stem().string(), pieces));
      },
      "a piece of 3 vertices");
  expectRefusedAndRebuilt(
      "a valid checksum over more pieces than max_pieces",
      [](const fs::path& e) {
        detail::CachedPieces pieces;
        pieces.pieces.assign(65, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
        ASSERT_TRUE(detail::writeCacheEntry(e.parent_path(), e.stem().string(), pieces));
      },
      "65 pieces, not 1..64");
  expectRefusedAndRebuilt(
      "a valid checksum over a coordinate that is not finite",
      [](const fs::path& e) {
        detail::CachedPieces pieces;
        pieces.pieces = {{{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}, {0, 0, 1}}};
        ASSERT_TRUE(detail::writeCacheEntry(e.parent_path(), e.stem().string(), pieces));
      },
      "not finite");
  expectRefusedAndRebuilt(
      "bytes after the payload the header counts",
      [](const fs::path& e) { writeAll(e, readAll(e) + "tail"); }, "truncated or padded");
  static_assert(kHeader == 148);
}

TEST(SceneDecomposition, NoCacheFolderTurnsTheCacheOff) {
  const GltfBuilder b = dentedScene();
  for (int i = 0; i < 2; ++i) {
    const LoadReport r = load(b);  // LoadOptions{}: cache_dir empty
    ASSERT_TRUE(r.ok()) << r.message();
    EXPECT_EQ(r.decomposition.decomposed, 1u);
    EXPECT_EQ(r.decomposition.cache_hits + r.decomposition.cache_written, 0u);
  }
  EXPECT_EQ(decompositionCacheDir(""), fs::path());
}

// [scene] cache_max_mb: after a write, the least recently used entries (modification time; a
// hit refreshes it) go until the rest fit, never the new one; temporary files of dead writers go;
// nothing else in the folder is touched
TEST(SceneDecomposition, TheCacheKeepsItsSizeByRemovingTheLeastRecentlyUsedEntries) {
  const TempDir dir;
  detail::CachedPieces pieces;
  pieces.note = "four points";
  pieces.pieces.push_back(
      {Vec3{0.0}, Vec3{1.0, 0.0, 0.0}, Vec3{0.0, 1.0, 0.0}, Vec3{0.0, 0.0, 1.0}});
  const std::string k1(64, '1'), k2(64, '2'), k3(64, '3'), k4(64, '4');
  const auto now = fs::file_time_type::clock::now();
  int age = 400;
  for (const std::string& k : {k1, k2, k3, k4}) {
    ASSERT_TRUE(detail::writeCacheEntry(dir.path(), k, pieces));
    fs::last_write_time(detail::cacheEntryPath(dir.path(), k), now - std::chrono::seconds(age));
    age -= 100;  // k1 the oldest, k4 the newest
  }
  const std::uintmax_t size = fs::file_size(detail::cacheEntryPath(dir.path(), k1));
  // not entries: a file of the user's, an entry's copy, a writer's file still being written and
  // one of a writer that died two hours ago
  writeAll(dir.path() / "notes.txt", std::string(4 * size, 'x'));
  writeAll(dir.path() / (k1 + ".pieces.bak"), "copy");
  const fs::path fresh_tmp = dir.path() / (k3 + ".pieces.tmp.77.0");
  const fs::path dead_tmp = dir.path() / (k4 + ".pieces.tmp.78.0");
  writeAll(fresh_tmp, "half");
  writeAll(dead_tmp, "half");
  fs::last_write_time(dead_tmp, now - std::chrono::hours(2));

  // no limit: nothing goes but the dead writer's file
  const detail::Eviction none = detail::evictCache(dir.path(), 0, k4);
  EXPECT_EQ(none.entries, 0u);
  EXPECT_EQ(none.stale, 1u);
  EXPECT_FALSE(fs::exists(dead_tmp));
  EXPECT_EQ(entries(dir.path()).size(), 4u);

  // k1 read: now the most recently used
  const detail::CacheLookup hit = detail::readCacheEntry(dir.path(), k1, 64);
  ASSERT_EQ(hit.status, detail::CacheLookup::Status::kHit) << hit.why;
  // room for two and a half: in order of use k2, k3, k4, k1; k2 kept (just written), so k3 and
  // k4 go
  const detail::Eviction ev = detail::evictCache(dir.path(), 2 * size + size / 2, k2);
  EXPECT_EQ(ev.entries, 2u);
  EXPECT_EQ(ev.bytes, 2 * size);
  EXPECT_EQ(ev.stale, 0u);
  EXPECT_TRUE(fs::exists(detail::cacheEntryPath(dir.path(), k1)));
  EXPECT_TRUE(fs::exists(detail::cacheEntryPath(dir.path(), k2)));
  EXPECT_FALSE(fs::exists(detail::cacheEntryPath(dir.path(), k3)));
  EXPECT_FALSE(fs::exists(detail::cacheEntryPath(dir.path(), k4)));
  EXPECT_TRUE(fs::exists(dir.path() / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir.path() / (k1 + ".pieces.bak")));
  EXPECT_TRUE(fs::exists(fresh_tmp));
  // within the limit: nothing more
  EXPECT_EQ(detail::evictCache(dir.path(), 2 * size, k2).entries, 0u);
  // a limit below the kept entry alone: every other entry goes, the kept one stays
  EXPECT_EQ(detail::evictCache(dir.path(), 1, k2).entries, 1u);
  EXPECT_EQ(entries(dir.path()), std::vector<fs::path>{detail::cacheEntryPath(dir.path(), k2)});
}

// through the loader: a limit of one byte keeps only the entry of the latest decomposition, the
// load counts what it removed, and the removed mesh is decomposed again on its next load
TEST(SceneDecomposition, ALoadOverTheCachesLimitRemovesOtherEntriesAndKeepsItsOwn) {
  const TempDir dir;
  LoadOptions tiny = withCache(dir.path());
  tiny.decomposition.cache_max_bytes = 1;
  const GltfBuilder b = dentedScene();
  const LoadReport first = load(b, tiny);
  ASSERT_TRUE(first.ok()) << first.message();
  EXPECT_EQ(first.decomposition.cache_written, 1u);
  EXPECT_EQ(first.decomposition.cache_evicted, 0u);
  LoadOptions other = tiny;
  other.decomposition.max_pieces = 3;
  const LoadReport second = load(b, other);
  ASSERT_TRUE(second.ok()) << second.message();
  EXPECT_EQ(second.decomposition.cache_written, 1u);
  EXPECT_EQ(second.decomposition.cache_evicted, 1u);
  EXPECT_EQ(entries(dir.path()).size(), 1u);
  const LoadReport again = load(b, other);  // its own entry was kept
  EXPECT_EQ(again.decomposition.cache_hits, 1u);
  const LoadReport back = load(b, tiny);  // the first one's was removed
  EXPECT_EQ(back.decomposition.cache_hits, 0u);
  EXPECT_EQ(back.decomposition.decomposed, 1u);
  EXPECT_EQ(back.decomposition.cache_evicted, 1u);
  // the default keeps 512 MiB
  EXPECT_EQ(DecompositionOptions{}.cache_max_bytes, std::uint64_t{512} << 20);
}

TEST(SceneDecomposition, AFolderThatCannotBeWrittenIsAWarningAndTheSceneLoads) {
  const TempDir dir;
  // a folder under a regular file cannot be made by anyone, root included
  writeAll(dir.path() / "file", "x");
  const fs::path cache = dir.path() / "file" / "hapticd";
  const GltfBuilder b = dentedScene();
  const LoadReport r = load(b, withCache(cache));
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r.decomposition.decomposed, 1u);
  EXPECT_EQ(r.decomposition.cache_written, 0u);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("decomposition cache: cannot create " + cache.string()),
            std::string::npos)
      << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("the scene loads all the same"), std::string::npos);
  EXPECT_GE(r.scene->bodies[0].primitives.size(), 2u);
}

TEST(SceneDecomposition, TheNodesConcavityOverridesTheOption) {
  const TempDir dir;
  // concavity 0.01 from the options: one entry
  ASSERT_TRUE(load(dentedScene(), withCache(dir.path())).ok());
  // options 0.3, but 0.01 on the parent node: the same key, read from the cache
  LoadOptions coarse = withCache(dir.path());
  coarse.decomposition.concavity = 0.3;
  const LoadReport over = load(dentedScene(0.01), coarse);
  ASSERT_TRUE(over.ok()) << over.message();
  EXPECT_EQ(over.decomposition.cache_hits, 1u);
  EXPECT_EQ(over.decomposition.decomposed, 0u);
  // options 0.3 and no override: another key, decomposed
  const LoadReport plain = load(dentedScene(), coarse);
  ASSERT_TRUE(plain.ok()) << plain.message();
  EXPECT_EQ(plain.decomposition.cache_hits, 0u);
  EXPECT_EQ(plain.decomposition.decomposed, 1u);
  EXPECT_NE(testing::notesOf(*plain.scene).find("target 0.3"), std::string::npos)
      << testing::notesOf(*plain.scene);
  EXPECT_NE(testing::notesOf(*over.scene).find("target 0.01"), std::string::npos)
      << testing::notesOf(*over.scene);
}

TEST(SceneDecomposition, ABadConcavityOnANodeOrInTheOptionsIsRefused) {
  for (const double c : {0.0, 1.0, -0.5, 2.0}) {
    const LoadReport r = load(dentedScene(c));
    EXPECT_FALSE(r.ok()) << c;
    EXPECT_TRUE(testing::hasProblem(r, "node 0 'Group' extras.haptic")) << r.message();
    EXPECT_TRUE(testing::hasProblem(r, "concavity")) << r.message();
  }
  GltfBuilder text = dentedScene();
  text.doc["nodes"][0]["extras"]["haptic"]["concavity"] = "fine";
  EXPECT_FALSE(load(text).ok());
  for (const double c : {0.0, 1.0, std::nan("")}) {
    LoadOptions o;
    o.decomposition.concavity = c;
    const LoadReport r = load(dentedScene(), o);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(testing::hasProblem(r, "options: concavity")) << r.message();
  }
  LoadOptions none;
  none.decomposition.max_pieces = 0;
  EXPECT_TRUE(testing::hasProblem(load(dentedScene(), none), "max_pieces"));
  LoadOptions negative;
  negative.decomposition.time_limit_s = -1.0;
  EXPECT_TRUE(testing::hasProblem(load(dentedScene(), negative), "decompose_time_limit_s"));
}

TEST(SceneDecomposition, TrimeshMeshColliderAndPlainMeshShareOneDecomposition) {
  const TempDir dir;
  // a KHR mesh collider
  const LoadReport khr = load(dentedScene(), withCache(dir.path()));
  ASSERT_TRUE(khr.ok()) << khr.message();
  EXPECT_EQ(khr.decomposition.decomposed, 1u);
  // a plain model: the same mesh on a node, no physics extension
  GltfBuilder plain;
  json n = GltfBuilder::node("Dented");
  n["mesh"] = plain.addMesh(testing::dentedCubeMesh(), "DentedMesh");
  plain.addNode(n);
  const LoadReport p = load(plain, withCache(dir.path()));
  ASSERT_TRUE(p.ok()) << p.message();
  EXPECT_EQ(p.decomposition.decomposed, 0u);
  EXPECT_EQ(p.decomposition.cache_hits, 1u);
  // an OMI trimesh shape
  GltfBuilder omi;
  const int mesh = omi.addMesh(testing::dentedCubeMesh(), "DentedMesh");
  omi.doc["extensions"]["OMI_physics_shape"]["shapes"] =
      json::array({{{"type", "trimesh"}, {"trimesh", {{"mesh", mesh}}}}});
  omi.useExtension("OMI_physics_body", false);
  omi.useExtension("OMI_physics_shape", false);
  json o = GltfBuilder::node("Dented");
  o["extensions"]["OMI_physics_body"] = {{"collider", {{"shape", 0}}}};
  omi.addNode(o);
  const LoadReport t = load(omi, withCache(dir.path()));
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_EQ(t.decomposition.decomposed, 0u);
  EXPECT_EQ(t.decomposition.cache_hits, 1u);
  EXPECT_EQ(shapesOf(*t.scene), shapesOf(*khr.scene));
  EXPECT_EQ(shapesOf(*p.scene), shapesOf(*khr.scene));
}

TEST(SceneDecomposition, ProgressIsToldWhileAMeshIsDecomposed) {
  std::vector<LoadProgress> told;
  LoadOptions o;
  o.progress = [&](const LoadProgress& p) { told.push_back(p); };
  const LoadReport r = load(dentedScene(), o);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_FALSE(told.empty());
  for (const LoadProgress& p : told) {
    EXPECT_EQ(p.mesh, 1u);
    EXPECT_NE(p.mesh_name.find("'DentedMesh'"), std::string::npos) << p.mesh_name;
    EXPECT_GE(p.elapsed_s, 0.0);
  }
  EXPECT_GE(told.back().pieces, 1u);
  // from the cache: nothing to tell
  const TempDir dir;
  o.decomposition.cache_dir = dir.path();
  ASSERT_TRUE(load(dentedScene(), o).ok());
  told.clear();
  const LoadReport cached = load(dentedScene(), o);
  ASSERT_TRUE(cached.ok());
  EXPECT_EQ(cached.decomposition.cache_hits, 1u);
  EXPECT_TRUE(told.empty());
}

// a UV sphere: convex, with more hull vertices than a small max_hull_vertices
testing::Mesh uvSphere(int rings, int segments, double r) {
  testing::Mesh m;
  m.vertices.push_back({0.0, r, 0.0});
  for (int i = 1; i < rings; ++i) {
    const double th = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2.0 * std::numbers::pi * j / segments;
      m.vertices.push_back(
          {r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph)});
    }
  }
  m.vertices.push_back({0.0, -r, 0.0});
  const auto at = [&](int ring, int j) {
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + (j % segments));
  };
  const auto bottom = static_cast<std::uint32_t>(m.vertices.size() - 1);
  for (int j = 0; j < segments; ++j) {
    m.triangles.insert(m.triangles.end(), {0u, at(1, j + 1), at(1, j)});
    for (int i = 1; i + 1 < rings; ++i) {
      m.triangles.insert(m.triangles.end(), {at(i, j), at(i, j + 1), at(i + 1, j)});
      m.triangles.insert(m.triangles.end(), {at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
    }
    m.triangles.insert(m.triangles.end(), {bottom, at(rings - 1, j), at(rings - 1, j + 1)});
  }
  return m;
}

TEST(SceneDecomposition, AMeshWhoseHullIsOverTheVertexLimitIsDecomposedNotRefused) {
  GltfBuilder b;
  json n = GltfBuilder::node("Ball");
  n["mesh"] = b.addMesh(uvSphere(16, 24, 0.1), "BallMesh");  // 362 vertices, all on its hull
  GltfBuilder::physics(n)["collider"] = {{"geometry", {{"node", 0}}}};
  b.addNode(n);
  // within the limit: one convex mesh
  const LoadReport whole = load(b);
  ASSERT_TRUE(whole.ok()) << whole.message();
  ASSERT_EQ(whole.scene->bodies[0].primitives.size(), 1u);
  EXPECT_EQ(whole.scene->bodies[0].primitives[0].source, ShapeSource::kConvexMesh);
  // over it: pieces, each within it, said so
  LoadOptions small;
  small.limits.max_hull_vertices = 64;
  const LoadReport r = load(b, small);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r.decomposition.decomposed, 1u);
  for (const Primitive& p : r.scene->bodies[0].primitives) {
    EXPECT_EQ(p.source, ShapeSource::kMeshPiece);
    EXPECT_LE(p.shape->vertices().size(), 64u);
  }
  EXPECT_NE(testing::notesOf(*r.scene).find("convex, but its hull has more than 64 vertices"),
            std::string::npos)
      << testing::notesOf(*r.scene);
  // with a cache: the pieces are read back under the same limit, and an entry made under
  // another limit is not used where the whole hull fits
  const TempDir dir;
  small.decomposition.cache_dir = dir.path();
  ASSERT_TRUE(load(b, small).ok());
  const LoadReport again = load(b, small);
  ASSERT_TRUE(again.ok()) << again.message();
  EXPECT_EQ(again.decomposition.cache_hits, 1u);
  EXPECT_EQ(shapesOf(*again.scene), shapesOf(*r.scene));
  EXPECT_EQ(testing::notesOf(*again.scene), testing::notesOf(*r.scene));
  const LoadReport fits = load(b, withCache(dir.path()));
  ASSERT_TRUE(fits.ok()) << fits.message();
  EXPECT_EQ(fits.decomposition.cache_hits, 0u);
  ASSERT_EQ(fits.scene->bodies[0].primitives.size(), 1u);
  EXPECT_EQ(fits.scene->bodies[0].primitives[0].source, ShapeSource::kConvexMesh);
}

TEST(SceneDecomposition, TheAutoCacheFolderFollowsTheEnvironment) {
  // the environment as ctest gives it is put back at the end
  const auto get = [](const char* name) -> std::optional<std::string> {
    const char* v = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): one test thread
    return v ? std::optional<std::string>(v) : std::nullopt;
  };
  const auto put = [](const char* name, const std::optional<std::string>& v) {
    if (v)
      ::setenv(name, v->c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
    else
      ::unsetenv(name);  // NOLINT(concurrency-mt-unsafe)
  };
  const auto cache = get("CACHE_DIRECTORY"), xdg = get("XDG_CACHE_HOME"), home = get("HOME");
  put("CACHE_DIRECTORY", "/var/cache/hapticd:/var/cache/other");
  put("XDG_CACHE_HOME", "/x/cache");
  put("HOME", "/home/u");
  EXPECT_EQ(decompositionCacheDir("auto"), fs::path("/var/cache/hapticd"));
  put("CACHE_DIRECTORY", std::nullopt);
  EXPECT_EQ(decompositionCacheDir("auto"), fs::path("/x/cache/hapticd"));
  put("XDG_CACHE_HOME", "");
  EXPECT_EQ(decompositionCacheDir("auto"), fs::path("/home/u/.cache/hapticd"));
  put("HOME", std::nullopt);
  EXPECT_EQ(decompositionCacheDir("auto"), fs::path());
  EXPECT_EQ(decompositionCacheDir("/srv/c"), fs::path("/srv/c"));
  put("CACHE_DIRECTORY", cache);
  put("XDG_CACHE_HOME", xdg);
  put("HOME", home);
}

}  // namespace
}  // namespace hapticd::scene
