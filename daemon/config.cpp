#include "daemon/config.h"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

namespace hapticd::daemon {
namespace {

std::string fmtNum(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// Reads one [section] of the file; every problem becomes one line of `errors`.
class Section {
 public:
  Section(const toml::table* table,
          std::string section,
          const std::string& name,
          std::vector<std::string>& errors,
          std::vector<std::string>& keys_set,
          std::vector<std::string>* all_keys)
      : t_(table),
        section_(std::move(section)),
        name_(name),
        errors_(errors),
        keys_set_(keys_set),
        all_keys_(all_keys) {}

  ~Section() {
    if (t_ == nullptr)
      return;
    for (auto&& [k, v] : *t_) {
      if (known_.count(std::string(k.str())) == 0)
        error(v, std::string(k.str()), "unknown key (see config/hapticd.toml for every key)");
    }
  }

  void number(const char* key, double& out, double lo, double hi, const char* unit = "") {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    std::optional<double> v;
    if (auto f = n->value_exact<double>())
      v = *f;
    else if (auto i = n->value_exact<std::int64_t>())
      v = static_cast<double>(*i);
    if (!v)
      return error(*n, key, "must be a number");
    if (!std::isfinite(*v) || *v < lo || *v > hi)
      return error(*n, key,
                   "must be in [" + fmtNum(lo) + ", " + fmtNum(hi) + "]" + unit + " (got " +
                       fmtNum(*v) + ")");
    out = *v;
  }
  void positive(const char* key, double& out, double hi, const char* unit = "") {
    if (t_ == nullptr || t_->get(key) == nullptr) {
      find(key);
      return;
    }
    const std::size_t before = errors_.size();
    double v = out;
    number(key, v, 0.0, hi, unit);
    if (errors_.size() != before)
      return;
    if (v <= 0.0)
      return error(*t_->get(key), key, "must be > 0 (got " + fmtNum(v) + ")");
    out = v;
  }
  template <class Int>
  void integer(const char* key, Int& out, std::int64_t lo, std::int64_t hi) {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    auto i = n->value_exact<std::int64_t>();
    if (!i)
      return error(*n, key, "must be an integer");
    if (*i < lo || *i > hi)
      return error(*n, key,
                   "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " +
                       std::to_string(*i) + ")");
    out = static_cast<Int>(*i);
  }
  void boolean(const char* key, bool& out) {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    auto b = n->value_exact<bool>();
    if (!b)
      return error(*n, key, "must be true or false");
    out = *b;
  }
  void string(const char* key,
              std::string& out,
              const std::function<std::optional<std::string>(const std::string&)>& check = {}) {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    auto s = n->value_exact<std::string>();
    if (!s)
      return error(*n, key, "must be a string");
    if (check) {
      if (auto problem = check(*s))
        return error(*n, key, *problem);
    }
    out = *s;
  }
  template <class E>
  void choice(const char* key, E& out, Result<E> (*parse)(std::string_view)) {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    auto s = n->value_exact<std::string>();
    if (!s)
      return error(*n, key, "must be a string");
    auto r = parse(*s);
    if (!r)
      return error(*n, key, r.error().message);
    out = r.value();
  }
  template <std::size_t N>
  void vector(const char* key, std::array<double, N>& out, double bound) {
    const toml::node* n = find(key);
    if (n == nullptr)
      return;
    const toml::array* a = n->as_array();
    if (a == nullptr || a->size() != N)
      return error(*n, key, "must be an array of " + std::to_string(N) + " numbers");
    std::array<double, N> v{};
    for (std::size_t i = 0; i < N; ++i) {
      const toml::node& e = *a->get(i);
      if (auto f = e.value_exact<double>())
        v[i] = *f;
      else if (auto j = e.value_exact<std::int64_t>())
        v[i] = static_cast<double>(*j);
      else
        return error(*n, key, "element " + std::to_string(i) + " must be a number");
      if (!std::isfinite(v[i]) || std::abs(v[i]) > bound)
        return error(*n, key,
                     "element " + std::to_string(i) + " must be finite and within ±" +
                         fmtNum(bound) + " (got " + fmtNum(v[i]) + ")");
    }
    out = v;
  }
  void quaternion(const char* key, std::array<double, 4>& out) {
    const toml::node* n = t_ != nullptr ? t_->get(key) : nullptr;
    std::array<double, 4> q = out;
    const std::size_t before = errors_.size();
    vector(key, q, 1.0 + 1e-9);
    if (n == nullptr || errors_.size() != before)
      return;
    const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (std::abs(len - 1.0) > 1e-6)
      return error(*n, key, "must be a unit quaternion [x, y, z, w] (length " + fmtNum(len) + ")");
    out = q;
  }

 private:
  const toml::node* find(const char* key) {
    known_.insert(key);
    if (all_keys_ != nullptr)
      all_keys_->push_back(section_ + "." + key);
    if (t_ == nullptr)
      return nullptr;
    const toml::node* n = t_->get(key);
    if (n != nullptr)
      keys_set_.push_back(section_ + "." + key);
    return n;
  }
  void error(const toml::node& n, const std::string& key, const std::string& what) {
    errors_.push_back(name_ + ":" + std::to_string(n.source().begin.line) + ": [" + section_ +
                      "] " + key + ": " + what);
  }

  const toml::table* t_;
  std::string section_;
  const std::string& name_;
  std::vector<std::string>& errors_;
  std::vector<std::string>& keys_set_;
  std::vector<std::string>* all_keys_;
  std::set<std::string> known_;
};

const toml::table* sectionOf(const toml::table& root,
                             const char* name,
                             const std::string& file,
                             std::vector<std::string>& errors) {
  const toml::node* n = root.get(name);
  if (n == nullptr)
    return nullptr;
  if (!n->is_table()) {
    errors.push_back(file + ":" + std::to_string(n->source().begin.line) + ": " + name +
                     ": must be a table ([" + name + "])");
    return nullptr;
  }
  return n->as_table();
}

std::optional<std::string> checkUdp(const std::string& s) {
  const auto colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0)
    return "must be \"ADDRESS:PORT\" (got \"" + s + "\")";
  const std::string port = s.substr(colon + 1);
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535)
    return "port must be 0..65535, 0 for any free port (got \"" + port + "\")";
  return std::nullopt;
}

// "" (off) or "/name" (POSIX shm_open: one leading slash, no other, at most NAME_MAX)
std::optional<std::string> checkShmName(const std::string& s) {
  if (s.empty())
    return std::nullopt;
  if (s.size() < 2 || s[0] != '/' || s.find('/', 1) != std::string::npos || s.size() > 255)
    return "must be empty (no shared memory) or \"/NAME\" with no other '/' (got \"" + s + "\")";
  return std::nullopt;
}

std::optional<std::string> checkSpec(const std::string& s) {
  if (s.empty())
    return "must not be empty (\"sim\", \"replay:FILE\", \"hid\", \"usb\")";
  return std::nullopt;
}

void readAll(const toml::table& root,
             const std::string& name,
             Config& c,
             std::vector<std::string>& errors,
             std::vector<std::string>& keys,
             std::vector<std::string>* all_keys = nullptr) {
  static const std::set<std::string> kSections = {"servo", "device",  "response",
                                                  "scene", "network", "log"};
  for (auto&& [k, v] : root)
    if (kSections.count(std::string(k.str())) == 0)
      errors.push_back(name + ":" + std::to_string(v.source().begin.line) + ": " +
                       std::string(k.str()) +
                       ": unknown section or key (sections: servo, device, response, scene, "
                       "network, log)");
  {
    Section s(sectionOf(root, "servo", name, errors), "servo", name, errors, keys, all_keys);
    s.number("rate_hz", c.servo.rate_hz, 1.0, 20000.0, " Hz");
    s.choice("realtime", c.servo.realtime, &parseRealtimePolicy);
    s.integer("priority", c.servo.priority, 1, 99);
    s.integer("cpu", c.servo.cpu, -1, 1023);
    s.integer("miss_fault_count", c.servo.miss_fault_count, 1, 1000000);
    s.number("fault_fade_s", c.servo.fault_fade_s, 0.0, 10.0, " s");
    s.number("stop_ramp_s", c.servo.stop_ramp_s, 0.0, 10.0, " s");
    s.boolean("armed_at_start", c.servo.armed_at_start);
    s.choice("clock", c.servo.clock, &parseClockKind);
    s.integer("stack_prefault_kib", c.servo.stack_prefault_kib, 0, 8192);
    s.integer("record_ring_rows", c.servo.record_ring_rows, 64, 1 << 24);
  }
  {
    Section s(sectionOf(root, "device", name, errors), "device", name, errors, keys, all_keys);
    auto& d = c.device;
    s.string("spec", d.spec, &checkSpec);
    s.positive("max_force_n", d.max_force_n, 1000.0, " N");
    s.positive("max_torque_nm", d.max_torque_nm, 100.0, " N m");
    s.positive("max_force_step_n", d.max_force_step_n, 1000.0, " N");
    s.positive("max_torque_step_nm", d.max_torque_step_nm, 100.0, " N m");
    s.positive("sim_hand_mass_kg", d.sim_hand_mass_kg, 1000.0, " kg");
    s.positive("sim_hand_stiffness_n_per_m", d.sim_hand_stiffness_n_per_m, 1e7, " N/m");
    s.number("sim_hand_damping_n_s_per_m", d.sim_hand_damping_n_s_per_m, 0.0, 1e6, " N s/m");
    s.number("sim_idle_motion_after_s", d.sim_idle_motion_after_s, 0.0, 1e6, " s");
    s.boolean("sim_home_from_scene", d.sim_home_from_scene);
    s.vector("sim_home_translation_m", d.sim_home_translation_m, 1e9);
    s.quaternion("sim_home_rotation", d.sim_home_rotation);
    s.vector("workspace_translation_m", d.workspace_translation_m, 1e9);
    s.quaternion("workspace_rotation", d.workspace_rotation);
    s.positive("workspace_scale", d.workspace_scale, 1e9);
    s.positive("service_interval_s", d.service_interval_s, 10.0, " s");
    s.positive("sim_hand_inertia_kg_m2", d.sim_hand_inertia_kg_m2, 1000.0, " kg m^2");
    s.positive("sim_hand_rot_stiffness_nm_per_rad", d.sim_hand_rot_stiffness_nm_per_rad, 1e6,
               " N m/rad");
    s.number("sim_hand_rot_damping_nm_s_per_rad", d.sim_hand_rot_damping_nm_s_per_rad, 0.0, 1e6,
             " N m s/rad");
    s.number("sim_idle_amplitude_m", d.sim_idle_amplitude_m, 0.0, 1e6, " m");
    s.number("sim_idle_angle_rad", d.sim_idle_angle_rad, 0.0, 3.14159, " rad");
    s.positive("sim_max_step_s", d.sim_max_step_s, 1.0, " s");
    s.positive("replay_quat_tolerance", d.replay_quat_tolerance, 0.5);
    s.positive("hid_spacemouse_speed_m_per_s", d.hid_spacemouse_speed_m_per_s, 1e3, " m/s");
    s.positive("hid_spacemouse_angular_speed_rad_per_s", d.hid_spacemouse_angular_speed_rad_per_s,
               1e3, " rad/s");
    s.positive("hid_spacemouse_full_scale", d.hid_spacemouse_full_scale, 32767.0);
    s.number("hid_spacemouse_deadband", d.hid_spacemouse_deadband, 0.0, 32767.0);
    s.positive("hid_spacemouse_workspace_m", d.hid_spacemouse_workspace_m, 1e6, " m");
    s.positive("usb_silence_lost_s", d.usb_silence_lost_s, 60.0, " s");
    s.integer("usb_falcon_max_motor_command", d.usb_falcon_max_motor_command, 1, 32767);
    s.string("usb_falcon_firmware", d.usb_falcon_firmware);
  }
  {
    Section s(sectionOf(root, "response", name, errors), "response", name, errors, keys, all_keys);
    auto& r = c.response;
    s.positive("stiffness_n_per_m", r.stiffness_n_per_m, 1e9, " N/m");
    s.number("tick_s", r.tick_s, 0.0, 1.0, " s");
    s.positive("max_force_n", r.max_force_n, 1000.0, " N");
    s.positive("max_torque_nm", r.max_torque_nm, 100.0, " N m");
    s.positive("max_force_step_n", r.max_force_step_n, 1000.0, " N");
    s.positive("max_torque_step_nm", r.max_torque_step_nm, 100.0, " N m");
    s.number("ramp_s", r.ramp_s, 0.0, 60.0, " s");
    s.integer("max_pairs_per_tick", r.max_pairs_per_tick, 0, 100000000);
    s.positive("probe_sphere_radius_m", r.probe_sphere_radius_m, 1e6, " m");
    s.positive("max_speed_m_per_s", r.max_speed_m_per_s, 1e6, " m/s");
    s.positive("speed_decay_s", r.speed_decay_s, 60.0, " s");
    s.number("min_predictive_fraction", r.min_predictive_fraction, 0.0, 1.0);
    s.positive("proxy_stiffness_ratio", r.proxy_stiffness_ratio, 1e6);
    s.number("coupling_damping_factor", r.coupling_damping_factor, 0.0, 1e3);
    s.number("rot_stiffness_nm_per_rad", r.rot_stiffness_nm_per_rad, 0.0, 1e6, " N m/rad");
    s.positive("penetration_allowance_m", r.penetration_allowance_m, 1e6, " m");
    s.number("crease_angle_deg", r.crease_angle_deg, 0.0, 180.0, " degrees");
    s.integer("attach_button_mask", r.attach_button_mask, 0, 0xffffffffll);
    s.number("attach_distance_m", r.attach_distance_m, 0.0, 1e6, " m");
    s.choice("hinge_attach", r.hinge_attach, &parseHingeAttach);
    s.number("centre_radius_fraction", r.centre_radius_fraction, 0.0, 1.0);
    s.boolean("grab_weight", r.grab_weight);
    s.boolean("grab_inertia", r.grab_inertia);
    s.number("grab_inertia_filter_s", r.grab_inertia_filter_s, 0.0, 10.0, " s");
    s.number("dynamic_backstop_fraction", r.dynamic_backstop_fraction, 0.0, 1e3);
    s.number("impulse_window_s", r.impulse_window_s, 0.0, 10.0, " s");
    s.number("dynamics_sleep_time_s", r.dynamics_sleep_time_s, 0.0, 1e6, " s");
  }
  {
    Section s(sectionOf(root, "scene", name, errors), "scene", name, errors, keys, all_keys);
    auto& sc = c.scene;
    s.string("path", sc.path);
    s.string("demo", sc.demo, [](const std::string& v) -> std::optional<std::string> {
      if (v.empty())
        return std::string("must name a demo scene");
      return std::nullopt;
    });
    s.integer("max_file_bytes", sc.max_file_bytes, 1, std::int64_t{1} << 40);
    s.integer("max_nodes", sc.max_nodes, 1, 100000000);
    s.integer("max_bodies", sc.max_bodies, 1, 100000000);
    s.integer("max_primitives", sc.max_primitives, 1, 100000000);
    s.integer("max_hull_input_points", sc.max_hull_input_points, 4, 100000000);
    s.integer("max_hull_vertices", sc.max_hull_vertices, 4, 100000000);
    s.positive("tessellation_tolerance", sc.tessellation_tolerance, 0.5);
    s.string("allowed_uri_dir", sc.allowed_uri_dir);
  }
  {
    Section s(sectionOf(root, "network", name, errors), "network", name, errors, keys, all_keys);
    s.string("udp", c.network.udp, &checkUdp);
    s.string("key_file", c.network.key_file);
    s.number("rate_limit_packets_per_s", c.network.rate_limit_packets_per_s, 0.0, 1e9);
    s.number("rate_limit_burst", c.network.rate_limit_burst, 1.0, 1e9);
    s.integer("max_datagram_bytes", c.network.max_datagram_bytes, 512, 65507);
    s.number("max_state_rate_hz", c.network.max_state_rate_hz, 1.0, 1000.0, " Hz");
    s.string("shm", c.network.shm, &checkShmName);
  }
  {
    Section s(sectionOf(root, "log", name, errors), "log", name, errors, keys, all_keys);
    s.choice("level", c.log.level, &parseLogLevel);
    s.number("status_interval_s", c.log.status_interval_s, 0.0, 86400.0, " s");
  }
}

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) {
    if (!out.empty())
      out += '\n';
    out += l;
  }
  return out;
}

}  // namespace

