#include "daemon/web/web_json.h"

#include <cmath>
#include <cstdio>

namespace hapticd::web {
namespace {

using json = nlohmann::ordered_json;

template <std::size_t N>
json arrayOf(const std::array<double, N>& v) {
  json a = json::array();
  for (double x : v)
    a.push_back(x);
  return a;
}

json poseJson(const proto::WirePose& X) {
  return {{"p", arrayOf(X.p)}, {"q", arrayOf(X.q)}};
}

json faultList(std::uint32_t bits, const FaultNames& names) {
  json list = json::array();
  if (bits == 0 || !names)
    return list;
  const std::string text = names(bits);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string name =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!name.empty() && name != "none")
      list.push_back(name);
    if (comma == std::string::npos)
      break;
    start = comma + 1;
  }
  return list;
}

// `message[key]` as N finite numbers into `out`; false with *error naming the key
template <std::size_t N>
bool numbersOf(const json& message,
               const char* key,
               std::array<double, N>& out,
               std::string* error) {
  const auto it = message.find(key);
  if (it == message.end() || !it->is_array() || it->size() != N) {
    *error = std::string(key) + " must be an array of " + std::to_string(N) + " numbers";
    return false;
  }
  for (std::size_t i = 0; i < N; ++i) {
    const json& v = (*it)[i];
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      *error = std::string(key) + "[" + std::to_string(i) + "] is not a finite number";
      return false;
    }
    out[i] = v.get<double>();
  }
  return true;
}

// The members a state and a status share, appended to `j` in this order: the servo's recent
// compute times and misses, the faults and the armed and streaming flags (proto::State and
// proto::StatusReply name them alike).
template <class Message>
void appendServoHealth(json& j, const Message& m, const FaultNames& names) {
  j["tick_p50_ns"] = m.tick_p50_ns;
  j["tick_p99_ns"] = m.tick_p99_ns;
  j["tick_max_ns"] = m.tick_max_ns;
  j["tick_misses"] = m.tick_misses;
  j["faults"] = faultList(m.fault_bits, names);
  j["armed"] = (m.state_flags & proto::kStateArmed) != 0;
  j["streaming"] = (m.state_flags & proto::kStateStreaming) != 0;
}

}  // namespace

json stateJson(const proto::State& s, const FaultNames& names) {
  json contacts = json::array();
  for (const auto& c : s.contacts)
    contacts.push_back({{"p", arrayOf(c.p_W)}, {"n", arrayOf(c.n_W)}, {"depth", c.depth_m}});
  json bodies = json::array();
  for (const auto& b : s.bodies)
    bodies.push_back({{"body", b.body_index}, {"p", arrayOf(b.X_WB.p)}, {"q", arrayOf(b.X_WB.q)}});
  json j = {{"type", "state"},
            {"tick", s.tick},
            {"t", static_cast<double>(s.sim_time_ns) * 1e-9},
            {"device", poseJson(s.X_WD)},
            {"proxy", poseJson(s.X_WP)},
            {"force", arrayOf(s.force_n)},
            {"torque", arrayOf(s.torque_nm)},
            {"force_scale", s.force_scale},
            {"contact_count", s.contact_count},
            {"contacts", std::move(contacts)},
            {"bodies", std::move(bodies)},
            {"max_penetration", s.max_penetration_m},
            {"pairs_tested", s.pairs_tested},
            {"pairs_skipped", s.pairs_skipped},
            {"tick_ns", s.tick_ns}};
  appendServoHealth(j, s, names);
  j["ramping"] = (s.state_flags & proto::kStateRamping) != 0;
  j["last_sequence"] = s.last_command_sequence;
  return j;
}

json statusJson(const proto::StatusReply& r, const FaultNames& names) {
  json j = {{"type", "status"},
            {"device", r.device},
            {"scene", r.scene},
            {"plan", r.plan},
            {"uptime_s", static_cast<double>(r.uptime_ns) * 1e-9},
            {"ticks", r.ticks},
            {"tick_rate_hz", r.tick_rate_hz},
            {"measured_tick_hz", r.measured_tick_hz}};
  appendServoHealth(j, r, names);
  j.update(json{{"commands_accepted", r.commands_accepted},
                {"commands_dropped", r.commands_dropped},
                {"edit_batches_applied", r.edit_batches_applied},
                {"edit_batches_dropped", r.edit_batches_dropped},
                {"edits_applied", r.edits_applied},
                {"edits_refused", r.edits_refused},
                {"shm", r.shm_name},
                {"loading", r.loading}});  // appended in this order (ordered_json)
  return j;
}

std::optional<proto::WirePose> poseOf(const json& message, std::string* error) {
  proto::WirePose X;
  if (!numbersOf(message, "p", X.p, error) || !numbersOf(message, "q", X.q, error))
    return std::nullopt;
  double n2 = 0.0;
  for (double v : X.q)
    n2 += v * v;
  if (std::fabs(std::sqrt(n2) - 1.0) > proto::kQuatNormTolerance) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "q has length %.6g, not 1 (x, y, z, w)", std::sqrt(n2));
    *error = buf;
    return std::nullopt;
  }
  return X;
}

std::optional<proto::WireVec3> vec3Of(const json& message, const char* key, std::string* error) {
  proto::WireVec3 v{0.0, 0.0, 0.0};
  if (!message.contains(key))
    return v;
  if (!numbersOf(message, key, v, error))
    return std::nullopt;
  return v;
}

std::optional<std::uint32_t> bodyOf(const json& message, std::string* error) {
  const auto it = message.find("body");
  if (it == message.end() || !it->is_number_integer() || it->get<std::int64_t>() < 0 ||
      it->get<std::int64_t>() > 0xffffffffLL) {
    *error = "body must be a body index (an integer >= 0; \"scene\" lists them)";
    return std::nullopt;
  }
  return static_cast<std::uint32_t>(it->get<std::int64_t>());
}

}  // namespace hapticd::web
