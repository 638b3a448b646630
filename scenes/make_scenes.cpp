// make_scenes: writes the demo scenes (scenes/<name>.glb) and their pose streams
// (tests/streams/<name>.csv), or with --check compares the files there with what the generator
// makes now. Exit 0: written / identical; 1: a file differs or is missing (--check), or a write
// failed.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "scenes/demo_scenes.h"
#include "scenes/pose_streams.h"

namespace {

namespace fs = std::filesystem;

bool sameContents(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return false;
  const std::vector<std::uint8_t> have((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
  return have == bytes;
}

bool writeFile(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();
  return static_cast<bool>(out);
}

}  // namespace

namespace {
int run(int argc, char** argv) {
  CLI::App app{"Writes hapticd's demo scenes (.glb) and their pose streams (.csv)"};
  std::string scenes_dir = HAPTICD_SOURCE_DIR "/scenes";
  std::string streams_dir = HAPTICD_SOURCE_DIR "/tests/streams";
  bool check = false;
  app.add_option("--scenes-dir", scenes_dir, "folder for <name>.glb")->capture_default_str();
  app.add_option("--streams-dir", streams_dir, "folder for <name>.csv")->capture_default_str();
  app.add_flag("--check", check, "compare the files with the generator's output, write nothing");
  CLI11_PARSE(app, argc, argv);

  int status = 0;
  for (std::string_view name : hapticd::scenes::demoSceneNames()) {
    const std::vector<std::uint8_t> glb = hapticd::scenes::makeDemoScene(name);
    const std::string csv = hapticd::scenes::makePoseStream(name);
    const std::vector<std::uint8_t> csv_bytes(csv.begin(), csv.end());
    const fs::path glb_path = fs::path(scenes_dir) / (std::string(name) + ".glb");
    const fs::path csv_path = fs::path(streams_dir) / (std::string(name) + ".csv");
    for (const auto& [path, bytes] : {std::pair{glb_path, glb}, std::pair{csv_path, csv_bytes}}) {
      if (check) {
        if (!sameContents(path, bytes)) {
          std::fprintf(stderr, "make_scenes: %s differs from the generator's output\n",
                       path.c_str());
          status = 1;
        }
      } else if (!writeFile(path, bytes)) {
        std::fprintf(stderr, "make_scenes: cannot write %s\n", path.c_str());
        status = 1;
      } else {
        std::printf("%s: %zu bytes\n", path.c_str(), bytes.size());
      }
    }
  }
  return status;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // a bug: every expected failure is reported where it happens
    std::fprintf(stderr, "make_scenes: unexpected error: %s\n", e.what());
    return 1;
  }
}
