#include "client/study.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>

#include "bench/study/report.h"
#include "bench/study/scene_study.h"
#include "client/replay_stream.h"

namespace hapticd::client {
namespace {

namespace fs = std::filesystem;
using study::Summary;

std::string fmt(double x, const char* f = "%.3g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

bool writeFile(const fs::path& file, const std::string& text, std::ostream& err) {
  std::ofstream f(file);
  f << text;
  f.close();
  if (!f) {
    err << "hapticctl study: cannot write " << file.string() << "\n";
    return false;
  }
  return true;
}

// Option values a study cannot run with: the message, or empty.
std::string badOption(const StudyOptions& o) {
  if (!std::isfinite(o.rate_hz) || o.rate_hz < 100.0 || o.rate_hz > 20000.0)
    return "--rate must be a number of Hz in [100, 20000] (got " + fmt(o.rate_hz, "%g") + ")";
  if (!std::isfinite(o.budget_us) || o.budget_us < 0.0)
    return "--budget-us must be a finite number of µs > 0 (got " + fmt(o.budget_us, "%g") + ")";
  if (!std::isfinite(o.time_limit_s) || o.time_limit_s < 0.0)
    return "--time-limit must be a finite number of seconds ≥ 0 (got " + fmt(o.time_limit_s, "%g") +
           ")";
  return "";
}

}  // namespace

int runStudy(const StudyOptions& o, std::ostream& out, std::ostream& err) {
  if (const std::string bad = badOption(o); !bad.empty()) {
    err << "hapticctl study: " << bad << "\n";
    return 2;
  }
  for (const std::string& f : {o.scene, o.stream}) {
    std::error_code ec;
    if (!f.empty() && !fs::is_regular_file(f, ec)) {
      err << "hapticctl study: cannot open " << f << ": no such file\n";
      return 2;
    }
  }
  const double budget_ns = (o.budget_us > 0.0 ? o.budget_us : 1e6 / o.rate_hz) * 1e3;

  // the scene, with check's messages
  scene::LoadReport report = scene::loadSceneFile(o.scene, o.load);
  for (const std::string& w : report.warnings)
    err << o.scene << ": warning: " << w << '\n';
  if (!report.ok()) {
    for (const scene::Problem& p : report.problems)
      err << o.scene << ": " << p.where << ": " << p.what << '\n';
    return 1;
  }
  auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));

  // the stream: the user's (read as `hapticctl replay` reads it), or an approach
  std::vector<proto::PoseStreamRow> stream;
  if (!o.stream.empty()) {
    auto text = proto::readPoseStreamFile(o.stream);
    if (!text.ok()) {
      err << "hapticctl study: " << text.error().message << "\n";
      return 1;
    }
    auto parsed = parseReplayStream(text.value(), o.stream);
    if (!parsed.ok()) {
      err << "hapticctl study: " << parsed.error().message << "\n";
      return 1;
    }
    stream = std::move(parsed).value();
  } else {
    stream = study::approachStream(*model, o.quick ? 0.5 : 1.0);
  }

  const fs::path dir = o.out_dir.empty() ? fs::path("study-" + fs::path(o.scene).stem().string())
                                         : fs::path(o.out_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    err << "hapticctl study: cannot create " << dir.string() << ": " << ec.message() << "\n";
    return 1;
  }
  if (o.stream.empty() && !writeFile(dir / "stream.csv", study::poseStreamCsv(stream), err))
    return 1;

  study::SceneStudyOptions so;
  so.rate_hz = o.rate_hz;
  so.max_seconds = o.quick ? 3.0 : 0.0;
  so.load = o.load;
  so.progress = [&err](const std::string& line) { err << "study: " << line << std::endl; };

