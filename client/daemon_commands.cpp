#include "client/daemon_commands.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

#include "protocol/client.h"
#include "protocol/command_gate.h"

namespace hapticd::client {
namespace {

using Clock = std::chrono::steady_clock;

std::string address(const DaemonTarget& t) {
  const bool v6 = t.host.find(':') != std::string::npos;
  return (v6 ? "[" + t.host + "]" : t.host) + ":" + std::to_string(t.port);
}

// Connects, or says why not on `err` (exit code 1).
std::unique_ptr<proto::Client> connect(const DaemonTarget& t, std::ostream& err) {
  proto::ClientConfig c;
  c.server = address(t);
  c.timeout_ms = t.timeout_ms;
  if (!t.key_file.empty()) {
    std::ifstream in(t.key_file);
    if (!in) {
      err << "hapticctl: --key-file " << t.key_file << ": cannot read\n";
      return nullptr;
    }
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string why;
    auto key = proto::parseKeyHex(text, &why);
    if (!key) {
      err << "hapticctl: --key-file " << t.key_file << ": " << why << "\n";
      return nullptr;
    }
    c.key = *key;
  }
  auto client = proto::Client::connect(c);
  if (!client) {
    err << "hapticctl: no daemon at " << c.server << " (" << client.error().message << ")\n";
    return nullptr;
  }
  return std::move(client.value());
}

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

double norm(const proto::Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

proto::PoseCommand poseCommand(double px,
                               double py,
                               double pz,
                               double qx,
                               double qy,
                               double qz,
                               double qw,
                               std::uint32_t buttons) {
  proto::PoseCommand c;
  const double n = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  c.X_WT.p = {px, py, pz};
  c.X_WT.q = {qx / n, qy / n, qz / n, qw / n};
  c.buttons = buttons;
  return c;
}

bool finite(std::initializer_list<double> v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// Streams `cmd` for `seconds` at `rate_hz` (at least once), keeping the newest state.
void streamPose(proto::Client& c,
                const proto::PoseCommand& cmd,
                double seconds,
                double rate_hz,
                std::optional<proto::State>& last) {
  const auto period = std::chrono::duration<double>(1.0 / std::max(rate_hz, 1.0));
  const auto end = Clock::now() + std::chrono::duration<double>(std::max(seconds, 0.0));
  do {
    (void)c.sendPose(cmd);
    const auto next = Clock::now() + std::chrono::duration_cast<Clock::duration>(period);
    while (Clock::now() < next) {
      const int ms = static_cast<int>(
          std::chrono::duration_cast<std::chrono::milliseconds>(next - Clock::now()).count());
      if (auto s = c.receiveState(std::max(ms, 0)))
        last = std::move(*s);
      else if (ms <= 0)
        break;
    }
  } while (Clock::now() < end);
}

}  // namespace

const char* recordHeader() {
  return "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
         "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
         "pairs_skipped,tick_ns";
}

int runStatus(const DaemonTarget& t, const StatusOptions& o, std::ostream& out, std::ostream& err) {
  auto c = connect(t, err);
  if (!c)
    return 1;
  auto r = c->status();
  c->bye();
  if (!r) {
    err << "hapticctl status: " << r.error().message << "\n";
    return 1;
  }
  const proto::StatusReply& s = r.value();
  nlohmann::json refused = nlohmann::json::object();
  for (std::size_t i = 1; i < s.refused.size() && i < proto::kErrcCount; ++i)
    refused[proto::errcName(static_cast<proto::Errc>(i))] = s.refused[i];
  if (o.json) {
    nlohmann::json j;
    j["daemon"] = address(t);
    j["device"] = s.device;
    j["scene"] = s.scene;
    j["plan"] = s.plan;
    j["uptime_s"] = static_cast<double>(s.uptime_ns) * 1e-9;
    j["ticks"] = s.ticks;
    j["tick_misses"] = s.tick_misses;
    j["tick_rate_hz"] = s.tick_rate_hz;
    j["measured_tick_hz"] = s.measured_tick_hz;
    j["tick_ns"] = {{"p50", s.tick_p50_ns}, {"p99", s.tick_p99_ns}, {"max", s.tick_max_ns}};
    j["faults"] = faultText(s.fault_bits);
    j["fault_bits"] = s.fault_bits;
    j["armed"] = (s.state_flags & proto::kStateArmed) != 0;
    j["state_flags"] = s.state_flags;
    j["sessions"] = s.sessions;
    j["subscribers"] = s.subscribers;
    j["state_rate_hz"] = s.state_rate_hz;
    j["packets_received"] = s.packets_received;
    j["packets_sent"] = s.packets_sent;
    j["commands_accepted"] = s.commands_accepted;
    j["commands_dropped"] = s.commands_dropped;
    j["refused"] = refused;
    out << j.dump(2) << "\n";
    return 0;
  }
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "daemon %s\ndevice %s\nscene %s\nticks %" PRIu64
                " (%.1f Hz measured, %.1f Hz "
                "configured), misses %" PRIu64
                "\ntick compute p50 %.1f us, p99 %.1f us, max "
                "%.1f us\nfaults %s, %s\nsessions %u, subscribers %u (%u states/s)\npackets "
                "received %" PRIu64 ", sent %" PRIu64 "\ncommands accepted %" PRIu64
                ", dropped %" PRIu64 "\n",
                address(t).c_str(), s.device.c_str(), s.scene.c_str(), s.ticks, s.measured_tick_hz,
                s.tick_rate_hz, s.tick_misses, s.tick_p50_ns / 1e3, s.tick_p99_ns / 1e3,
                s.tick_max_ns / 1e3, faultText(s.fault_bits).c_str(),
                (s.state_flags & proto::kStateArmed) != 0 ? "armed" : "disarmed", s.sessions,
                s.subscribers, s.state_rate_hz, s.packets_received, s.packets_sent,
                s.commands_accepted, s.commands_dropped);
  out << buf << "refused";
  bool any = false;
  for (auto& [name, n] : refused.items()) {
    if (n.get<std::uint64_t>() == 0)
      continue;
    out << " " << name << "=" << n.get<std::uint64_t>();
    any = true;
  }
  out << (any ? "" : " none") << "\nplan:\n"
      << s.plan << (s.plan.empty() || s.plan.back() == '\n' ? "" : "\n");
  return 0;
}

int runLoad(const DaemonTarget& t, const std::string& file, std::ostream& out, std::ostream& err) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    err << "hapticctl load: cannot open " << file << "\n";
    return 2;
  }
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  auto c = connect(t, err);
  if (!c)
    return 1;
  std::string name =
      file.substr(file.find_last_of('/') == std::string::npos ? 0 : file.find_last_of('/') + 1);
  if (name.size() > proto::kMaxSceneNameBytes)
    name.resize(proto::kMaxSceneNameBytes);
  auto r = c->load(bytes, name);
  c->bye();
  if (!r) {
    err << "hapticctl load: " << file << " refused: " << r.error().message << "\n";
    return 1;
  }
  out << "loaded " << name << " (" << bytes.size() << " bytes)\n";
  return 0;
}