Result<ParsedConfig> parseConfig(std::string_view text, const std::string& name) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    return Error{name + ":" + std::to_string(e.source().begin.line) + ": " +
                 std::string(e.description())};
  }
  ParsedConfig parsed;
  std::vector<std::string> errors;
  readAll(root, name, parsed.config, errors, parsed.keys_set);
  if (!errors.empty())
    return Error{joinLines(errors)};
  return parsed;
}

Result<ParsedConfig> loadConfigFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return Error{path.string() + ": cannot read the config file"};
  std::ostringstream ss;
  ss << in.rdbuf();
  if (ss.str().size() > (1u << 20))
    return Error{path.string() + ": config file over 1 MiB"};
  return parseConfig(ss.str(), path.string());
}

std::vector<std::string> knownConfigKeys() {
  // the reader itself lists the keys it looks up
  std::vector<std::string> errors, keys_set, all;
  Config c;
  readAll(toml::table{}, "(keys)", c, errors, keys_set, &all);
  return all;
}

Result<bool> validateConfig(const Config& c) {
  std::vector<std::string> errors;
  if (!(c.servo.rate_hz >= 1.0 && c.servo.rate_hz <= 20000.0))
    errors.push_back("[servo] rate_hz: must be in [1, 20000] Hz (got " + fmtNum(c.servo.rate_hz) +
                     ")");
  if (c.servo.priority < 1 || c.servo.priority > 99)
    errors.push_back("[servo] priority: must be in [1, 99] (got " +
                     std::to_string(c.servo.priority) + ")");
  if (c.servo.cpu < -1 || c.servo.cpu > 1023)
    errors.push_back("[servo] cpu: must be -1 or a CPU number (got " + std::to_string(c.servo.cpu) +
                     ")");
  if (c.device.spec.empty())
    errors.push_back("[device] spec: must not be empty");
  if (auto p = checkUdp(c.network.udp))
    errors.push_back("[network] udp: " + *p);
  if (auto p = checkShmName(c.network.shm))
    errors.push_back("[network] shm: " + *p);
  if (!errors.empty())
    return Error{joinLines(errors)};
  return true;
}

