// hapticstudy: what accuracy costs in time. Runs every part of the study, writes the rows as CSV,
// the tables as Markdown (also into docs/accuracy.md between its study markers), and the plots as
// PNG through gnuplot. scripts/accuracy.sh builds and runs it: one command regenerates everything.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench/study/report.h"
#include "bench/study/study.h"

namespace hapticd::study {

namespace {

std::string fmt(double x, const char* f = "%.3g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  while (!s.empty() && s.back() == '\n')
    s.pop_back();
  return s;
}

// Replaces what stands between the study markers of docs/accuracy.md.
void updateDoc(const std::filesystem::path& doc, const std::string& text) {
  std::ifstream in(doc);
  if (!in)
    return;
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  const std::string begin = "<!-- study:begin -->", end = "<!-- study:end -->";
  const auto b = s.find(begin), e = s.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    std::fprintf(stderr, "study: %s has no study markers: left alone\n", doc.c_str());
    return;
  }
  s = s.substr(0, b + begin.size()) + "\n" + text + "\n" + s.substr(e);
  std::ofstream(doc) << s;
}

}  // namespace
}  // namespace hapticd::study

int main(int argc, char** argv) {
  using namespace hapticd::study;
  Options options;
  std::string doc = "docs/accuracy.md";
  CLI::App app{"hapticstudy: what accuracy costs in time (docs/accuracy.md)"};
  app.add_option("--out", options.out_dir, "folder for results.csv, tables.md and the plots")
      ->capture_default_str();
  app.add_option("--doc", doc, "document whose study section is rewritten ('' : none)")
      ->capture_default_str();
  app.add_flag("--quick", options.quick, "fewer configurations (a smoke run)");
  bool from_csv = false;
  app.add_flag("--from-csv", from_csv,
               "measure nothing: redraw the plots and tables from OUT/results.csv and "
               "OUT/measured.txt");
  app.add_option("--seed", options.seed, "seed of every random configuration")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) {
    std::cerr << "hapticstudy: cannot create " << options.out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  const std::filesystem::path dir(options.out_dir);
  std::vector<Summary> summaries;
  std::string header;
  if (from_csv) {
    // redraw from what a run measured: its results.csv and the line saying where and when
    std::string error;
    if (!readCsv(dir / "results.csv", summaries, error)) {
      std::cerr << "hapticstudy: --from-csv: " << error << "\n";
      return 1;
    }
    header = slurp(dir / "measured.txt");
    if (header.empty()) {
      std::cerr << "hapticstudy: --from-csv: " << (dir / "measured.txt").string()
                << " is missing or empty (it says where and when the figures were measured)\n";
      return 1;
    }
  } else {
    std::vector<Row> rows;
    runPairs(options, rows);
    runScenes(options, rows);
    runDecomposition(options, rows);
    runDecompositionLoop(options, rows);
    for (const Row& r : rows)
      summaries.push_back(summarize(r));
    const std::time_t now = std::time(nullptr);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
    header = std::string("Measured ") + date + " on " + machine() +
             (options.quick ? ", quick run" : "") + "; timer overhead " +
             fmt(timerOverheadNs(), "%.0f") + " ns subtracted from every time.";
    if (!writeCsv(dir / "results.csv", summaries))
      return 1;
    std::ofstream(dir / "measured.txt") << header << "\n";
  }
  // the plots are linked from the document, relative to its folder
  std::string plot_rel = options.out_dir;
  if (!doc.empty()) {
    std::error_code rel_ec;
    const auto rel =
        std::filesystem::relative(dir, std::filesystem::absolute(doc).parent_path(), rel_ec);
    if (!rel_ec && !rel.empty())
      plot_rel = rel.generic_string();
  }
  const std::string md = tables(summaries, header, plot_rel);
  std::ofstream(dir / "tables.md") << md;
  const bool plotted = plots(dir, summaries);
  if (!doc.empty())
    updateDoc(doc, md);
  std::fprintf(stderr, "study: %zu rows written to %s%s\n", summaries.size(),
               options.out_dir.c_str(), plotted ? "" : " (no plots)");
  return plotted ? 0 : 1;
}
