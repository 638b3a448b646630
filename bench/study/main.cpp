// hapticstudy: what accuracy costs in time. Runs every part of the study, writes the rows as CSV,
// the tables as Markdown (also into docs/accuracy.md between its study markers), and the plots as
// PNG through gnuplot. scripts/accuracy.sh builds and runs it: one command regenerates everything.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include "bench/study/study.h"

namespace hapticd::study {

Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  const auto n = static_cast<double>(v.size());
  s.p99 = v[std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(0.99 * n)) - 1)];
  s.max = v.back();
  return s;
}

double timerOverheadNs() {
  std::vector<double> d;
  for (int i = 0; i < 10001; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto t1 = std::chrono::steady_clock::now();
    d.push_back(static_cast<double>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()));
  }
  std::nth_element(d.begin(), d.begin() + 5000, d.end());
  return d[5000];
}

namespace {

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown CPU";
}

std::string label(const Row& r) { return r.setting.empty() ? r.method : r.method + " " + r.setting; }

void writeCsv(const std::filesystem::path& file, const std::vector<Row>& rows) {
  std::ofstream out(file);
  out << "part,method,setting,configurations,truth_contacts,misses,false_contacts,no_answer,"
         "force_err_mean_n,force_err_p99_n,force_err_max_n,torque_err_mean_nm,torque_err_p99_nm,"
         "torque_err_max_nm,time_mean_ns,time_p99_ns,time_max_ns\n";
  for (const Row& r : rows) {
    const Stats f = stats(r.force_err_n), t = stats(r.torque_err_nm), ns = stats(r.time_ns);
    out << r.part << ',' << r.method << ',' << r.setting << ',' << r.time_ns.size() << ','
        << r.truth_contacts << ',' << r.misses << ',' << r.false_contacts << ',' << r.no_answer
        << ',' << f.mean << ',' << f.p99 << ',' << f.max << ',' << t.mean << ',' << t.p99 << ','
        << t.max << ',' << ns.mean << ',' << ns.p99 << ',' << ns.max << '\n';
  }
}

std::string fmt(double x, const char* f = "%.3g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string tables(const std::vector<Row>& rows, const std::string& header) {
  std::ostringstream md;
  md << header << "\n\n";
  std::string part;
  for (const Row& r : rows) {
    if (r.part != part) {
      part = r.part;
      md << "\n### " << part << "\n\n"
         << "| method | force error mean / p99 / max (N) | torque error mean / p99 / max (N·m) | "
            "misses | false contacts | no answer | time mean / p99 / max (ns) |\n"
         << "|---|---|---|---|---|---|---|\n";
    }
    const Stats f = stats(r.force_err_n), t = stats(r.torque_err_nm), ns = stats(r.time_ns);
    md << "| " << label(r) << " | " << fmt(f.mean) << " / " << fmt(f.p99) << " / " << fmt(f.max)
       << " | " << fmt(t.mean) << " / " << fmt(t.p99) << " / " << fmt(t.max) << " | " << r.misses
       << " of " << r.truth_contacts << " | " << r.false_contacts << " | " << r.no_answer << " | "
       << fmt(ns.mean, "%.0f") << " / " << fmt(ns.p99, "%.0f") << " / " << fmt(ns.max, "%.0f")
       << " |\n";
  }
  return md.str();
}

// One PNG per part: p99 force error against mean time, one labelled point per method and setting.
void plots(const std::filesystem::path& dir, const std::vector<Row>& rows) {
  std::map<std::string, std::vector<const Row*>> by_part;
  for (const Row& r : rows) by_part[r.part].push_back(&r);
  std::ofstream gp(dir / "plots.gp");
  gp << "set terminal pngcairo size 900,600 font 'Sans,10'\nset logscale xy\nset grid\n"
        "set xlabel 'mean time per query (ns)'\nset ylabel 'p99 force error (N)'\n"
        "set key off\n";
  for (const auto& [part, list] : by_part) {
    std::string name = part;
    std::replace(name.begin(), name.end(), '/', '_');
    std::ofstream dat(dir / (name + ".dat"));
    for (const Row* r : list) {
      // a method without error is drawn at 1e-16 N so that it shows on the log scale
      dat << std::max(stats(r->time_ns).mean, 1.0) << ' '
          << std::max(stats(r->force_err_n).p99, 1e-16) << " \"" << label(*r) << "\"\n";
    }
    gp << "set output '" << (dir / (name + ".png")).string() << "'\n"
       << "set title 'Force error against time: " << part << "'\n"
       << "plot '" << (dir / (name + ".dat")).string()
       << "' using 1:2 with points pt 7 ps 1.5, '' using 1:2:3 with labels rotate by 35 left "
          "offset 0.6,0.6 font 'Sans,8'\n";
  }
  gp.close();
  const std::string cmd = "gnuplot " + (dir / "plots.gp").string();
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "study: gnuplot failed or is missing: no PNG written (%s)\n", cmd.c_str());
  }
}

// Replaces what stands between the study markers of docs/accuracy.md.
void updateDoc(const std::filesystem::path& doc, const std::string& text) {
  std::ifstream in(doc);
  if (!in) return;
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
  app.add_option("--seed", options.seed, "seed of every random configuration")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) {
    std::cerr << "hapticstudy: cannot create " << options.out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  std::vector<Row> rows;
  runPairs(options, rows);
  runScenes(options, rows);

  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  const std::string header = std::string("Measured ") + date + " on " + cpuModel() + " (" +
                             std::to_string(std::thread::hardware_concurrency()) +
                             " threads), compiler " + __VERSION__ +
                             (options.quick ? ", quick run" : "") + "; timer overhead " +
                             fmt(timerOverheadNs(), "%.0f") + " ns subtracted from every time.";
  const std::filesystem::path dir(options.out_dir);
  writeCsv(dir / "results.csv", rows);
  const std::string md = tables(rows, header);
  std::ofstream(dir / "tables.md") << md;
  plots(dir, rows);
  if (!doc.empty()) updateDoc(doc, md);
  std::fprintf(stderr, "study: %zu rows written to %s\n", rows.size(), options.out_dir.c_str());
  return 0;
}
