// What the accuracy study writes: CSV in and out, the Markdown tables with their plots and
// readings, and the gnuplot script of the plots (bench/study/report.h).
#include "bench/study/report.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace hapticd::study {

namespace {

std::string fmt(double x, const char* f = "%.3g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

// a time in whole ns
std::string ns(double x) {
  return fmt(x, "%.0f");
}

std::string label(const Summary& r) {
  return r.setting.empty() ? r.method : r.method + " " + r.setting;
}

// parts timed per tick: the scenes and the knob sweeps in the closed loop
bool perTick(const std::string& part) {
  for (const char* prefix : {"scene/", "dynamics/", "shaping/"}) {
    if (part.rfind(prefix, 0) == 0)
      return true;
  }
  const std::string tick = "-tick";  // decomposition/crescent-tick: the concavity in the loop
  return part.size() > tick.size() &&
         part.compare(part.size() - tick.size(), tick.size(), tick) == 0;
}

// The time a row is plotted and compared at: a tick's p99.9 (what must fit the tick's budget; CPU
// time, so preemptions do not count), a query's median (wall time: on a shared machine its mean
// and tail hold other processes' time slices).
double axisTime(const Summary& r) {
  return perTick(r.part) ? r.time_ns.p999 : r.time_ns.p50;
}

const char* axisName(const std::string& part) {
  return perTick(part) ? "p99.9 time per tick" : "median time per query";
}

/// "0.61 µs", "107 µs", "1.2 ms", "85 ns"
std::string duration(double ns) {
  if (ns < 1e3)
    return fmt(ns, "%.0f") + " ns";
  if (ns < 1e6)
    return fmt(ns / 1e3) + " µs";
  return fmt(ns / 1e6) + " ms";
}

// RFC 4180: a field with a comma, a quote or a line break is quoted, its quotes doubled
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos)
    return s;
  std::string out = "\"";
  for (char c : s)
    out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      out.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

// A family is a method with one knob: "voxel-McNeely" with h swept, "hapticd-tick" with the budget
// swept; a setting without '=' ("exact", "δ off") is a family of its own.
struct Family {
  std::string title;                   ///< the legend
  std::vector<const Summary*> points;  ///< in the order the study swept them
  bool swept = false;                  ///< a knob with several values: drawn as a line, labelled
};

std::string knobOf(const std::string& setting) {
  const auto eq = setting.find('=');
  return eq == std::string::npos ? setting : setting.substr(0, eq);
}

std::string valueOf(const std::string& setting) {
  const auto eq = setting.find('=');
  std::string v = eq == std::string::npos ? setting : setting.substr(eq + 1);
  for (const char* drop : {" pairs/tick", " (open loop)"}) {
    const auto at = v.find(drop);
    if (at != std::string::npos)
      v.erase(at, std::string(drop).size());
  }
  return v;
}

std::vector<Family> families(const std::vector<const Summary*>& part) {
  std::vector<Family> out;
  std::map<std::string, std::size_t> index;
  for (const Summary* r : part) {
    const std::string key = r->method + '\x1f' + knobOf(r->setting);
    auto [it, added] = index.emplace(key, out.size());
    if (added) {
      Family f;
      const std::string knob = knobOf(r->setting);
      f.title = r->setting.find('=') != std::string::npos ? r->method + ", " + knob + " swept"
                                                          : label(*r);
      out.push_back(f);
    }
    out[it->second].points.push_back(r);
  }
  for (Family& f : out)
    f.swept = f.points.size() > 1;
  return out;
}

// Nothing both faster and more accurate: sorted by time (the axis's), each point more accurate than
// all faster ones.
std::vector<const Summary*> paretoFront(const std::vector<const Summary*>& part) {
  std::vector<const Summary*> byTime = part;
  std::sort(byTime.begin(), byTime.end(), [](const Summary* a, const Summary* b) {
    return axisTime(*a) != axisTime(*b) ? axisTime(*a) < axisTime(*b)
                                        : a->force_n.p99 < b->force_n.p99;
  });
  // more accurate: the smaller p99 force error, on equal p99 the smaller mean error
  std::vector<const Summary*> front;
  for (const Summary* r : byTime) {
    const Summary* b = front.empty() ? nullptr : front.back();
    if (b == nullptr || r->force_n.p99 < b->force_n.p99 ||
        (r->force_n.p99 == b->force_n.p99 && r->force_n.mean < b->force_n.mean))
      front.push_back(r);
  }
  return front;
}

std::map<std::string, std::vector<const Summary*>> byPart(const std::vector<Summary>& rows,
                                                          std::vector<std::string>& order) {
  std::map<std::string, std::vector<const Summary*>> parts;
  for (const Summary& r : rows) {
    if (!parts.count(r.part))
      order.push_back(r.part);
    parts[r.part].push_back(&r);
  }
  return parts;
}

std::string reading(const std::vector<const Summary*>& part, bool tick) {
  const Summary* best = part.front();
  const Summary* fastest = part.front();
  for (const Summary* r : part) {
    // the smaller p99 force error, then the smaller mean error, then the shorter time
    if (r->force_n.p99 != best->force_n.p99     ? r->force_n.p99 < best->force_n.p99
        : r->force_n.mean != best->force_n.mean ? r->force_n.mean < best->force_n.mean
                                                : axisTime(*r) < axisTime(*best))
      best = r;
    if (axisTime(*r) < axisTime(*fastest))
      fastest = r;
  }
  const char* per = tick ? " p99.9 per tick" : " median per query";
  std::string s = "Most accurate: " + label(*best) + " (p99 force error " + fmt(best->force_n.p99) +
                  " N, mean " + fmt(best->force_n.mean) + " N; " + duration(axisTime(*best)) + per +
                  ")";
  if (fastest != best) {
    s += "; fastest: " + label(*fastest) + " (" + duration(axisTime(*fastest)) + ", p99 " +
         fmt(fastest->force_n.p99) + " N, " + std::to_string(fastest->misses) + " of " +
         std::to_string(fastest->truth_contacts) + " contact " +
         (tick ? "ticks" : "configurations") + " missed)";
  }
  s += ". Nothing is both faster and more accurate than ";
  const auto front = paretoFront(part);
  for (std::size_t i = 0; i < front.size(); ++i)
    s += (i == 0 ? "" : i + 1 == front.size() ? " and " : ", ") + label(*front[i]);
  s += " (the Pareto front, dashed grey in the plot).";
  return s;
}

// --- label placement --------------------------------------------------------------------------

// Pixel geometry of the plot area, fixed by the margins the script sets.
constexpr double kWidthPx = 1100.0, kHeightPx = 660.0;
constexpr double kLeft = 0.08, kRight = 0.63, kBottom = 0.10, kTop = 0.91;
constexpr double kAreaW = (kRight - kLeft) * kWidthPx, kAreaH = (kTop - kBottom) * kHeightPx;
constexpr double kCharW = 6.0, kCharH = 11.0;  // Sans 8 in pngcairo, generous

struct Box {
  double x0, y0, x1, y1;
};

double overlap(const Box& a, const Box& b) {
  const double w = std::min(a.x1, b.x1) - std::max(a.x0, b.x0);
  const double h = std::min(a.y1, b.y1) - std::max(a.y0, b.y0);
  return w > 0 && h > 0 ? w * h : 0.0;
}

struct Placed {
  std::string text;
  double gx, gy;  ///< graph coordinates of the text's left end, vertical middle
};

struct Axes {
  double lx0, lx1, ly0, ly1;  ///< log10 ranges
  double px(double x) const { return (std::log10(x) - lx0) / (lx1 - lx0) * kAreaW; }
  double py(double y) const { return (std::log10(y) - ly0) / (ly1 - ly0) * kAreaH; }
};

// Greedy: each label at the first of a ring of candidate spots around its point that overlaps no
// point and no label placed before it and stays inside the plot; if none is free, the least bad.
// Vertical lines (pixel x) are obstacles too, with their rotated labels at the top.
std::vector<Placed> placeLabels(
    const std::vector<std::pair<std::string, std::array<double, 2>>>& want,
    const std::vector<std::array<double, 2>>& points,
    const std::vector<double>& vertical_px) {
  std::vector<Box> taken;
  taken.reserve(points.size() + 2 * vertical_px.size() + want.size());
  for (const auto& p : points)
    taken.push_back({p[0] - 5, p[1] - 5, p[0] + 5, p[1] + 5});
  for (const double x : vertical_px) {
    taken.push_back({x - 2, 0, x + 2, kAreaH});
    taken.push_back({x - 16, kAreaH - 90, x, kAreaH});  // its name, rotated, left of it
  }
  std::vector<Placed> out;
  for (const auto& [text, p] : want) {
    const double w = kCharW * static_cast<double>(text.size()), h = kCharH;
    const std::array<std::array<double, 2>, 12> spots{{{7, -h / 2},
                                                       {-7 - w, -h / 2},
                                                       {-w / 2, 7},
                                                       {-w / 2, -7 - h},
                                                       {6, 5},
                                                       {6, -5 - h},
                                                       {-6 - w, 5},
                                                       {-6 - w, -5 - h},
                                                       {7, 14},
                                                       {7, -14 - h},
                                                       {-7 - w, 14},
                                                       {-7 - w, -14 - h}}};
    double best_cost = 1e300;
    Box best{};
    for (const auto& s : spots) {
      const Box b{p[0] + s[0], p[1] + s[1], p[0] + s[0] + w, p[1] + s[1] + h};
      double cost = 0.0;
      for (const Box& t : taken)
        cost += overlap(b, t) + (overlap(b, t) > 0 ? 100.0 : 0.0);
      if (b.x0 < 0 || b.y0 < 0 || b.x1 > kAreaW || b.y1 > kAreaH)
        cost += 1e6;
      if (cost < best_cost) {
        best_cost = cost;
        best = b;
      }
      if (cost == 0.0)
        break;
    }
    taken.push_back(best);
    out.push_back({text, best.x0 / kAreaW, (best.y0 + best.y1) / 2 / kAreaH});
  }
  return out;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\')
      out += '\\';
    out += c;
  }
  return out + "\"";
}