int runArm(const DaemonTarget& t, bool arm, std::ostream& out, std::ostream& err) {
  auto c = connect(t, err);
  if (!c)
    return 1;
  auto r = arm ? c->arm() : c->disarm();
  c->bye();
  if (!r) {
    err << "hapticctl " << (arm ? "arm" : "disarm") << ": " << r.error().message << "\n";
    return 1;
  }
  out << (arm ? "armed\n" : "disarmed\n");
  return 0;
}

int runPose(const DaemonTarget& t, const PoseOptions& o, std::ostream& out, std::ostream& err) {
  if (!finite({o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw}) ||
      o.qx * o.qx + o.qy * o.qy + o.qz * o.qz + o.qw * o.qw < 1e-12) {
    err << "hapticctl pose: the position must be finite and the quaternion finite and nonzero\n";
    return 2;
  }
  auto c = connect(t, err);
  if (!c)
    return 1;
  if (o.arm) {
    if (auto a = c->arm(); !a) {
      err << "hapticctl pose: arm: " << a.error().message << "\n";
      return 1;
    }
  }
  if (auto s = c->subscribe(static_cast<std::uint32_t>(std::clamp(o.rate_hz, 1.0, 1000.0))); !s) {
    err << "hapticctl pose: subscribe: " << s.error().message << "\n";
    return 1;
  }
  std::optional<proto::State> last;
  streamPose(*c, poseCommand(o.px, o.py, o.pz, o.qx, o.qy, o.qz, o.qw, 0), o.seconds, o.rate_hz,
             last);
  c->bye();
  if (!last) {
    err << "hapticctl pose: sent, but no state came back\n";
    return 1;
  }
  char buf[256];
  std::snprintf(buf, sizeof buf, "device at %.6g %.6g %.6g, force %.4g N, command %" PRIu64 "\n",
                last->X_WD.p[0], last->X_WD.p[1], last->X_WD.p[2], norm(last->force_n),
                last->last_command_sequence);
  out << buf;
  return 0;
}