sim::SimOptions toSimOptions(const Config& c) {
  sim::SimOptions o;
  o.response.stiffness_n_per_m = c.response.stiffness_n_per_m;
  o.response.tick_s = c.response.tick_s > 0.0 ? c.response.tick_s : 1.0 / c.servo.rate_hz;
  o.response.max_force_n = c.response.max_force_n;
  o.response.max_torque_nm = c.response.max_torque_nm;
  o.response.max_force_step_n = c.response.max_force_step_n;
  o.response.max_torque_step_nm = c.response.max_torque_step_nm;
  o.response.ramp_s = c.response.ramp_s;
  o.max_pairs_per_tick = c.response.max_pairs_per_tick;
  o.probe_sphere_radius_m = c.response.probe_sphere_radius_m;
  auto& r = o.response;
  const auto& cr = c.response;
  r.max_speed_m_per_s = cr.max_speed_m_per_s;
  r.speed_decay_s = cr.speed_decay_s;
  r.min_predictive_fraction = cr.min_predictive_fraction;
  r.proxy_stiffness_ratio = cr.proxy_stiffness_ratio;
  r.coupling_damping_factor = cr.coupling_damping_factor;
  r.rot_stiffness_nm_per_rad = cr.rot_stiffness_nm_per_rad;
  r.penetration_allowance_m = cr.penetration_allowance_m;
  r.crease_angle_deg = cr.crease_angle_deg;
  r.attach_button_mask = cr.attach_button_mask;
  r.attach_distance_m = cr.attach_distance_m;
  r.hinge_attach = cr.hinge_attach;
  r.centre_radius_fraction = cr.centre_radius_fraction;
  r.grab_weight = cr.grab_weight;
  r.grab_inertia = cr.grab_inertia;
  r.grab_inertia_filter_s = cr.grab_inertia_filter_s;
  r.dynamic_backstop_fraction = cr.dynamic_backstop_fraction;
  o.dynamics_impulse_window_s = cr.impulse_window_s;
  o.dynamics_sleep_time_s = cr.dynamics_sleep_time_s;
  return o;
}

