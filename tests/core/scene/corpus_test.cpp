// The bad-file corpus (tests/scenes/bad/): every file gives its own error, nothing crashes or
// hangs; the committed files are exactly what scene_corpus_gen makes; the good scenes load; and
// every prefix and many byte-flipped copies of a good file are refused or loaded, never a crash.
#include "tests/core/scene/corpus.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "core/scene/loader.h"

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

TEST(SceneCorpus, TheGoodScenesLoad) {
  for (const auto& f : testing::goodCorpus()) {
    SCOPED_TRACE(f.name);
    const auto path = kScenes / "good" / f.name;
    EXPECT_EQ(readFile(path), f.bytes);
    const LoadReport r = loadSceneFile(path);
    EXPECT_TRUE(r.ok()) << r.message();
  }
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

}  // namespace
}  // namespace hapticd::scene
