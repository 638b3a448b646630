// hapticctl: the command-line client of hapticd. Today: the offline `query` command; the commands
// that talk to a running daemon arrive with the protocol (issue 8).
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include "client/query.h"

int main(int argc, char** argv) {
  CLI::App app{"hapticctl: the command-line client of the hapticd haptic server"};
  app.require_subcommand(1);
  std::string file;
  auto* query = app.add_subcommand(
      "query", "Answer convex pair queries offline: one JSON object per line in FILE (- for stdin), "
               "one result per line out (docs/query.md)");
  query->add_option("FILE", file, "JSON-lines file of queries, or - for standard input")->required();
  CLI11_PARSE(app, argc, argv);

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
