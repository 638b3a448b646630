#include "daemon/config.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <type_traits>
#include <utility>

#include "daemon/config_keys.h"
#include "daemon/enum_names.h"

namespace hapticd::daemon {
namespace {

// Problems of one file, each with its line, listed in line order.
class Problems {
 public:
  explicit Problems(const std::string& name) : name_(name) {}
  void add(const toml::node& at, const std::string& text) {
    list_.emplace_back(at.source().begin.line,
                       name_ + ":" + std::to_string(at.source().begin.line) + ": " + text);
  }
  bool empty() const { return list_.empty(); }
  std::vector<std::string> lines() {
    std::stable_sort(list_.begin(), list_.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> out;
    for (auto& p : list_)
      out.push_back(std::move(p.second));
    return out;
  }

 private:
  const std::string& name_;
  std::vector<std::pair<std::uint32_t, std::string>> list_;
};

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) {
    if (!out.empty())
      out += '\n';
    out += l;
  }
  return out;
}

// a number: a TOML float, or an integer taken as one
std::optional<double> numberOf(const toml::node& n) {
  if (auto f = n.value_exact<double>())
    return *f;
  if (auto i = n.value_exact<std::int64_t>())
    return static_cast<double>(*i);
  return std::nullopt;
}

Result<RealtimePolicy> parseEnum(std::string_view t, RealtimePolicy*) {
  return parseRealtimePolicy(t);
}
Result<ClockKind> parseEnum(std::string_view t, ClockKind*) {
  return parseClockKind(t);
}
Result<LogLevel> parseEnum(std::string_view t, LogLevel*) {
  return parseLogLevel(t);
}
Result<sim::ResponseOptions::HingeAttach> parseEnum(std::string_view t,
                                                    sim::ResponseOptions::HingeAttach*) {
  return parseHingeAttach(t);
}

// `n` as an array of N numbers, each finite and within ±bound; what is wrong, or nothing
template <std::size_t N>
std::optional<std::string> readArray(const toml::node& n, double bound, double (&out)[N]) {
  const toml::array* a = n.as_array();
  if (a == nullptr || a->size() != N)
    return "must be an array of " + std::to_string(N) + " numbers";
  for (std::size_t i = 0; i < N; ++i) {
    const auto v = numberOf(*a->get(i));
    if (!v)
      return "element " + std::to_string(i) + " must be a number";
    if (!std::isfinite(*v) || std::abs(*v) > bound)
      return "element " + std::to_string(i) + " must be finite and within ±" +
             shortestNumber(bound) + " (got " + shortestNumber(*v) + ")";
    out[i] = *v;
  }
  return std::nullopt;
}

// Reads `n` into the key's field of `c`; what is wrong, or nothing (then the field may hold a
// refused value: a refused file is never used).
std::optional<std::string> readValue(const toml::node& n, const ConfigKey& key, Config& c) {
  return std::visit(
      [&](auto* p) -> std::optional<std::string> {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          const auto b = n.value_exact<bool>();
          if (!b)
            return "must be true or false";
          *p = *b;
          return std::nullopt;
        } else if constexpr (std::is_same_v<T, double>) {
          const auto v = numberOf(n);
          if (!v)
            return "must be a number";
          *p = *v;
          return checkNumber(key, *v);
        } else if constexpr (std::is_integral_v<T>) {
          const auto i = n.value_exact<std::int64_t>();
          if (!i)
            return "must be an integer";
          if (auto problem = checkNumber(key, static_cast<double>(*i)))
            return problem;
          *p = static_cast<T>(*i);
          return std::nullopt;
        } else if constexpr (std::is_same_v<T, std::string>) {
          const auto s = n.value_exact<std::string>();
          if (!s)
            return "must be a string";
          *p = *s;
          return checkValue(key, c);
        } else if constexpr (std::is_same_v<T, geom::Vec3>) {
          double v[3];
          if (auto problem = readArray(n, key.range.hi, v))
            return problem;
          *p = geom::Vec3(v[0], v[1], v[2]);
          return std::nullopt;
        } else if constexpr (std::is_same_v<T, geom::Quat>) {
          double q[4];
          if (auto problem = readArray(n, 1.0 + 1e-9, q))
            return problem;
          *p = geom::Quat(q[3], q[0], q[1], q[2]);
          if (auto problem = checkValue(key, c))
            return problem;
          *p = glm::normalize(*p);  // as geom::Pose::fromXyzw
          return std::nullopt;
        } else {
          const auto s = n.value_exact<std::string>();
          if (!s)
            return "must be a string";
          auto e = parseEnum(*s, p);
          if (!e)
            return e.error().message;
          *p = e.value();
          return std::nullopt;
        }
      },
      key.in(c));
}

