#include "client/state_format.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <sstream>

namespace hapticd::client {
namespace {

// the contacts of `s`, deepest first
std::vector<proto::State::Contact> deepestFirst(const proto::State& s) {
  std::vector<proto::State::Contact> c = s.contacts;
  std::sort(c.begin(), c.end(), [](const auto& a, const auto& b) { return a.depth_m > b.depth_m; });
  return c;
}

std::string formatContacts(const proto::State& s, std::size_t n) {
  const std::vector<proto::State::Contact> c = deepestFirst(s);
  std::string out;
  char buf[160];
  for (std::size_t i = 0; i < std::min(n, c.size()); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.3g m at (%.4g, %.4g, %.4g)", i == 0 ? "" : ", ",
                  c[i].depth_m, c[i].p_W[0], c[i].p_W[1], c[i].p_W[2]);
    out += buf;
  }
  return out;
}

nlohmann::json refusedJson(const proto::StatusReply& s) {
  nlohmann::json refused = nlohmann::json::object();
  for (std::size_t i = 1; i < s.refused.size() && i < proto::kErrcCount; ++i)
    refused[proto::errcName(static_cast<proto::Errc>(i))] = s.refused[i];
  return refused;
}

// force, torque and contacts of one tick, for status
nlohmann::json tickJson(const proto::State& s) {
  const std::vector<proto::State::Contact> c = deepestFirst(s);
  return {{"tick", s.tick},
          {"force_n", s.force_n},
          {"force_norm_n", norm(s.force_n)},
          {"torque_nm", s.torque_nm},
          {"torque_norm_nm", norm(s.torque_nm)},
          {"contacts", s.contact_count},
          {"deepest_m", c.empty() ? 0.0 : c.front().depth_m},
          {"max_penetration_m", s.max_penetration_m}};
}
std::string tickText(const proto::State& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "force %.4g N (%.4g, %.4g, %.4g), torque %.4g N m, contacts %u, max penetration "
                "%.3g m (tick %" PRIu64 ")",
                norm(s.force_n), s.force_n[0], s.force_n[1], s.force_n[2], norm(s.torque_nm),
                s.contact_count, s.max_penetration_m, s.tick);
  return buf;
}

}  // namespace

std::string faultText(std::uint32_t bits) {
  if (bits == 0)
    return "none";
  std::string s;
  auto add = [&](std::uint32_t bit, const char* name) {
    if ((bits & bit) != 0)
      s += (s.empty() ? "" : ",") + std::string(name);
  };
  add(proto::kFaultStreamLost, "stream_lost");
  add(proto::kFaultDevice, "device");
  add(proto::kFaultForceClamped, "force_clamped");
  add(proto::kFaultNotFinite, "not_finite");
  add(proto::kFaultTickOverrun, "tick_overrun");
  return s;
}

double norm(const proto::WireVec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

nlohmann::json stateJson(const proto::State& s, std::size_t deepest, bool bodies) {
  const std::vector<proto::State::Contact> c = deepestFirst(s);
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < std::min(deepest, c.size()); ++i)
    list.push_back({{"p", c[i].p_W}, {"n", c[i].n_W}, {"depth_m", c[i].depth_m}});
  nlohmann::json j = {{"tick", s.tick},
                      {"t_s", static_cast<double>(s.sim_time_ns) * 1e-9},
                      {"tick_ns",
                       {{"p50", s.tick_p50_ns},
                        {"p99", s.tick_p99_ns},
                        {"max", s.tick_max_ns},
                        {"this", s.tick_ns}}},
                      {"tick_misses", s.tick_misses},
                      {"pairs_tested", s.pairs_tested},
                      {"pairs_skipped", s.pairs_skipped},
                      {"device", {{"p", s.X_WD.p}, {"q", s.X_WD.q}}},
                      {"proxy", {{"p", s.X_WP.p}, {"q", s.X_WP.q}}},
                      {"force_n", s.force_n},
                      {"force_norm_n", norm(s.force_n)},
                      {"torque_nm", s.torque_nm},
                      {"torque_norm_nm", norm(s.torque_nm)},
                      {"force_scale", s.force_scale},
                      {"contacts", s.contact_count},
                      {"max_penetration_m", s.max_penetration_m},
                      {"deepest", list},
                      {"faults", faultText(s.fault_bits)},
                      {"fault_bits", s.fault_bits},
                      {"armed", (s.state_flags & proto::kStateArmed) != 0},
                      {"state_flags", s.state_flags},
                      {"last_command_sequence", s.last_command_sequence}};
  if (bodies) {
    nlohmann::json poses = nlohmann::json::array();
    for (const auto& b : s.bodies)
      poses.push_back({{"body", b.body_index}, {"p", b.X_WB.p}, {"q", b.X_WB.q}});
    j["bodies"] = poses;
    j["bodies_truncated"] = (s.state_flags & proto::kStateBodiesTruncated) != 0;
  }
  return j;
}

