// scene_corpus_gen DIR: writes the loader's bad-file corpus to DIR/bad (with expected.txt, one
// "name<TAB>allow<TAB>expected message" line per file) and the good scenes to DIR/good.
// The committed tests/scenes/{bad,good} are its output; scene_corpus_test checks they match.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "tests/core/scene/corpus.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: scene_corpus_gen DIR\n";
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
  for (const auto& f : hapticd::scene::testing::goodCorpus())
    write(dir / "good" / f.name, f.bytes);
  return 0;
}