// the key a file's `section.name` sets (itself, or the one a deprecated key was replaced by)
struct Resolved {
  const ConfigKey* key = nullptr;
  const DeprecatedKey* deprecated = nullptr;
};
Resolved resolve(std::string_view section,
                 std::string_view name,
                 std::span<const DeprecatedKey> deprecated) {
  if (const ConfigKey* k = findConfigKey(section, name))
    return {k, nullptr};
  for (const DeprecatedKey& d : deprecated)
    if (section == d.old_section && name == d.old_name)
      return {findConfigKey(d.section, d.name), &d};
  return {};
}

// "[old] name" of the deprecated key that `key` replaced (the first, if several)
std::string oldLabel(const ConfigKey& key, std::span<const DeprecatedKey> deprecated) {
  for (const DeprecatedKey& d : deprecated)
    if (key.section == d.section && key.name == d.name)
      return "[" + std::string(d.old_section) + "] " + d.old_name;
  return key.label();
}

// the warning for a deprecated key set beside its new one to the same value: it replaces the
// old key's own warning if that came first (a table's keys are read in name order)
void sameValueWarning(std::vector<std::string>& warnings,
                      const std::string& line,
                      const std::string& old_label,
                      const ConfigKey& key) {
  const std::string text = old_label + " is deprecated: use " + key.label() +
                           " (both are set, to the same value: remove " + old_label + ")";
  const std::string earlier = ": " + old_label + " is deprecated: use ";
  for (std::string& w : warnings) {
    const std::size_t at = w.find(earlier);
    if (at != std::string::npos) {
      w.resize(at + 2);
      w += text;
      return;
    }
  }
  warnings.push_back(line + text);
}

void readSection(const toml::table& table,
                 std::string_view section,
                 std::span<const DeprecatedKey> deprecated,
                 Problems& problems,
                 std::vector<std::string>& warnings,
                 const std::string& name,
                 std::vector<const ConfigKey*>& set,
                 Config& c) {
  const std::string label = "[" + std::string(section) + "] ";
  for (auto&& [k, v] : table) {
    const std::string key_name(k.str());
    const Resolved r = resolve(section, key_name, deprecated);
    if (r.key == nullptr) {
      problems.add(v, label + key_name + ": unknown key (see config/hapticd.toml for every key)");
      continue;
    }
    const std::string line = name + ":" + std::to_string(v.source().begin.line) + ": ";
    if (std::find(set.begin(), set.end(), r.key) != set.end()) {
      // set under its deprecated name and its own: the same value is taken with a warning,
      // different values are refused, naming both
      const std::string old_label =
          r.deprecated != nullptr ? label + key_name : oldLabel(*r.key, deprecated);
      Config other = c;
      if (auto problem = readValue(v, *r.key, other))
        problems.add(v, label + key_name + ": " + *problem);
      else if (sameValue(*r.key, c, other))
        sameValueWarning(warnings, line, old_label, *r.key);
      else
        problems.add(v, std::string(old_label)
                            .append(" and ")
                            .append(r.key->label())
                            .append(" are both set, to different values: ")
                            .append(old_label)
                            .append(" is deprecated, keep only ")
                            .append(r.key->label()));
      continue;
    }
    if (r.deprecated != nullptr)
      warnings.push_back(std::string(line)
                             .append(label)
                             .append(key_name)
                             .append(" is deprecated: use ")
                             .append(r.key->label())
                             .append(" (the value is taken for it)"));
    set.push_back(r.key);
    if (auto problem = readValue(v, *r.key, c))
      problems.add(v, label + key_name + ": " + *problem);
  }
}

}  // namespace

bool operator==(const Config& a, const Config& b) {
  for (const ConfigKey& k : configKeys())
    if (!sameValue(k, a, b))
      return false;
  return true;
}

std::vector<std::string> changedKeys(const Config& a,
                                     const Config& b,
                                     std::span<const std::string_view> sections) {
  std::vector<std::string> out;
  for (const ConfigKey& k : configKeys()) {
    if (!sections.empty() &&
        std::find(sections.begin(), sections.end(), k.section) == sections.end())
      continue;
    if (!sameValue(k, a, b))
      out.push_back(std::string(k.section) + "." + std::string(k.name));
  }
  return out;
}

