#pragma once
/// \file
/// What the accuracy study writes from its rows: the CSV, the Markdown tables with a plot and a
/// short reading per part, and the plots themselves (gnuplot). Everything here works from the
/// summaries alone, so `hapticstudy --from-csv` redraws plots and tables from a results.csv without
/// measuring again.

#include <filesystem>
#include <string>
#include <vector>

#include "bench/study/study.h"

namespace hapticd::study {

/// The figures of one row as the CSV holds them.
struct Summary {
  std::string part, method, setting;
  std::uint64_t configurations = 0, truth_contacts = 0, misses = 0, false_contacts = 0,
                no_answer = 0;
  Stats force_n, torque_nm, time_ns;
  /// With dynamics (Row::drift_m, Row::energy_err_j): mean, p99 and max; all zero otherwise.
  Stats drift_m, energy_err_j;
};

Summary summarize(const Row& row);

/// Writes every summary as one CSV line (header first). Throws nothing; a failed write is reported
/// on stderr and returns false.
bool writeCsv(const std::filesystem::path& file, const std::vector<Summary>& rows);

/// Reads what writeCsv wrote. Returns false with `error` set (file and line) on anything else.
bool readCsv(const std::filesystem::path& file, std::vector<Summary>& rows, std::string& error);

/// The Markdown of the results: `header` (machine, date), then per part its plot (a link relative
/// to the document, `plot_dir_rel`), two sentences read from the figures, and its table.
std::string tables(const std::vector<Summary>& rows,
                   const std::string& header,
                   const std::string& plot_dir_rel);

/// One PNG per part in `dir` through gnuplot (`dir`/plots.gp): p99 force error against time (a
/// tick's p99.9, a query's median) on
/// log axes, one colour and marker per method family, a swept setting as a line through its values
/// (labelled, placed so that labels do not overlap), the Pareto front, and the budget of one tick
/// at 1 kHz and 4 kHz as vertical lines (labels kept off them). Returns false when gnuplot is
/// missing or fails.
struct PlotOptions {
  /// One more vertical line: a budget (ns) of the user's, 0 for none.
  double budget_ns = 0.0;
};
bool plots(const std::filesystem::path& dir,
           const std::vector<Summary>& rows,
           const PlotOptions& options = {});

/// The file name of a part's plot: "pairs/32" -> "pairs_32.png".
std::string plotName(const std::string& part);

}  // namespace hapticd::study