void plotPart(std::ostream& gp,
              const std::filesystem::path& dir,
              const std::string& part,
              const std::vector<const Summary*>& rows,
              const PlotOptions& options) {
  const auto time = [](const Summary* r) { return axisTime(*r); };
  // errors of exactly zero (the truth's own row) are drawn on a floor line below the rest
  double min_err = 1e300, max_err = 0.0, min_t = 1e300, max_t = 0.0;
  for (const Summary* r : rows) {
    if (r->force_n.p99 > 0)
      min_err = std::min(min_err, r->force_n.p99);
    max_err = std::max(max_err, r->force_n.p99);
    min_t = std::min(min_t, std::max(time(r), 1.0));
    max_t = std::max(max_t, time(r));
  }
  if (max_err <= 0.0)
    min_err = max_err = 1.0;
  const double floor_err = min_err / 30.0;
  auto y = [&](const Summary* r) { return r->force_n.p99 > 0 ? r->force_n.p99 : floor_err; };
  auto x = [&](const Summary* r) { return std::max(time(r), 1.0); };
  // the budget lines (1 and 4 kHz, the user's) always inside
  const double lo_line = options.budget_ns > 0.0 ? std::min(2.5e5, options.budget_ns) : 2.5e5;
  const double hi_line = std::max(1.0e6, options.budget_ns);
  const Axes ax{std::log10(std::min(min_t, lo_line)) - 0.25,
                std::log10(std::max(max_t, hi_line)) + 0.25, std::log10(floor_err) - 0.5,
                std::log10(max_err) + 0.6};

  const std::array<const char*, 10> colours{"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                                            "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  const std::array<int, 10> markers{7, 5, 9, 11, 13, 4, 6, 8, 10, 12};

  gp << "reset\nset terminal pngcairo size " << kWidthPx << ',' << kHeightPx
     << " font 'Sans,10'\nset output " << quoted((dir / plotName(part)).string()) << "\n"
     << "set lmargin at screen " << kLeft << "\nset rmargin at screen " << kRight
     << "\nset bmargin at screen " << kBottom << "\nset tmargin at screen " << kTop << "\n"
     << "set logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\n"
     << "set format x '10^{%L}'\nset format y '10^{%L}'\n"
     << "set xrange [" << std::pow(10.0, ax.lx0) << ':' << std::pow(10.0, ax.lx1) << "]\n"
     << "set yrange [" << std::pow(10.0, ax.ly0) << ':' << std::pow(10.0, ax.ly1) << "]\n"
     << "set xlabel '" << axisName(part) << " (ns)'\n"
     << "set ylabel 'p99 force error (N)'\n"
     << "set title " << quoted("What accuracy costs in time: " + part) << " noenhanced\n"
     << "set key at screen " << kRight + 0.02 << ", screen " << kTop
     << " left top Left reverse font 'Sans,9' spacing 1.2\n";
  // the budget of one tick at 1 and 4 kHz, and the floor of the exact answers
  std::vector<std::pair<double, std::string>> lines{{1.0e6, "1 kHz tick"}, {2.5e5, "4 kHz tick"}};
  if (options.budget_ns > 0.0 && options.budget_ns != 1.0e6 && options.budget_ns != 2.5e5)
    lines.emplace_back(options.budget_ns, "budget " + fmt(options.budget_ns / 1e3) + " µs");
  std::vector<double> vertical_px;
  for (const auto& [ns, name] : lines) {
    gp << "set arrow from " << ns << ", graph 0 to " << ns
       << ", graph 1 nohead dt 3 lw 1.5 lc rgb '#b00000' back\n"
       << "set label " << quoted(name) << " at " << ns << ", graph 0.97 right rotate by 90 "
       << "offset -1.3,0 font 'Sans,8' tc rgb '#b00000'\n";
    vertical_px.push_back(ax.px(ns));
  }
  if (min_err / 30.0 == floor_err &&
      std::any_of(rows.begin(), rows.end(), [](const Summary* r) { return r->force_n.p99 <= 0; })) {
    gp << "set arrow from graph 0, first " << floor_err << " to graph 1, first " << floor_err
       << " nohead dt 2 lc rgb '#999999' back\n"
       << "set label 'no error (exact)' at graph 0.99, first " << floor_err
       << " right offset 0,0.7 font 'Sans,8' tc rgb '#666666'\n";
  }

  const auto fams = families(rows);
  std::vector<std::array<double, 2>> pts;
  std::vector<std::pair<std::string, std::array<double, 2>>> want;
  pts.reserve(rows.size());
  for (const Summary* r : rows)
    pts.push_back({ax.px(x(r)), ax.py(y(r))});
  for (const Family& f : fams) {
    if (!f.swept)
      continue;
    for (const Summary* r : f.points)
      want.push_back({valueOf(r->setting), {ax.px(x(r)), ax.py(y(r))}});
  }
  for (const Placed& l : placeLabels(want, pts, vertical_px))
    gp << "set label " << quoted(l.text) << " at graph " << l.gx << ", graph " << l.gy
       << " left font 'Sans,8' front noenhanced\n";

  // the data as datablocks: one per family, then the Pareto front
  // a gnuplot datablock's name: letters, digits and '_' only
  std::string name = plotName(part);
  name = name.substr(0, name.size() - 4);
  std::replace_if(
      name.begin(), name.end(), [](unsigned char c) { return std::isalnum(c) == 0; }, '_');
  for (std::size_t i = 0; i < fams.size(); ++i) {
    gp << "$" << name << "_" << i << " << EOD\n";
    for (const Summary* r : fams[i].points)
      gp << x(r) << ' ' << y(r) << '\n';
    gp << "EOD\n";
  }
  gp << "$" << name << "_front << EOD\n";
  for (const Summary* r : paretoFront(rows))
    gp << x(r) << ' ' << y(r) << '\n';
  gp << "EOD\n";
  gp << "plot $" << name << "_front using 1:2 with lines dt 2 lw 2 lc rgb '#888888' "
     << "title 'Pareto front'";
  for (std::size_t i = 0; i < fams.size(); ++i) {
    gp << ", \\\n  $" << name << "_" << i << " using 1:2 with "
       << (fams[i].swept ? "linespoints lw 1.5" : "points") << " pt " << markers[i % markers.size()]
       << " ps 1.6 lc rgb '" << colours[i % colours.size()] << "' title " << quoted(fams[i].title)
       << " noenhanced";
  }
  gp << "\n";
}

}  // namespace