// the refusal counters by name (index 0, "ok", is not a refusal)
std::string stateLine(const proto::State& s, std::size_t deepest, bool bodies) {
  // the 1.0 line as it was, then what minor 1 and the contact list add
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "tick %" PRIu64
                " t %.3f s | tick p50 %.1f us p99 %.1f us max %.1f us | force "
                "%.4g N torque %.4g N m scale %.2f | contacts %u | faults %s%s",
                s.tick, static_cast<double>(s.sim_time_ns) * 1e-9, s.tick_p50_ns / 1e3,
                s.tick_p99_ns / 1e3, s.tick_max_ns / 1e3, norm(s.force_n), norm(s.torque_nm),
                s.force_scale, s.contact_count, faultText(s.fault_bits).c_str(),
                (s.state_flags & proto::kStateArmed) != 0 ? " | armed" : " | disarmed");
  std::string line = buf;
  std::snprintf(buf, sizeof buf, " | this tick %.1f us, pairs %u tested %u skipped, max pen %.3g m",
                s.tick_ns / 1e3, s.pairs_tested, s.pairs_skipped, s.max_penetration_m);
  line += buf;
  const std::string contacts = formatContacts(s, deepest);
  if (!contacts.empty())
    line += " | deepest " + contacts;
  if (bodies) {
    std::snprintf(buf, sizeof buf, " | bodies %zu%s", s.bodies.size(),
                  (s.state_flags & proto::kStateBodiesTruncated) != 0 ? "+" : "");
    line += buf;
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      const auto& p = s.bodies[i].X_WB.p;
      std::snprintf(buf, sizeof buf, "%s %u at (%.4g, %.4g, %.4g)", i == 0 ? ":" : ",",
                    s.bodies[i].body_index, p[0], p[1], p[2]);
      line += buf;
    }
  }
  return line;
}

const char* recordHeader() {
  return "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
         "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
         "pairs_skipped,tick_ns";
}

const char* bodiesHeader() {
  return "tick,t,body,px,py,pz,qx,qy,qz,qw";
}

bool writeRecordRow(std::FILE* f, const proto::State& s) {
  const auto& d = s.X_WD;
  const auto& p = s.X_WP;
  return std::fprintf(
             f,
             "%" PRIu64
             ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
             "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%.17g,%u,%u,%u\n",
             s.tick - 1, static_cast<double>(s.sim_time_ns) * 1e-9, d.p[0], d.p[1], d.p[2], d.q[0],
             d.q[1], d.q[2], d.q[3], p.p[0], p.p[1], p.p[2], p.q[0], p.q[1], p.q[2], p.q[3],
             s.force_n[0], s.force_n[1], s.force_n[2], s.torque_nm[0], s.torque_nm[1],
             s.torque_nm[2], s.contact_count, s.max_penetration_m, s.pairs_tested, s.pairs_skipped,
             s.tick_ns) >= 0;
}

bool writeBodyRows(std::FILE* f, const proto::State& s, const std::vector<std::string>& names) {
  bool ok = true;
  for (const auto& b : s.bodies) {
    const std::string name = b.body_index < names.size() && !names[b.body_index].empty()
                                 ? names[b.body_index]
                                 : "body" + std::to_string(b.body_index);
    const auto& x = b.X_WB;
    ok = std::fprintf(f, "%" PRIu64 ",%.17g,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                      s.tick - 1, static_cast<double>(s.sim_time_ns) * 1e-9, name.c_str(), x.p[0],
                      x.p[1], x.p[2], x.q[0], x.q[1], x.q[2], x.q[3]) >= 0 &&
         ok;
  }
  return ok;
}

