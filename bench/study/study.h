#pragma once
/// \file
/// The accuracy study (docs/accuracy.md): every way of computing contact trades error for time;
/// each method and setting is run on the same configurations as a ground truth, and its force
/// and torque error, its missed and false contacts, and its time are summarised. One row per
/// method and setting.

#include <cstdint>
#include <string>
#include <vector>

namespace hapticd::study {

/// Errors and times of one method and setting, over every configuration of one part of the study.
struct Row {
  std::string part;     ///< "pairs/32" (random convex pairs of 32 points), "scene/peg_in_hole", ...
  std::string method;   ///< "hapticd-exact-warm", "voxel", "FCL-GJK-EPA-libccd", ...
  std::string setting;  ///< "h=0.5mm", "budget=2", "" ...
  std::vector<double> force_err_n;    ///< |F - F_truth| per configuration
  std::vector<double> torque_err_nm;  ///< |T - T_truth| per configuration
  std::vector<double> time_ns;        ///< time per query or per tick
  std::uint64_t misses = 0;           ///< truth in contact, method felt nothing (or had no answer)
  std::uint64_t false_contacts = 0;   ///< truth free, method felt a force
  std::uint64_t no_answer = 0;        ///< the method returned no answer at all
  std::uint64_t truth_contacts = 0;   ///< configurations in contact by the truth
  /// With dynamics (the parts "dynamics/..."), per scored tick: the largest distance between a
  /// dynamic body's position and the truth's at the same tick (m), and the difference of the
  /// dynamic bodies' mechanical energy (kinetic + potential in the scene's gravity) from the
  /// truth's (J, absolute). Empty for the other parts.
  std::vector<double> drift_m;
  std::vector<double> energy_err_j;

  /// Adds one configuration: its errors, its time, whether the truth and the method were in
  /// contact.
  void add(double force_err, double torque_err, double ns, bool truth_contact, bool got_contact) {
    force_err_n.push_back(force_err);
    torque_err_nm.push_back(torque_err);
    time_ns.push_back(ns);
    if (truth_contact)
      ++truth_contacts;
    if (truth_contact && !got_contact)
      ++misses;
    if (!truth_contact && got_contact)
      ++false_contacts;
  }
};

/// mean, p99, max, p50 and p99.9 of a sample (0 for an empty one); a percentile is the sample's
/// value at that rank (nearest rank, no interpolation).
struct Stats {
  double mean = 0.0, p99 = 0.0, max = 0.0;
  double p50 = 0.0, p999 = 0.0;
};
Stats stats(std::vector<double> v);

/// Options of the whole study.
struct Options {
  std::string out_dir = "docs/accuracy";
  bool quick = false;  ///< fewer configurations (CI smoke run)
  std::uint64_t seed = 20261201;
};

/// Random convex pairs: ellipsoid hulls of 8, 32 and 128 points, near contact, on coherent paths.
void runPairs(const Options& options, std::vector<Row>& rows);

/// The demo scenes replayed from their pose streams through the whole tick: scheduler budgets, δ
/// on and off (closed loop), voxel sampling at the truth's proxy poses (open loop).
void runScenes(const Options& options, std::vector<Row>& rows);

/// A non-convex model (a crescent) touched through the convex pieces of its decomposition at
/// several concavities, against the exact distance to its triangle mesh (open loop, a sphere
/// probe along its walls; bench/study/decomp_study.cpp).
void runDecomposition(const Options& options, std::vector<Row>& rows);

/// The same crescent in the closed loop (part decomposition/crescent-tick): the tick with the
/// probe sphere along its concave inner wall, the crescent decomposed at each concavity, against
/// the tick whose pairs are answered from the crescent's own mesh.
void runDecompositionLoop(const Options& options, std::vector<Row>& rows);

/// "AMD EPYC ... (2 threads), compiler 12.2.0": where the figures were measured.
std::string machine();

/// The CPU time of the calling thread, ns (CLOCK_THREAD_CPUTIME_ID): what a tick costs, without
/// the preemptions of a shared machine (the servo thread runs SCHED_FIFO).
double threadNowNs();
/// Nanoseconds of one pair of threadNowNs() readings (the median of many).
double threadClockOverheadNs();

/// Nanoseconds of one steady_clock reading pair (subtracted from every timed call).
double timerOverheadNs();

}  // namespace hapticd::study
