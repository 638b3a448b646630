// scene_corpus_gen DIR: writes the loader's bad-file corpus to DIR/bad (with expected.txt, one
// "name<TAB>allow<TAB>expected message" line per file) and the good scenes to DIR/good (with
// expected.txt, one "name<TAB>a line hapticctl check prints" per expectation).
// The committed tests/scenes/{bad,good} are its output; scene_corpus_test checks they match.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <span>
#include <tuple>

#include "tests/core/scene/corpus.h"

namespace {

/// Seeds of scene_decoders_fuzz (tests/fuzz): a selector byte, two parameter bytes, a stream.
void writeFuzzSeeds(const std::filesystem::path& dir) {
  using namespace hapticd::scene::testing;
  std::filesystem::create_directories(dir);
  const auto seed = [&](const std::string& name, std::uint8_t selector, std::uint8_t a,
                        std::uint8_t b, std::span<const std::uint8_t> stream) {
    std::ofstream out(dir / name, std::ios::binary);
    const std::uint8_t head[3] = {selector, a, b};
    out.write(reinterpret_cast<const char*>(head), 3);
    out.write(reinterpret_cast<const char*>(stream.data()),
              static_cast<std::streamsize>(stream.size()));
  };
  GltfBuilder d;
  addDracoMesh(d, dentedCubeMesh(), "Dented");
  const json& ext = d.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"];
  seed("draco_mesh", 0, ext["attributes"]["POSITION"].get<std::uint8_t>(), 0, d.bin);
  seed("draco_cloud", 1, ext["attributes"]["POSITION"].get<std::uint8_t>(), 0, d.bin);
  // meshopt: 8 positions (stride 12 = 4 * 3, count 8), 36 triangle indices, 36 index sequence
  for (const auto& [name, filter, index_mode, mode] :
       {std::tuple{"meshopt_attributes", "NONE", "TRIANGLES", 2},
        std::tuple{"meshopt_exponential", "EXPONENTIAL", "INDICES", 2}}) {
    GltfBuilder m;
    addMeshoptMesh(m, cubeMesh(), "Cube", filter, index_mode);
    const json& views = m.doc["bufferViews"];
    const auto slice = [&](std::size_t v) {
      const json& e = views[v]["extensions"]["EXT_meshopt_compression"];
      const auto at = e["byteOffset"].get<std::size_t>(), n = e["byteLength"].get<std::size_t>();
      return std::span<const std::uint8_t>(m.bin).subspan(at, n);
    };
    const std::uint8_t a =
        static_cast<std::uint8_t>(2 | (std::string(filter) == "NONE" ? 0 : 3 << 4));
    seed(std::string(name) + "_positions", static_cast<std::uint8_t>(mode), a, 7, slice(0));
    seed(std::string(name) + "_indices",
         static_cast<std::uint8_t>(std::string(index_mode) == "TRIANGLES" ? 2 + 4 : 2 + 8), 1,
         std::string(index_mode) == "TRIANGLES" ? 11 : 35, slice(1));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--fuzz-seeds") {
    writeFuzzSeeds(argv[2]);
    return 0;
  }
  if (argc != 2) {
    std::cerr << "usage: scene_corpus_gen DIR | scene_corpus_gen --fuzz-seeds DIR\n";
    return 2;
  }
  namespace fs = std::filesystem;
  const fs::path dir = argv[1];
  fs::create_directories(dir / "bad");
  fs::create_directories(dir / "good");
  const auto write = [](const fs::path& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  };
  std::ofstream manifest(dir / "bad" / "expected.txt");
  for (const auto& f : hapticd::scene::testing::badCorpus()) {
    write(dir / "bad" / f.name, f.bytes);
    manifest << f.name << '\t' << (f.allow_folder ? 1 : 0) << '\t' << f.expect << '\n';
  }
  std::ofstream good(dir / "good" / "expected.txt");
  for (const auto& f : hapticd::scene::testing::goodCorpus()) {
    write(dir / "good" / f.name, f.bytes);
    std::size_t start = 0;
    while (f.scene && start < f.expect.size()) {
      const std::size_t end = std::min(f.expect.find('\n', start), f.expect.size());
      good << f.name << '\t' << f.expect.substr(start, end - start) << '\n';
      start = end + 1;
    }
  }
  return 0;
}