std::span<const DeprecatedKey> deprecatedConfigKeys() {
  // a key renamed or moved is listed here (old section, old name, new section, new name), so
  // that old files keep working with a warning. The output limits were set twice, in [device]
  // and in [response]; they are one set now.
  static constexpr DeprecatedKey kDeprecated[] = {
      {"response", "max_force_n", "device", "max_force_n"},
      {"response", "max_torque_nm", "device", "max_torque_nm"},
      {"response", "max_force_step_n", "device", "max_force_step_n"},
      {"response", "max_torque_step_nm", "device", "max_torque_step_nm"},
      {"response", "ramp_s", "servo", "ramp_in_s"},
  };
  return kDeprecated;
}

Result<ParsedConfig> parseConfig(std::string_view text,
                                 const std::string& name,
                                 std::span<const DeprecatedKey> deprecated) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    return Error{name + ":" + std::to_string(e.source().begin.line) + ": " +
                 std::string(e.description())};
  }
  ParsedConfig parsed;
  Problems problems(name);
  std::vector<const ConfigKey*> set;
  const auto sections = configSections();
  for (auto&& [k, v] : root) {
    const std::string section(k.str());
    if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
      problems.add(v, section +
                          ": unknown section or key (sections: servo, device, response, scene, "
                          "network, web, log)");
    } else if (!v.is_table()) {
      problems.add(
          v, std::string(section).append(": must be a table ([").append(section).append("])"));
    } else {
      readSection(*v.as_table(), section, deprecated, problems, parsed.warnings, name, set,
                  parsed.config);
    }
  }
  if (!problems.empty())
    return Error{joinLines(problems.lines())};
  for (const ConfigKey& k : configKeys())
    if (std::find(set.begin(), set.end(), &k) != set.end())
      parsed.keys_set.push_back(std::string(k.section) + "." + std::string(k.name));
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
  std::vector<std::string> all;
  for (const ConfigKey& k : configKeys())
    all.push_back(std::string(k.section) + "." + std::string(k.name));
  return all;
}

Result<bool> validateConfig(const Config& c) {
  std::vector<std::string> errors;
  for (const ConfigKey& k : configKeys())
    if (auto problem = checkValue(k, c))
      errors.push_back(k.label() + ": " + *problem);
  if (!errors.empty())
    return Error{joinLines(errors)};
  return true;
}

namespace {

// the comment above a key: its text, its range and unit, its default; wrapped at 100 columns
// with "(default: ...)" and a range kept whole on one line
std::string keyComment(const ConfigKey& k) {
  std::vector<std::string> tokens;
  std::istringstream words{std::string(k.text)};
  for (std::string w; words >> w;)
    tokens.push_back(w);
  const std::string unit = k.unit.empty() ? "" : " " + std::string(k.unit);
  std::string range;
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, double> ||
                      (std::is_integral_v<T> && !std::is_same_v<T, bool>))
          range = "Range " + k.range.text() + unit + ".";
        else if constexpr (std::is_same_v<T, geom::Vec3>)
          range = "[x, y, z]" + unit + ", each within ±" + shortestNumber(k.range.hi) + ".";
        else if constexpr (std::is_same_v<T, geom::Quat>)
          range = "[x, y, z, w], unit length.";
      },
      k.in(Config{}));
  if (!range.empty())
    tokens.push_back(range);
  tokens.push_back("(default: " + tomlValue(k, Config{}) + ")");
  std::string out, line = "#";
  for (const std::string& t : tokens) {
    if (line.size() > 1 && line.size() + 1 + t.size() > 100) {
      out += line + "\n";
      line = "#";
    }
    line += " " + t;
  }
  return out + line + "\n";
}

constexpr const char* kFileHeader =
    "# hapticd configuration: every key with its value, and above it what the key does, its "
    "range and\n"
    "# its default. An empty file, or no --config at all, means the defaults.\n"
    "# A wrong value, a wrong type or an unknown key is refused with the file, line and key; on "
    "SIGHUP a\n"
    "# refused file changes nothing (the daemon keeps the configuration it runs).\n"
    "# Command-line options override the file (`hapticd --help`); `hapticd --check-config` runs "
    "the\n"
    "# start-up checks (the scene loaded, its simulation built, the device spec, the key file).\n"
    "# Units: metres, kilograms, seconds, newtons; rotations are quaternions [x, y, z, w] (glTF "
    "order).\n"
    "# config/hapticd.toml is this text for the defaults, made from the table of keys in\n"
    "# daemon/config_keys.cpp: `hapticd --print-config > config/hapticd.toml`.\n";

}  // namespace

