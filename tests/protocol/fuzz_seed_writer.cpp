// Writes the seed corpus of one fuzz target into a folder (for libFuzzer runs).
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/protocol/fuzz_seeds.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s TARGET DIR\n", argv[0]);
    return 2;
  }
  std::filesystem::create_directories(argv[2]);
  int i = 0;
  for (const auto& s : hapticd::proto::testing::fuzzSeeds(argv[1])) {
    std::ofstream f(std::filesystem::path(argv[2]) / ("seed_" + std::to_string(i++)),
                    std::ios::binary);
    f.write(reinterpret_cast<const char*>(s.data()), static_cast<std::streamsize>(s.size()));
  }
  return 0;
}
