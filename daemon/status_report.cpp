#include "daemon/status_report.h"

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace hapticd::daemon {
namespace {

nlohmann::json percentiles(const DurationHistogram& h) {
  return {{"p50", h.quantileNs(0.5)},
          {"p99", h.quantileNs(0.99)},
          {"p999", h.quantileNs(0.999)},
          {"max", h.maxNs()}};
}

}  // namespace

nlohmann::json statusJson(const ServoState& st,
                          const DurationHistogram& lateness,
                          const DurationHistogram& compute,
                          const StatusFacts& facts) {
  const Config& config = *facts.config;
  nlohmann::json j;
  j["phase"] = facts.phase;
  j["tick"] = st.tick;
  j["t_s"] = st.t_s;
  j["period_index"] = st.period_index;
  j["rate_hz"] = config.servo.rate_hz;
  j["clock"] = toString(config.servo.clock);
  j["device"] = {{"name", facts.device},
                 {"connected", st.device_connected},
                 {"lost_count", st.device_lost_count}};
  j["scene"] = {{"name", facts.scene},
                {"generation", st.scene_generation},
                {"offered_generation", facts.offered_generation}};
  j["armed"] = st.armed;
  j["stopping"] = st.stopping;
  j["running"] = st.running;
  // bits: the protocol's numbering (State::fault_bits); names: the latched ones
  j["faults"] = {{"bits", st.faults},
                 {"names", faultNames(st.faults)},
                 {"misses", (st.faults & kFaultMisses) != 0},
                 {"non_finite", (st.faults & kFaultNonFinite) != 0},
                 {"stream_lost", (st.faults & kFaultStreamLost) != 0},
                 {"latched_since_start", st.fault_latches},
                 {"seen", faultNames(st.faults_seen)}};
  j["overruns"] = st.overruns;
  j["skipped_periods"] = st.skipped_periods;
  j["consecutive_misses"] = st.consecutive_misses;
  j["force_n"] = {st.force_W_n.x, st.force_W_n.y, st.force_W_n.z};
  j["torque_nm"] = {st.torque_W_nm.x, st.torque_W_nm.y, st.torque_W_nm.z};
  j["contacts"] = st.contacts;
  j["max_penetration_m"] = st.max_penetration_m;
  j["pairs_tested"] = st.pairs_tested;
  j["pairs_skipped"] = st.pairs_skipped;
  j["last_tick_ns"] = st.last_tick_ns;
  j["peak_force_n"] = st.peak_force_n;
  j["output_gain"] = st.output_gain;
  j["last_command_sequence"] = st.last_command_sequence;
  j["records_dropped"] = st.records_dropped;
  j["lateness_ns"] = percentiles(lateness);
  j["compute_ns"] = percentiles(compute);
  j["realtime"] = {{"policy", toString(config.servo.realtime)},
                   {"memory_locked", facts.memory_locked},
                   {"fifo", facts.servo_realtime.fifo},
                   {"pinned", facts.servo_realtime.pinned},
                   {"servo_scheduling", facts.servo_scheduling}};
  j["last_reload"] = facts.last_reload;
  j["edits"] = {{"batches_applied", st.edit_batches_applied},
                {"batches_dropped", st.edit_batches_dropped},
                {"entries_applied", st.edits_applied},
                {"entries_refused", st.edits_refused},
                {"pending", facts.edits_pending}};
  return j;
}

void writeJsonFile(const std::string& path, const nlohmann::json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << j.dump(2) << "\n";
    if (!out)
      return;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
}

std::string statusLine(const ServoState& st,
                       const DurationHistogram& lateness,
                       const DurationHistogram& compute) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "status: tick %" PRIu64 ", faults %s, overruns %" PRIu64
                ", device %s, force %.3f N",
                st.tick, faultNames(st.faults).c_str(), st.overruns,
                st.device_connected ? "connected" : "LOST", glm::length(st.force_W_n));
  return std::string(buf) + "; lateness " + lateness.summary() + "; compute " + compute.summary();
}

std::string summaryLine(ServoExit exit,
                        const ServoState& st,
                        const DurationHistogram& compute,
                        const Config& config,
                        const std::string& scene,
                        std::uint64_t records_written) {
  const char* why = exit == ServoExit::kEndOfStream ? "end of stream"
                    : exit == ServoExit::kMaxTicks  ? "tick limit"
                                                    : "stopped";
  // faults: the ones latched now, and how often any was latched over the run (a re-arm clears
  // them, so "none" alone would hide a run's faults)
  std::string faults = faultNames(st.faults);
  if (st.fault_latches > 0)
    faults += " (latched " + std::to_string(st.fault_latches) +
              " times since start: " + faultNames(st.faults_seen) + ")";
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "hapticd: %s: %" PRIu64
                " ticks, %.3f s %s time, scene '%s', peak force %.6g N, "
                "peak penetration %.6g m, contact ticks %" PRIu64 ", overruns %" PRIu64
                ", faults %s, records %" PRIu64 " (dropped %" PRIu64
                "), tick p50 %.1f us p99 %.1f us max %.1f us",
                why, st.tick, st.tick > 0 ? st.t_s + 1.0 / config.servo.rate_hz : 0.0,
                config.servo.clock == ClockKind::kVirtual ? "simulated" : "loop", scene.c_str(),
                st.peak_force_n, st.peak_penetration_m, st.contact_ticks, st.overruns,
                faults.c_str(), records_written, st.records_dropped,
                static_cast<double>(compute.quantileNs(0.5)) / 1e3,
                static_cast<double>(compute.quantileNs(0.99)) / 1e3,
                static_cast<double>(compute.maxNs()) / 1e3);
  return buf;
}

}  // namespace hapticd::daemon
