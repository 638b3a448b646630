// The bad-file corpus (tests/scenes/bad/): every file gives its own error, nothing crashes or
// hangs; the committed files are exactly what scene_corpus_gen makes; the good scenes load; and
// every prefix and many byte-flipped copies of a good file are refused or loaded, never a crash.
#include "tests/core/scene/corpus.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <random>

#include "core/scene/loader.h"
#include "core/scene/triangles.h"
#include "tests/core/scene/plan_expect.h"

namespace hapticd::scene {
namespace {

const std::filesystem::path kScenes = HAPTICD_SOURCE_DIR "/tests/scenes";

std::vector<std::uint8_t> readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(SceneCorpus, EveryBadFileGivesItsOwnError) {
  const auto corpus = testing::badCorpus();
  ASSERT_GE(corpus.size(), 40u);
  for (const auto& f : corpus) {
    SCOPED_TRACE(f.name);
    const auto path = kScenes / "bad" / f.name;
    ASSERT_TRUE(std::filesystem::exists(path)) << "regenerate with scene_corpus_gen tests/scenes";
    EXPECT_EQ(readFile(path), f.bytes) << "the committed file differs from scene_corpus_gen's";
    LoadOptions options;
    if (f.allow_folder)
      options.allowed_uri_dir = kScenes / "bad";
    const LoadReport r = loadSceneFile(path, options);
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.problems.empty());
    EXPECT_NE(r.message().find(f.expect), std::string::npos)
        << "expected: " << f.expect << "\ngot:\n"
        << r.message();
  }
}

TEST(SceneCorpus, TheManifestListsEveryBadFile) {
  std::ifstream in(kScenes / "bad" / "expected.txt");
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);)
    ++lines;
  EXPECT_EQ(lines, testing::badCorpus().size());
}

TEST(SceneCorpus, TheGoodScenesLoadAndTheManifestListsEachAnswer) {
  std::ifstream in(kScenes / "good" / "expected.txt");
  std::string manifest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto corpus = testing::goodCorpus();
  ASSERT_GE(corpus.size(), 30u);
  for (const auto& f : corpus) {
    SCOPED_TRACE(f.name);
    const auto path = kScenes / "good" / f.name;
    EXPECT_EQ(readFile(path), f.bytes) << "regenerate with scene_corpus_gen tests/scenes";
    if (!f.scene)
      continue;  // a buffer beside a scene
    EXPECT_NE(manifest.find(f.name + "\t"), std::string::npos);
    const LoadReport r = loadSceneFile(path);
    EXPECT_TRUE(r.ok()) << r.message();
  }
}

// readSceneTriangles (hapticctl import's glTF reader) reads every good scene and says nothing of a
// bad file that the loader does not say in the same words: each problem it reports is one of the
// loader's (where and what), and a file it refuses is refused for the reason the corpus expects
// (files refused only while building bodies and colliders it reads)
TEST(SceneCorpus, ReadSceneTrianglesSaysWhatTheLoaderSays) {
  for (const auto& f : testing::goodCorpus()) {
    if (!f.scene)
      continue;
    SCOPED_TRACE(f.name);
    const TrianglesReport t = readSceneTrianglesFile(kScenes / "good" / f.name);
    EXPECT_TRUE(t.ok()) << t.message();
  }
  std::size_t refused = 0, refused_alike = 0;
  for (const auto& f : testing::badCorpus()) {
    SCOPED_TRACE(f.name);
    const auto path = kScenes / "bad" / f.name;
    LoadOptions load;
    if (f.allow_folder)
      load.allowed_uri_dir = kScenes / "bad";
    TrianglesOptions options;
    options.load = load;
    const TrianglesReport t = readSceneTrianglesFile(path, options);
    const LoadReport r = loadSceneFile(path, load);
    for (const Problem& p : t.problems) {
      const std::string line = p.where + ": " + p.what + "\n";
      EXPECT_NE(r.message().find(line), std::string::npos)
          << "readSceneTriangles: " << line << "the loader:\n"
          << r.message();
    }
    if (!t.ok()) {
      ++refused;
      refused_alike += t.message().find(f.expect) != std::string::npos ? 1u : 0u;
    }
  }
  // the files refused before building (71 of the 80 in December 2026), each for the loader's reason
  EXPECT_GT(refused, 0u);
  EXPECT_EQ(refused_alike, refused);
}