  // the estimate, before anything long runs: the truth's mean tick over its first ticks, times
  // every run's ticks (each run also rebuilds the simulation; tessellation runs reload the scene)
  const auto runs = study::planRuns(*model);
  const std::size_t ticks = study::ticksOf(stream, so);
  const std::size_t probe_ticks = std::min<std::size_t>(ticks, 300);
  const auto probe = study::probeTickNs(model, stream, so, probe_ticks);
  if (!probe.ok()) {
    err << "hapticctl study: " << o.scene << ": " << probe.error().message << "\n";
    return 1;
  }
  const double estimate_s = 1.5 * static_cast<double>(runs.size()) * static_cast<double>(ticks) *
                            probe.value().first * 1e-9;
  err << "study: " << model->name << ": " << runs.size() << " runs of " << ticks << " ticks ("
      << fmt(static_cast<double>(ticks) / o.rate_hz) << " s of "
      << (o.stream.empty() ? "generated approach stream" : "stream") << " at "
      << fmt(o.rate_hz, "%.4g") << " Hz), about " << fmt(std::max(estimate_s, 0.1), "%.2g") << " s"
      << std::endl;
  if (o.time_limit_s > 0.0 && estimate_s > o.time_limit_s) {
    err << "hapticctl study: this study would take about " << fmt(estimate_s, "%.0f")
        << " s (the most accurate tick takes " << fmt(probe.value().first / 1e3)
        << " µs on average here), more than --time-limit " << fmt(o.time_limit_s, "%g")
        << " s: nothing was run; use --quick (3 s of stream), a shorter stream, or a larger "
           "--time-limit\n";
    return 1;
  }
  if (probe.value().second > budget_ns) {
    err << "study: note: the most accurate settings take " << fmt(probe.value().second / 1e3)
        << " µs per tick at p99.9 over the first " << probe_ticks << " ticks, more than the budget "
        << fmt(budget_ns / 1e3, "%.4g") << " µs: the study looks for cheaper settings" << std::endl;
  }

  std::vector<study::Row> rows;
  const std::string part = "scene/" + fs::path(o.scene).stem().string();
  auto ran = study::runSceneStudy(part, o.scene, model, stream, so, rows);
  if (!ran.ok()) {
    err << "hapticctl study: " << ran.error().message << "\n";
    return 1;
  }

  std::vector<Summary> summaries;
  summaries.reserve(rows.size());
  for (const study::Row& r : rows)
    summaries.push_back(study::summarize(r));
  std::vector<const Summary*> pointers;
  pointers.reserve(summaries.size());
  for (const Summary& s : summaries)
    pointers.push_back(&s);
  const study::Recommendation rec = study::recommend(pointers, budget_ns);

  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  const std::string header =
      std::string("Measured ") + date + " on " + study::machine() + "; " + o.scene + ", " +
      (o.stream.empty() ? std::string("a generated approach stream") : "stream " + o.stream) +
      ", " + fmt(o.rate_hz, "%.4g") + " Hz" + (o.quick ? ", quick run" : "") + ".";
  std::string md = study::tables(summaries, header, ".");
  std::vector<std::string> comment;
  if (rec.row != nullptr) {
    comment.push_back("hapticctl study " + o.scene + ": " +
                      (rec.fits ? "the most accurate settings whose p99.9 tick fits "
                                : "NO setting fits; the fastest, over ") +
                      fmt(budget_ns / 1e3, "%.4g") + " µs at " + fmt(o.rate_hz, "%.4g") +
                      " Hz ([servo] rate_hz)");
    comment.push_back("setting: " + rec.row->setting + "; p99.9 tick " +
                      fmt(rec.row->time_ns.p999 / 1e3, "%.4g") + " µs, p99 force error " +
                      fmt(rec.row->force_n.p99) + " N; " + date + " on " + study::machine());
    md += "\nRecommended for a p99.9 tick budget of " + fmt(budget_ns / 1e3, "%.4g") +
          " µs: " + (rec.fits ? "" : "(none fits; the fastest) ") + rec.row->setting + ".\n";
  }
  bool written = study::writeCsv(dir / "results.csv", summaries) &&
                 writeFile(dir / "measured.txt", header + "\n", err) &&
                 writeFile(dir / "tables.md", md, err);
  study::PlotOptions po;
  po.budget_ns = budget_ns;
  const bool plotted = written && study::plots(dir, summaries, po);
  if (rec.row == nullptr) {
    err << "hapticctl study: no setting of this study can be expressed in the config\n";
    return 1;
  }
  const std::string snippet = study::configSnippet(rec.knobs, comment);
  written = written && writeFile(dir / "recommended.toml", snippet, err);
  err << "study: tables, results.csv, the plot and recommended.toml in " << dir.string()
      << (plotted ? "" : " (no plot: gnuplot failed or is missing)") << std::endl;
  out << snippet;
  if (!rec.fits) {
    err << "hapticctl study: no setting's p99.9 tick fits " << fmt(budget_ns / 1e3, "%.4g")
        << " µs; the fastest is printed (" << fmt(rec.row->time_ns.p999 / 1e3, "%.4g")
        << " µs): lower the rate, simplify the scene, or raise --budget-us\n";
    return 1;
  }
  return written && plotted ? 0 : 1;
}

}  // namespace hapticd::client