nlohmann::json statusJson(const proto::StatusReply& s,
                          const std::string& daemon,
                          const std::optional<proto::State>& state) {
  const std::uint32_t shm = s.shm_flags;
  return {{"daemon", daemon},
          {"device", s.device},
          {"scene", s.scene},
          {"loading", s.loading},
          {"plan", s.plan},
          {"uptime_s", static_cast<double>(s.uptime_ns) * 1e-9},
          {"ticks", s.ticks},
          {"tick_misses", s.tick_misses},
          {"tick_rate_hz", s.tick_rate_hz},
          {"measured_tick_hz", s.measured_tick_hz},
          {"tick_ns", {{"p50", s.tick_p50_ns}, {"p99", s.tick_p99_ns}, {"max", s.tick_max_ns}}},
          {"faults", faultText(s.fault_bits)},
          {"fault_bits", s.fault_bits},
          {"armed", (s.state_flags & proto::kStateArmed) != 0},
          {"state_flags", s.state_flags},
          {"sessions", s.sessions},
          {"subscribers", s.subscribers},
          {"state_rate_hz", s.state_rate_hz},
          {"packets_received", s.packets_received},
          {"packets_sent", s.packets_sent},
          {"commands_accepted", s.commands_accepted},
          {"commands_dropped", s.commands_dropped},
          {"refused", refusedJson(s)},
          {"shm",
           {{"name", s.shm_name},
            {"serving", (shm & proto::kShmServing) != 0},
            {"client_attached", (shm & proto::kShmClientAttached) != 0},
            {"client_alive", (shm & proto::kShmClientAlive) != 0},
            {"commands", s.shm_commands},
            {"commands_refused", s.shm_commands_refused}}},
          {"edits",
           {{"batches_applied", s.edit_batches_applied},
            {"batches_dropped", s.edit_batches_dropped},
            {"entries_applied", s.edits_applied},
            {"entries_refused", s.edits_refused}}},
          {"state", state ? tickJson(*state) : nlohmann::json(nullptr)}};
}

std::string statusText(const proto::StatusReply& s,
                       const std::string& daemon,
                       const std::optional<proto::State>& state) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "daemon %s\ndevice %s\nscene %s\nticks %" PRIu64
                " (%.1f Hz measured, %.1f Hz configured), misses %" PRIu64
                "\ntick compute p50 %.1f us, p99 %.1f us, max %.1f us\nfaults %s, %s\nsessions %u, "
                "subscribers %u (%u states/s)\npackets received %" PRIu64 ", sent %" PRIu64
                "\ncommands accepted %" PRIu64 ", dropped %" PRIu64 "\n",
                daemon.c_str(), s.device.c_str(), s.scene.c_str(), s.ticks, s.measured_tick_hz,
                s.tick_rate_hz, s.tick_misses, s.tick_p50_ns / 1e3, s.tick_p99_ns / 1e3,
                s.tick_max_ns / 1e3, faultText(s.fault_bits).c_str(),
                (s.state_flags & proto::kStateArmed) != 0 ? "armed" : "disarmed", s.sessions,
                s.subscribers, s.state_rate_hz, s.packets_received, s.packets_sent,
                s.commands_accepted, s.commands_dropped);
  std::ostringstream out;
  out << buf;
  // a scene being built (protocol 1.2): the running scene stays until it is ready
  if (!s.loading.empty())
    out << "loading " << s.loading << " (scene " << s.scene << " runs until it is ready)\n";
  out << (state ? tickText(*state) : std::string("force and contacts: no state came"))
      << "\nrefused";
  bool any = false;
  const nlohmann::json refused = refusedJson(s);
  for (auto& [name, n] : refused.items()) {
    if (n.get<std::uint64_t>() == 0)
      continue;
    out << " " << name << "=" << n.get<std::uint64_t>();
    any = true;
  }
  out << (any ? "" : " none") << "\n";
  if ((s.shm_flags & proto::kShmServing) != 0)
    out << "shm " << s.shm_name << ", client "
        << ((s.shm_flags & proto::kShmClientAlive) != 0      ? "alive"
            : (s.shm_flags & proto::kShmClientAttached) != 0 ? "attached, not beating"
                                                             : "none")
        << ", commands " << s.shm_commands << ", refused " << s.shm_commands_refused << "\n";
  else
    out << "shm off\n";
  out << "scene updates applied " << s.edit_batches_applied << " (entries " << s.edits_applied
      << ", refused at the tick " << s.edits_refused << "), dropped " << s.edit_batches_dropped
      << "\nplan:\n"
      << s.plan << (s.plan.empty() || s.plan.back() == '\n' ? "" : "\n");
  return out.str();
}

}  // namespace hapticd::client