std::string plotName(const std::string& part) {
  std::string name = part;
  std::replace(name.begin(), name.end(), '/', '_');
  return name + ".png";
}

Summary summarize(const Row& r) {
  Summary s;
  s.part = r.part;
  s.method = r.method;
  s.setting = r.setting;
  s.configurations = r.time_ns.size();
  s.truth_contacts = r.truth_contacts;
  s.misses = r.misses;
  s.false_contacts = r.false_contacts;
  s.no_answer = r.no_answer;
  s.force_n = stats(r.force_err_n);
  s.torque_nm = stats(r.torque_err_nm);
  s.time_ns = stats(r.time_ns);
  s.drift_m = stats(r.drift_m);
  s.energy_err_j = stats(r.energy_err_j);
  return s;
}

bool writeCsv(const std::filesystem::path& file, const std::vector<Summary>& rows) {
  std::ofstream out(file);
  out << "part,method,setting,configurations,truth_contacts,misses,false_contacts,no_answer,"
         "force_err_mean_n,force_err_p99_n,force_err_max_n,torque_err_mean_nm,torque_err_p99_nm,"
         "torque_err_max_nm,time_mean_ns,time_p99_ns,time_max_ns,time_p50_ns,time_p999_ns,"
         "drift_mean_m,drift_p99_m,drift_max_m,energy_err_mean_j,energy_err_p99_j,"
         "energy_err_max_j\n";
  for (const Summary& r : rows) {
    out << csvField(r.part) << ',' << csvField(r.method) << ',' << csvField(r.setting) << ','
        << r.configurations << ',' << r.truth_contacts << ',' << r.misses << ',' << r.false_contacts
        << ',' << r.no_answer << ',' << r.force_n.mean << ',' << r.force_n.p99 << ','
        << r.force_n.max << ',' << r.torque_nm.mean << ',' << r.torque_nm.p99 << ','
        << r.torque_nm.max << ',' << r.time_ns.mean << ',' << r.time_ns.p99 << ',' << r.time_ns.max
        << ',' << r.time_ns.p50 << ',' << r.time_ns.p999 << ',' << r.drift_m.mean << ','
        << r.drift_m.p99 << ',' << r.drift_m.max << ',' << r.energy_err_j.mean << ','
        << r.energy_err_j.p99 << ',' << r.energy_err_j.max << '\n';
  }
  out.close();
  if (!out) {
    std::fprintf(stderr, "study: cannot write %s\n", file.c_str());
    return false;
  }
  return true;
}