TEST(SceneCorpus, EveryPrefixOfAGoodFileIsRefusedCleanly) {
  const auto glb = testing::baseScene().glb();
  for (std::size_t n = 0; n < glb.size(); ++n) {
    const LoadReport r = loadScene(std::span(glb.data(), n), "prefix.glb");
    ASSERT_FALSE(r.ok()) << n;
    ASSERT_FALSE(r.problems.empty());
  }
  const std::string text = testing::baseScene().gltf();
  for (std::size_t n = 0; n < text.size(); n += 7) {
    const LoadReport r =
        loadScene(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), n), "prefix.gltf");
    ASSERT_FALSE(r.ok()) << n;
  }
}

TEST(SceneCorpus, FlippedBytesNeverCrash) {
  std::mt19937 rng(12345);
  const auto glb = testing::baseScene().glb();
  std::size_t loaded = 0;
  for (int i = 0; i < 3000; ++i) {
    auto v = glb;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k)
      v[rng() % v.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    const LoadReport r = loadScene(v, "flipped.glb");
    EXPECT_EQ(r.ok(), r.problems.empty());
    if (r.ok())
      ++loaded;
  }
  // some flips land in names or padding and leave a valid scene; most do not
  EXPECT_LT(loaded, 3000u);
}

// the committed demo scenes (scenes/*.glb, written by the scene generator, docs/demo-scenes.md):
// each loads, and its plan is what the scene calls for and nothing more
std::optional<SceneModel> demo(const char* name) {
  const auto path =
      std::filesystem::path(HAPTICD_SOURCE_DIR "/scenes") / (std::string(name) + ".glb");
  if (!std::filesystem::exists(path))
    return std::nullopt;
  const LoadReport r = loadSceneFile(path);
  EXPECT_TRUE(r.ok()) << name << ":\n" << r.message();
  return r.scene;
}

const Body* named(const SceneModel& s, const std::string& name) {
  for (const Body& b : s.bodies) {
    if (b.name == name)
      return &b;
  }
  ADD_FAILURE() << "no body " << name;
  return nullptr;
}

TEST(SceneCorpus, DemoScenesLoadWithThePlanTheyCallFor) {
  const auto gears = demo("gears");
  if (!gears)
    GTEST_SKIP() << "scenes/*.glb not here yet";
  {
    const SceneModel& s = *gears;
    testing::expectPlan(s.plan, "dynamics joints", 0, 41);
    ASSERT_EQ(s.joints.size(), 2u);
    for (const Joint& j : s.joints) {
      EXPECT_EQ(j.kind, JointKind::kHinge);
      EXPECT_EQ(j.hinge_axis, 2);  // about Z
      EXPECT_EQ(j.body_b, -1);     // to the scene frame
    }
    for (const char* g : {"GearA", "GearB"}) {
      const Body* b = named(s, g);
      ASSERT_TRUE(b);
      EXPECT_EQ(b->motion, Motion::kDynamic);
      EXPECT_EQ(b->primitives.size(), 20u);
      EXPECT_DOUBLE_EQ(b->mass, 0.15);
    }
    ASSERT_GE(s.probe_body, 0);
    EXPECT_EQ(s.bodies[static_cast<std::size_t>(s.probe_body)].motion, Motion::kKinematic);
  }
  const auto peg = demo("peg_in_hole");
  ASSERT_TRUE(peg);
  {
    const SceneModel& s = *peg;
    testing::expectPlan(s.plan, "", 5, 1);
    const Body* hole = named(s, "Hole");
    ASSERT_TRUE(hole);
    ASSERT_TRUE(hole->stiffness_n_per_m);
    EXPECT_DOUBLE_EQ(*hole->stiffness_n_per_m, 600.0);
    ASSERT_GE(s.probe_body, 0);
    EXPECT_EQ(s.bodies[static_cast<std::size_t>(s.probe_body)].name, "Peg");
  }
  const auto dyn = demo("dynamic");
  ASSERT_TRUE(dyn);
  {
    const SceneModel& s = *dyn;
    testing::expectPlan(s.plan, "dynamics gravity friction restitution", 1, 13);
    std::size_t dynamic = 0;
    for (const Body& b : s.bodies)
      dynamic += b.motion == Motion::kDynamic ? 1u : 0u;
    EXPECT_EQ(dynamic, 12u);
    const Body* e = named(s, "Ellipsoid0");
    ASSERT_TRUE(e);
    EXPECT_FALSE(e->mass_declared);
    EXPECT_NEAR(e->mass, 0.08094, 0.00001);  // the hull's volume at 1000 kg/m^3
  }
  const auto stress = demo("stress");
  ASSERT_TRUE(stress);
  {
    const SceneModel& s = *stress;
    EXPECT_GE(s.plan.static_primitives + s.plan.moving_primitives, 1000u);
    testing::expectPlan(s.plan, "dynamics gravity", 1025, 17);
  }
}

}  // namespace
}  // namespace hapticd::scene
