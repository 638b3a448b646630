// The study's sample statistics and the timer's own cost (bench/study/study.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <string>
#include <thread>

#include "bench/study/study.h"

namespace hapticd::study {

Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty())
    return s;
  std::sort(v.begin(), v.end());
  double sum = 0.0;
  for (double x : v)
    sum += x;
  const auto n = static_cast<double>(v.size());
  s.mean = sum / n;
  const auto at = [&](double q) {
    const auto rank = static_cast<std::size_t>(std::ceil(q * n));
    return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
  };
  s.p50 = at(0.5);
  s.p99 = at(0.99);
  s.p999 = at(0.999);
  s.max = v.back();
  return s;
}

double timerOverheadNs() {
  std::vector<double> d;
  for (int i = 0; i < 10001; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto t1 = std::chrono::steady_clock::now();
    d.push_back(
        static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()));
  }
  std::nth_element(d.begin(), d.begin() + 5000, d.end());
  return d[5000];
}

// A tick's time is the CPU time of the thread that runs it: on a shared machine a preemption by
// another process (a scheduler quantum, milliseconds) would otherwise be the p99.9, while the
// servo thread runs SCHED_FIFO and is not preempted so. Cache and memory effects still count.
double threadNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

// The cost of one pair of readings, subtracted from every tick (the median of many).
double threadClockOverheadNs() {
  std::vector<double> d;
  for (int i = 0; i < 2001; ++i) {
    const double t0 = threadNowNs();
    d.push_back(threadNowNs() - t0);
  }
  std::nth_element(d.begin(), d.begin() + 1000, d.end());
  return d[1000];
}

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, cpu = "unknown CPU";
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  return cpu + " (" + std::to_string(std::thread::hardware_concurrency()) + " threads), compiler " +
         __VERSION__;
}

}  // namespace hapticd::study