std::string toToml(const Config& c) {
  std::string out = kFileHeader;
  std::string_view section;
  for (const ConfigKey& k : configKeys()) {
    if (k.section != section) {
      section = k.section;
      out += "\n[" + std::string(section) + "]\n";
    }
    out += keyComment(k) + std::string(k.name) + " = " + tomlValue(k, c) + "\n";
  }
  return out;
}

sim::SimOptions toSimOptions(const Config& c) {
  sim::SimOptions o = c.response.sim;
  o.response.tick_s = c.response.tick_s > 0.0 ? c.response.tick_s : 1.0 / c.servo.rate_hz;
  // one set of output limits: the [device] keys, and the ramp-in of [servo]
  o.response.max_force_n = c.device.options.limits.max_force_n;
  o.response.max_torque_nm = c.device.options.limits.max_torque_nm;
  o.response.max_force_step_n = c.device.max_force_step_n;
  o.response.max_torque_step_nm = c.device.max_torque_step_nm;
  o.response.ramp_s = c.servo.ramp_in_s;
  return o;
}

scene::LoadOptions toLoadOptions(const Config& c) {
  scene::LoadOptions o;
  o.limits = c.scene.limits;
  if (!c.scene.allowed_uri_dir.empty())
    o.allowed_uri_dir = c.scene.allowed_uri_dir;
  o.decomposition.concavity = c.scene.concavity;
  o.decomposition.max_pieces = c.scene.max_pieces;
  o.decomposition.time_limit_s = c.scene.decompose_time_limit_s;
  o.decomposition.cache_dir = scene::decompositionCacheDir(c.scene.cache_dir);
  o.decomposition.cache_max_bytes = std::uint64_t{c.scene.cache_max_mb} << 20;
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
  o.ramp_in_s = c.servo.ramp_in_s;
  o.armed_at_start = c.servo.armed_at_start;
  o.workspace = c.device.workspace;
  // the tighter of the configured limits and what the backend reports
  const device::DeviceLimits& limits = c.device.options.limits;
  o.limits.max_force_n = std::min(limits.max_force_n, device.limits.max_force_n);
  o.limits.max_torque_nm = std::min(limits.max_torque_nm, device.limits.max_torque_nm);
  o.max_force_step_n = c.device.max_force_step_n;
  o.max_torque_step_nm = c.device.max_torque_step_nm;
  o.record_capacity = c.servo.record_ring_rows;
  o.body_capacity = static_cast<std::size_t>(c.servo.record_ring_rows) * 4;
  return o;
}

namespace {
constexpr EnumName<ClockKind> kClockNames[] = {{ClockKind::kMonotonic, "monotonic"},
                                               {ClockKind::kVirtual, "virtual"}};
constexpr EnumName<LogLevel> kLogLevelNames[] = {{LogLevel::kError, "error"},
                                                 {LogLevel::kWarning, "warning"},
                                                 {LogLevel::kInfo, "info"},
                                                 {LogLevel::kDebug, "debug"}};
constexpr EnumName<sim::ResponseOptions::HingeAttach> kHingeAttachNames[] = {
    {sim::ResponseOptions::HingeAttach::kAuto, "auto"},
    {sim::ResponseOptions::HingeAttach::kRim, "rim"},
    {sim::ResponseOptions::HingeAttach::kCentre, "centre"}};
}  // namespace

const char* toString(ClockKind kind) {
  return nameIn(kClockNames, kind);
}
Result<ClockKind> parseClockKind(std::string_view t) {
  return parseIn(kClockNames, t);
}
const char* toString(LogLevel level) {
  return nameIn(kLogLevelNames, level);
}
Result<LogLevel> parseLogLevel(std::string_view t) {
  return parseIn(kLogLevelNames, t);
}
const char* toString(sim::ResponseOptions::HingeAttach a) {
  return nameIn(kHingeAttachNames, a);
}
Result<sim::ResponseOptions::HingeAttach> parseHingeAttach(std::string_view t) {
  return parseIn(kHingeAttachNames, t);
}

}  // namespace hapticd::daemon