namespace {
geom::Pose poseOf(const std::array<double, 3>& t, const std::array<double, 4>& q) {
  return geom::Pose::fromXyzw(geom::Vec3(t[0], t[1], t[2]), q[0], q[1], q[2], q[3]);
}
}  // namespace

device::DeviceOptions toDeviceOptions(const Config& c) {
  device::DeviceOptions o;
  o.limits.max_force_n = c.device.max_force_n;
  o.limits.max_torque_nm = c.device.max_torque_nm;
  o.sim_hand_mass_kg = c.device.sim_hand_mass_kg;
  o.sim_hand_stiffness_n_per_m = c.device.sim_hand_stiffness_n_per_m;
  o.sim_hand_damping_n_s_per_m = c.device.sim_hand_damping_n_s_per_m;
  o.sim_idle_motion_after_s = c.device.sim_idle_motion_after_s;
  o.sim_home = poseOf(c.device.sim_home_translation_m, c.device.sim_home_rotation);
  const auto& d = c.device;
  o.sim_hand_inertia_kg_m2 = d.sim_hand_inertia_kg_m2;
  o.sim_hand_rot_stiffness_nm_per_rad = d.sim_hand_rot_stiffness_nm_per_rad;
  o.sim_hand_rot_damping_nm_s_per_rad = d.sim_hand_rot_damping_nm_s_per_rad;
  o.sim_idle_amplitude_m = d.sim_idle_amplitude_m;
  o.sim_idle_angle_rad = d.sim_idle_angle_rad;
  o.sim_max_step_s = d.sim_max_step_s;
  o.replay_quat_tolerance = d.replay_quat_tolerance;
  o.hid_spacemouse_speed_m_per_s = d.hid_spacemouse_speed_m_per_s;
  o.hid_spacemouse_angular_speed_rad_per_s = d.hid_spacemouse_angular_speed_rad_per_s;
  o.hid_spacemouse_full_scale = d.hid_spacemouse_full_scale;
  o.hid_spacemouse_deadband = d.hid_spacemouse_deadband;
  o.hid_spacemouse_workspace_m = d.hid_spacemouse_workspace_m;
  o.usb_silence_lost_s = d.usb_silence_lost_s;
  o.usb_falcon_max_motor_command = d.usb_falcon_max_motor_command;
  o.usb_falcon_firmware = d.usb_falcon_firmware;
  return o;
}

