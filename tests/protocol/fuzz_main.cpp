// Without libFuzzer (GCC): runs a fuzz target over its seed corpus and 2000 deterministic
// mutations of each seed (bit flips, truncations, insertions, length-field lies).
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "tests/protocol/fuzz_seeds.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  const std::string target = argc > 1 ? argv[1] : "messages";
  std::mt19937 rng(20261201);
  std::size_t runs = 0;
  for (const auto& seed : hapticd::proto::testing::fuzzSeeds(target)) {
    LLVMFuzzerTestOneInput(seed.data(), seed.size());
    ++runs;
    for (int k = 0; k < 2000; ++k) {
      std::vector<std::uint8_t> d = seed;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits; ++e) {
        switch (rng() % 4) {
          case 0:
            if (!d.empty())
              d[rng() % d.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
            break;
          case 1:
            if (!d.empty())
              d.resize(rng() % d.size());
            break;
          case 2:
            d.insert(d.begin() + static_cast<long>(d.empty() ? 0 : rng() % d.size()),
                     static_cast<std::uint8_t>(rng()));
            break;
          case 3:
            if (d.size() > 16)
              d[12 + rng() % 4] = static_cast<std::uint8_t>(rng());  // payload_length
            break;
        }
      }
      LLVMFuzzerTestOneInput(d.data(), d.size());
      ++runs;
    }
  }
  std::printf("%s: %zu inputs, no crash\n", target.c_str(), runs);
  return 0;
}
