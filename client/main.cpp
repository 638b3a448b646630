// hapticctl: the command-line client of hapticd. Today: the offline `query` command; the commands
// that talk to a running daemon arrive with the protocol (issue 8).
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include "client/check.h"
#include "client/query.h"

int main(int argc, char** argv) {
  CLI::App app{"hapticctl: the command-line client of the hapticd haptic server"};
  app.require_subcommand(1);
  std::string file;
  auto* query = app.add_subcommand(
      "query", "Answer convex pair queries offline: one JSON object per line in FILE (- for stdin), "
               "one result per line out (docs/query.md)");
  query->add_option("FILE", file, "JSON-lines file of queries, or - for standard input")->required();
  auto* check = app.add_subcommand(
      "check", "Validate a scene offline (.glb or .gltf): list its bodies, primitives and "
               "simulation plan, or every problem (exit 1); docs/scenes.md");
  std::string scene_file;
  hapticd::client::CheckOptions check_options;
  std::string allowed_dir;
  check->add_option("FILE", scene_file, "scene file (.glb or .gltf)")->required();
  check->add_flag("--json", check_options.json, "print a machine-readable JSON report");
  check->add_option("--allowed-uri-dir", allowed_dir,
                    "folder external URIs may be read from (default: none, external URIs refused)");
  check->add_option("--tessellation-tolerance", check_options.load.limits.tessellation_tolerance,
                    "curved shapes' tessellation tolerance, a fraction of their size (default 1e-3)");
  CLI11_PARSE(app, argc, argv);

  if (check->parsed()) {
    if (!allowed_dir.empty()) check_options.load.allowed_uri_dir = allowed_dir;
    return hapticd::client::runCheck(scene_file, check_options, std::cout, std::cerr);
  }

  if (query->parsed()) {
    if (file == "-") return hapticd::client::runQuery(std::cin, std::cout);
    std::ifstream in(file);
    if (!in) {
      std::cerr << "hapticctl query: cannot open " << file << ": " << std::strerror(errno) << '\n';
      return 1;
    }
    return hapticd::client::runQuery(in, std::cout);
  }
  return 0;
}