scene::LoadOptions toLoadOptions(const Config& c) {
  scene::LoadOptions o;
  o.limits.max_file_bytes = c.scene.max_file_bytes;
  o.limits.max_nodes = c.scene.max_nodes;
  o.limits.max_bodies = c.scene.max_bodies;
  o.limits.max_primitives = c.scene.max_primitives;
  o.limits.max_hull_input_points = c.scene.max_hull_input_points;
  o.limits.max_hull_vertices = c.scene.max_hull_vertices;
  o.limits.tessellation_tolerance = c.scene.tessellation_tolerance;
  if (!c.scene.allowed_uri_dir.empty())
    o.allowed_uri_dir = c.scene.allowed_uri_dir;
  return o;
}

RealtimeOptions toRealtimeOptions(const Config& c) {
  RealtimeOptions o;
  o.policy = c.servo.realtime;
  o.priority = c.servo.priority;
  o.cpu = c.servo.cpu;
  o.stack_prefault_bytes = static_cast<std::size_t>(c.servo.stack_prefault_kib) * 1024;
  return o;
}

ServoOptions toServoOptions(const Config& c, const device::DeviceInfo& device) {
  ServoOptions o;
  o.rate_hz = c.servo.rate_hz;
  o.miss_fault_count = c.servo.miss_fault_count;
  o.fault_fade_s = c.servo.fault_fade_s;
  o.stop_ramp_s = c.servo.stop_ramp_s;
  o.armed_at_start = c.servo.armed_at_start;
  o.workspace.X_SD = poseOf(c.device.workspace_translation_m, c.device.workspace_rotation);
  o.workspace.scale = c.device.workspace_scale;
  // the tighter of the configured limits and what the backend reports
  o.limits.max_force_n = std::min(c.device.max_force_n, device.limits.max_force_n);
  o.limits.max_torque_nm = std::min(c.device.max_torque_nm, device.limits.max_torque_nm);
  o.max_force_step_n = c.device.max_force_step_n;
  o.max_torque_step_nm = c.device.max_torque_step_nm;
  o.record_capacity = c.servo.record_ring_rows;
  o.body_capacity = static_cast<std::size_t>(c.servo.record_ring_rows) * 4;
  return o;
}