int runReplay(const DaemonTarget& t, const ReplayOptions& o, std::ostream& out, std::ostream& err) {
  std::ifstream in(o.file);
  if (!in) {
    err << "hapticctl replay: cannot open " << o.file << "\n";
    return 2;
  }
  struct Row {
    double t;
    proto::PoseCommand cmd;
  };
  std::vector<Row> rows;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.rfind("t,", 0) == 0)
      continue;
    double v[8];
    unsigned buttons = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%u", &v[0], &v[1], &v[2], &v[3],
                    &v[4], &v[5], &v[6], &v[7], &buttons) < 8 ||
        !finite({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]}) ||
        v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7] < 1e-12 ||
        (!rows.empty() && v[0] < rows.back().t)) {
      err << "hapticctl replay: " << o.file << ":" << line_no
          << ": expected t,px,py,pz,qx,qy,qz,qw[,buttons] with t not decreasing\n";
      return 2;
    }
    rows.push_back({v[0], poseCommand(v[1], v[2], v[3], v[4], v[5], v[6], v[7], buttons)});
  }
  if (rows.empty()) {
    err << "hapticctl replay: " << o.file << ": no rows\n";
    return 2;
  }
  auto c = connect(t, err);
  if (!c)
    return 1;
  if (o.arm) {
    if (auto a = c->arm(); !a) {
      err << "hapticctl replay: arm: " << a.error().message << "\n";
      return 1;
    }
  }
  const auto start = Clock::now();
  std::size_t sent = 0;
  if (o.rate_hz > 0.0) {
    // resampled: at each send time the newest row at or before it
    const double period = 1.0 / o.rate_hz;
    std::size_t i = 0;
    for (double ts = rows.front().t; ts <= rows.back().t + 1e-12; ts += period) {
      while (i + 1 < rows.size() && rows[i + 1].t <= ts)
        ++i;
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(ts - rows.front().t)));
      (void)c->sendPose(rows[i].cmd);
      c->pump();
      ++sent;
    }
  } else {
    for (const Row& r : rows) {
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(r.t - rows.front().t)));
      (void)c->sendPose(r.cmd);
      c->pump();
      ++sent;
    }
  }
  c->bye();
  out << "replayed " << sent << " pose commands from " << o.file << "\n";
  return 0;
}

