#pragma once
/// \file
/// Typed access to the members of a glTF JSON document for the scene loader's validation (internal
/// to hapticd_scene): each accessor checks one member's type, range or index and reports its own
/// problem ("node 3 'Peg': translation must be an array of 3 numbers"), collecting every problem.
/// Any thread but the servo thread.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/geometry/pose.h"
#include "core/scene/loader.h"

namespace hapticd::scene::detail {

using nlohmann::json;

/// Collected problems, capped so that a hostile file cannot make the report huge.
class Problems {
 public:
  static constexpr std::size_t kMax = 200;
  void add(std::string where, std::string what);
  bool any() const { return !list_.empty() || dropped_ > 0; }
  /// The list is full: further work would only be counted, not reported.
  bool full() const { return list_.size() >= kMax; }
  std::vector<Problem> take();
  /// A note, not a problem: something ignored or stood in for, for the plan's notes.
  void note(std::string line);
  std::vector<std::string> takeNotes() { return std::move(notes_); }

 private:
  std::vector<Problem> list_;
  std::size_t dropped_ = 0;
  std::vector<std::string> notes_;
};

/// 's' in single quotes, for names in messages.
std::string inQuotes(const std::string& s);
/// A number as messages print it (%.9g).
std::string formatNumber(double v);

/// A rotation quaternion whose norm is farther than this from 1 is refused; closer ones are
/// normalised (exporters write float32 quaternions).
inline constexpr double kUnitQuaternionTolerance = 1e-3;

/// What a typed read found.
enum class Got { kAbsent, kOk, kBad };

/// Typed access to JSON members, each reporting its own problem to `problems`.
class Checker {
 public:
  explicit Checker(Problems* problems) : p_(problems) {}

  void add(const std::string& where, std::string what) { p_->add(where, std::move(what)); }
  Problems& problems() { return *p_; }

  /// The member `key` of `o`, or null (also when `o` is not an object).
  static const json* find(const json& o, const char* key);

  Got object(const json& o,
             const char* key,
             const std::string& where,
             const json** out,
             bool required = false);
  Got array(const json& o,
            const char* key,
            const std::string& where,
            const json** out,
            bool required = false);
  Got boolean(const json& o, const char* key, const std::string& where, bool* out);
  Got string(const json& o,
             const char* key,
             const std::string& where,
             std::string* out,
             bool required = false);
  Got uinteger(const json& o,
               const char* key,
               const std::string& where,
               std::uint64_t* out,
               bool required = false);

  /// An index into an array of `count` `things`.
  Got index(const json& o,
            const char* key,
            std::size_t count,
            const char* things,
            const std::string& where,
            std::int32_t* out,
            bool required = false);
  Got indexValue(const json& j,
                 const std::string& key,
                 std::size_t count,
                 const char* things,
                 const std::string& where,
                 std::int32_t* out);

  Got number(const json& o, const char* key, const std::string& where, double* out);
  /// A number that must be >= min (or > min when exclusive).
  Got bounded(const json& o,
              const char* key,
              const std::string& where,
              double* out,
              double min,
              bool exclusive);
  /// An array of exactly `n` finite numbers.
  Got vector(const json& o, const char* key, std::size_t n, const std::string& where, double* out);
  Got vec3(const json& o, const char* key, const std::string& where, geom::Vec3* out);
  /// A glTF quaternion (x, y, z, w): normalised when close to unit, refused otherwise.
  Got quaternion(const json& o, const char* key, const std::string& where, geom::Quat* out);
  /// An array of strings.
  Got strings(const json& o,
              const char* key,
              const std::string& where,
              std::vector<std::string>* out);

  /// One of `names` (an enumerated string); `*out` is its position. Absent: kAbsent, *out kept.
  Got choice(const json& o,
             const char* key,
             const std::string& where,
             const std::vector<std::string>& names,
             std::size_t* out);

 private:
  /// The member `key` when `is(member)`; a "must be <expected>" problem otherwise.
  template <class Is>
  Got typed(const json& o,
            const char* key,
            const std::string& where,
            bool required,
            const char* expected,
            Is is,
            const json** out);
  /// typed() and the member's value.
  template <class T>
  Got scalar(const json& o,
             const char* key,
             const std::string& where,
             bool required,
             const char* expected,
             bool (json::*is)() const noexcept,
             T* out);
  Got missing(const std::string& where, const char* key, bool required);
  Got wrong(const std::string& where, const char* key, const char* expected, const json& j);

  Problems* p_;
};

}  // namespace hapticd::scene::detail