bool readCsv(const std::filesystem::path& file, std::vector<Summary>& rows, std::string& error) {
  std::ifstream in(file);
  if (!in) {
    error = file.string() + ": cannot open";
    return false;
  }
  std::string line;
  std::getline(in, line);
  if (line.rfind("part,method,setting,", 0) != 0) {
    error = file.string() + ":1: not a results.csv of hapticstudy (header '" + line + "')";
    return false;
  }
  std::vector<Summary> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty())
      continue;
    const auto c = splitCsv(line);
    // 19 fields before the dynamics' figures were added (a file of then reads without them)
    if (c.size() != 25 && c.size() != 19) {
      error = file.string() + ":" + std::to_string(n) + ": " + std::to_string(c.size()) +
              " fields, 25 expected";
      return false;
    }
    try {
      Summary s;
      s.part = c[0];
      s.method = c[1];
      s.setting = c[2];
      s.configurations = std::stoull(c[3]);
      s.truth_contacts = std::stoull(c[4]);
      s.misses = std::stoull(c[5]);
      s.false_contacts = std::stoull(c[6]);
      s.no_answer = std::stoull(c[7]);
      s.force_n = {std::stod(c[8]), std::stod(c[9]), std::stod(c[10])};
      s.torque_nm = {std::stod(c[11]), std::stod(c[12]), std::stod(c[13])};
      s.time_ns = {std::stod(c[14]), std::stod(c[15]), std::stod(c[16])};
      s.time_ns.p50 = std::stod(c[17]);
      s.time_ns.p999 = std::stod(c[18]);
      if (c.size() == 25) {
        s.drift_m = {std::stod(c[19]), std::stod(c[20]), std::stod(c[21])};
        s.energy_err_j = {std::stod(c[22]), std::stod(c[23]), std::stod(c[24])};
      }
      out.push_back(s);
    } catch (const std::exception&) {
      error = file.string() + ":" + std::to_string(n) + ": a figure is not a number";
      return false;
    }
  }
  if (out.empty()) {
    error = file.string() + ": no rows";
    return false;
  }
  rows = std::move(out);
  return true;
}