const char* toString(ClockKind kind) {
  return kind == ClockKind::kVirtual ? "virtual" : "monotonic";
}

const char* toString(LogLevel level) {
  switch (level) {
    case LogLevel::kError:
      return "error";
    case LogLevel::kWarning:
      return "warning";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kDebug:
      return "debug";
  }
  return "?";
}

Result<LogLevel> parseLogLevel(std::string_view t) {
  if (t == "error")
    return LogLevel::kError;
  if (t == "warning")
    return LogLevel::kWarning;
  if (t == "info")
    return LogLevel::kInfo;
  if (t == "debug")
    return LogLevel::kDebug;
  return Error{"\"" + std::string(t) +
               "\" is not one of \"error\", \"warning\", \"info\", \"debug\""};
}

const char* toString(sim::ResponseOptions::HingeAttach a) {
  switch (a) {
    case sim::ResponseOptions::HingeAttach::kAuto:
      return "auto";
    case sim::ResponseOptions::HingeAttach::kRim:
      return "rim";
    case sim::ResponseOptions::HingeAttach::kCentre:
      return "centre";
  }
  return "?";
}

Result<sim::ResponseOptions::HingeAttach> parseHingeAttach(std::string_view t) {
  if (t == "auto")
    return sim::ResponseOptions::HingeAttach::kAuto;
  if (t == "rim")
    return sim::ResponseOptions::HingeAttach::kRim;
  if (t == "centre")
    return sim::ResponseOptions::HingeAttach::kCentre;
  return Error{"\"" + std::string(t) + "\" is not one of \"auto\", \"rim\", \"centre\""};
}

Result<ClockKind> parseClockKind(std::string_view t) {
  if (t == "monotonic")
    return ClockKind::kMonotonic;
  if (t == "virtual")
    return ClockKind::kVirtual;
  return Error{"\"" + std::string(t) + "\" is not one of \"monotonic\", \"virtual\""};
}

}  // namespace hapticd::daemon