int runRecord(const DaemonTarget& t, const RecordOptions& o, std::ostream& out, std::ostream& err) {
  std::FILE* f = std::fopen(o.file.c_str(), "w");
  if (f == nullptr) {
    err << "hapticctl record: cannot create " << o.file << "\n";
    return 2;
  }
  auto c = connect(t, err);
  if (!c) {
    std::fclose(f);
    return 1;
  }
  if (auto s = c->subscribe(std::clamp<std::uint32_t>(o.rate_hz, 1, 1000)); !s) {
    err << "hapticctl record: subscribe: " << s.error().message << "\n";
    std::fclose(f);
    return 1;
  }
  std::fprintf(f, "%s\n", recordHeader());
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(std::max(o.seconds, 0.0)));
  std::uint64_t rows = 0;
  std::uint64_t last_tick = 0;
  while (Clock::now() < end) {
    const int ms = static_cast<int>(
        std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count());
    auto s = c->receiveState(std::max(ms, 1));
    if (!s)
      continue;
    if (rows > 0 && s->tick <= last_tick)
      continue;  // a late or duplicated datagram
    last_tick = s->tick;
    const auto& d = s->X_WD;
    const auto& p = s->X_WP;
    double max_pen = 0.0;
    for (const auto& ct : s->contacts)
      max_pen = std::max(max_pen, ct.depth_m);
    // the stream carries no per-tick pair counts nor compute time: those columns stay empty
    std::fprintf(f,
                 "%" PRIu64
                 ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                 "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%.17g,,,\n",
                 s->tick - 1, static_cast<double>(s->sim_time_ns) * 1e-9, d.p[0], d.p[1], d.p[2],
                 d.q[0], d.q[1], d.q[2], d.q[3], p.p[0], p.p[1], p.p[2], p.q[0], p.q[1], p.q[2],
                 p.q[3], s->force_n[0], s->force_n[1], s->force_n[2], s->torque_nm[0],
                 s->torque_nm[1], s->torque_nm[2], s->contact_count, max_pen);
    ++rows;
  }
  c->bye();
  const bool ok = std::fclose(f) == 0;
  if (!ok) {
    err << "hapticctl record: writing " << o.file << " failed\n";
    return 2;
  }
  if (rows == 0) {
    err << "hapticctl record: no state came from the daemon\n";
    return 1;
  }
  out << "recorded " << rows << " rows to " << o.file << "\n";
  return 0;
}

int runWatch(const DaemonTarget& t, const WatchOptions& o, std::ostream& out, std::ostream& err) {
  auto c = connect(t, err);
  if (!c)
    return 1;
  if (auto s = c->subscribe(std::clamp<std::uint32_t>(o.rate_hz, 1, 1000)); !s) {
    err << "hapticctl watch: subscribe: " << s.error().message << "\n";
    return 1;
  }
  std::uint64_t lines = 0;
  int silent_ms = 0;
  while (o.count == 0 || lines < o.count) {
    auto s = c->receiveState(200);
    if (!s) {
      silent_ms += 200;
      if (silent_ms >= std::max(t.timeout_ms, 1000)) {
        err << "hapticctl watch: no state from the daemon at " << address(t) << " for " << silent_ms
            << " ms\n";
        return 1;
      }
      continue;
    }
    silent_ms = 0;
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "tick %" PRIu64
                  " t %.3f s | tick p50 %.1f us p99 %.1f us max %.1f us | force "
                  "%.4g N torque %.4g N m scale %.2f | contacts %u | faults %s%s\n",
                  s->tick, static_cast<double>(s->sim_time_ns) * 1e-9, s->tick_p50_ns / 1e3,
                  s->tick_p99_ns / 1e3, s->tick_max_ns / 1e3, norm(s->force_n), norm(s->torque_nm),
                  s->force_scale, s->contact_count, faultText(s->fault_bits).c_str(),
                  (s->state_flags & proto::kStateArmed) != 0 ? " | armed" : " | disarmed");
    out << buf << std::flush;
    ++lines;
  }
  c->bye();
  return 0;
}

}  // namespace hapticd::client