std::string tables(const std::vector<Summary>& rows,
                   const std::string& header,
                   const std::string& plot_dir_rel) {
  std::ostringstream md;
  md << header << "\n";
  std::vector<std::string> order;
  const auto parts = byPart(rows, order);
  for (const std::string& part : order) {
    const auto& list = parts.at(part);
    const bool dynamics = part.rfind("dynamics/", 0) == 0;
    md << "\n### " << part << "\n\n"
       << "![" << part << ": p99 force error against " << axisName(part) << "](" << plot_dir_rel
       << "/" << plotName(part) << ")\n\n"
       << reading(list, perTick(part)) << "\n\n"
       << "| method | force error mean / p99 / max (N) | torque error mean / p99 / max (N·m) | "
          "misses | false contacts | no answer | time mean / p50 / p99 / p99.9 / max (ns) |"
       << (dynamics ? " drift mean / p99 / max (mm) | energy error mean / p99 / max (mJ) |" : "")
       << "\n|---|---|---|---|---|---|---|" << (dynamics ? "---|---|" : "") << "\n";
    for (const Summary* r : list) {
      md << "| " << label(*r) << " | " << fmt(r->force_n.mean) << " / " << fmt(r->force_n.p99)
         << " / " << fmt(r->force_n.max) << " | " << fmt(r->torque_nm.mean) << " / "
         << fmt(r->torque_nm.p99) << " / " << fmt(r->torque_nm.max) << " | " << r->misses << " of "
         << r->truth_contacts << " | " << r->false_contacts << " | " << r->no_answer << " | "
         << ns(r->time_ns.mean) << " / " << ns(r->time_ns.p50) << " / " << ns(r->time_ns.p99)
         << " / " << ns(r->time_ns.p999) << " / " << ns(r->time_ns.max) << " |";
      if (dynamics) {
        md << ' ' << fmt(1e3 * r->drift_m.mean) << " / " << fmt(1e3 * r->drift_m.p99) << " / "
           << fmt(1e3 * r->drift_m.max) << " | " << fmt(1e3 * r->energy_err_j.mean) << " / "
           << fmt(1e3 * r->energy_err_j.p99) << " / " << fmt(1e3 * r->energy_err_j.max) << " |";
      }
      md << "\n";
    }
  }
  return md.str();
}

bool plots(const std::filesystem::path& dir,
           const std::vector<Summary>& rows,
           const PlotOptions& options) {
  std::vector<std::string> order;
  const auto parts = byPart(rows, order);
  {
    std::ofstream gp(dir / "plots.gp");
    gp << "# written by hapticstudy (bench/study/report.cpp): one plot per part of the study\n";
    for (const std::string& part : order)
      plotPart(gp, dir, part, parts.at(part), options);
  }
  const std::string cmd = "gnuplot " + (dir / "plots.gp").string();
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "study: gnuplot failed or is missing: no PNG written (%s)\n", cmd.c_str());
    return false;
  }
  return true;
}

}  // namespace hapticd::study
