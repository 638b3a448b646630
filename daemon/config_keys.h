#pragma once
/// \file
/// The one table of configuration keys: for each key its section, name, the field of Config it
/// sets, its range and unit, and its text. The parser (daemon/config.cpp), validateConfig(),
/// `--check-config`, `--print-config` and config/hapticd.toml are all made from it; the default
/// is the field's initializer. The ranges agree with what the users of each value refuse
/// (sim::Simulation::create, scene::loadScene, the device backends): tests/daemon/config_test.cpp
/// holds them to it.
///
/// Threads: any normal thread (the table is immutable).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "daemon/config.h"

namespace hapticd::daemon {

/// The field one key reads and writes. The type says what the TOML value must be: bool a
/// boolean, the integer types an integer, double a number (an integer is taken too), string a
/// string, the enums a string naming one of their values, Vec3 an array of 3 numbers, Quat an
/// array of 4 numbers [x, y, z, w] of unit length (stored normalised).
using FieldRef = std::variant<bool*,
                              int*,
                              std::uint32_t*,
                              std::uint64_t*,
                              std::int64_t*,
                              double*,
                              std::string*,
                              geom::Vec3*,
                              geom::Quat*,
                              RealtimePolicy*,
                              ClockKind*,
                              LogLevel*,
                              sim::ResponseOptions::HingeAttach*>;

/// Allowed values of a number or an integer, each end open or closed. For a Vec3, every element
/// is finite and within ±hi.
struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool lo_open = false;
  bool hi_open = false;
  bool contains(double v) const;
  /// "[1, 20000]", "(0, 1]", "[0, 90)"
  std::string text() const;
};

/// One key. `check` (strings only, may be null) says what is wrong with a value, or nothing.
struct ConfigKey {
  std::string_view section;
  std::string_view name;
  FieldRef (*field)(Config&);
  Range range;
  std::string_view unit;  ///< "" or e.g. "Hz", "N m" (messages and the documented file)
  std::string_view text;  ///< what the key does (the comment above it in config/hapticd.toml)
  std::optional<std::string> (*check)(const std::string&) = nullptr;

  /// "[section] name"
  std::string label() const;
  /// The field in `c` (read-only use through the const overload).
  FieldRef in(Config& c) const { return field(c); }
  FieldRef in(const Config& c) const { return field(const_cast<Config&>(c)); }
};

/// Every key, in file order.
std::span<const ConfigKey> configKeys();
/// The sections, in file order.
std::span<const std::string_view> configSections();
/// The key `section.name`, or nullptr.
const ConfigKey* findConfigKey(std::string_view section, std::string_view name);

/// The key's value in `c` as a TOML literal ("1000.0", "\"sim\"", "[0.0, 0.0, 0.0]", "true").
std::string tomlValue(const ConfigKey& key, const Config& c);
/// What is wrong with `v` as the key's number (out of its range, not finite), or nothing.
std::optional<std::string> checkNumber(const ConfigKey& key, double v);
/// What is wrong with the key's value in `c` (range, finiteness, unit quaternion, the string's
/// check, an enum value with no name), or nothing.
std::optional<std::string> checkValue(const ConfigKey& key, const Config& c);
/// The two configs hold the same value for the key.
bool sameValue(const ConfigKey& key, const Config& a, const Config& b);

/// A number as TOML writes a float: the shortest text that reads back to the same double, with
/// ".0" when it would otherwise read as an integer ("1000.0", "0.05", "1e-09").
std::string tomlFloat(double v);
/// The shortest text that reads back to the same double ("1000", "0.05", "1e+09").
std::string shortestNumber(double v);

}  // namespace hapticd::daemon
