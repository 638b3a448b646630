#include "core/scene/json_checker.h"

#include <cmath>
#include <cstdio>

namespace hapticd::scene::detail {

void Problems::add(std::string where, std::string what) {
  if (list_.size() >= kMax) {
    ++dropped_;
    return;
  }
  list_.push_back({std::move(where), std::move(what)});
}

std::vector<Problem> Problems::take() {
  std::vector<Problem> out = std::move(list_);
  if (dropped_ > 0)
    out.push_back({"file", std::to_string(dropped_) + " more problems not listed"});
  list_.clear();
  dropped_ = 0;
  return out;
}

void Problems::note(std::string line) {
  if (notes_.size() < kMax)
    notes_.push_back(std::move(line));
}

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

std::string formatNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

const json* Checker::find(const json& o, const char* key) {
  if (!o.is_object())
    return nullptr;
  const auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}

template <class Is>
Got Checker::typed(const json& o,
                   const char* key,
                   const std::string& where,
                   bool required,
                   const char* expected,
                   Is is,
                   const json** out) {
  const json* j = find(o, key);
  if (!j)
    return missing(where, key, required);
  if (!is(*j))
    return wrong(where, key, expected, *j);
  *out = j;
  return Got::kOk;
}

template <class T>
Got Checker::scalar(const json& o,
                    const char* key,
                    const std::string& where,
                    bool required,
                    const char* expected,
                    bool (json::*is)() const noexcept,
                    T* out) {
  const json* j = nullptr;
  const Got got = typed(
      o, key, where, required, expected, [&](const json& v) { return (v.*is)(); }, &j);
  if (got == Got::kOk)
    *out = j->get<T>();
  return got;
}

Got Checker::object(const json& o,
                    const char* key,
                    const std::string& where,
                    const json** out,
                    bool required) {
  return typed(
      o, key, where, required, "an object", [](const json& j) { return j.is_object(); }, out);
}

Got Checker::array(const json& o,
                   const char* key,
                   const std::string& where,
                   const json** out,
                   bool required) {
  return typed(
      o, key, where, required, "an array", [](const json& j) { return j.is_array(); }, out);
}

Got Checker::boolean(const json& o, const char* key, const std::string& where, bool* out) {
  return scalar(o, key, where, false, "a boolean", &json::is_boolean, out);
}

Got Checker::string(const json& o,
                    const char* key,
                    const std::string& where,
                    std::string* out,
                    bool required) {
  return scalar(o, key, where, required, "a string", &json::is_string, out);
}

Got Checker::uinteger(const json& o,
                      const char* key,
                      const std::string& where,
                      std::uint64_t* out,
                      bool required) {
  const json* j = find(o, key);
  if (!j)
    return missing(where, key, required);
  if (j->is_number_unsigned()) {
    *out = j->get<std::uint64_t>();
    return Got::kOk;
  }
  if (j->is_number_integer()) {
    add(where, std::string(key) + " is negative (" + std::to_string(j->get<std::int64_t>()) + ")");
    return Got::kBad;
  }
  return wrong(where, key, "a non-negative integer", *j);
}

Got Checker::index(const json& o,
                   const char* key,
                   std::size_t count,
                   const char* things,
                   const std::string& where,
                   std::int32_t* out,
                   bool required) {
  const json* j = find(o, key);
  if (!j)
    return missing(where, key, required);
  return indexValue(*j, key, count, things, where, out);
}

Got Checker::indexValue(const json& j,
                        const std::string& key,
                        std::size_t count,
                        const char* things,
                        const std::string& where,
                        std::int32_t* out) {
  if (!j.is_number_integer()) {
    add(where, key + " must be an integer index, got " + std::string(j.type_name()));
    return Got::kBad;
  }
  const bool negative = !j.is_number_unsigned();
  if (negative || j.get<std::uint64_t>() >= count) {
    const std::string value =
        negative ? std::to_string(j.get<std::int64_t>()) : std::to_string(j.get<std::uint64_t>());
    add(where,
        key + " index " + value + " out of range (" + std::to_string(count) + " " + things + ")");
    return Got::kBad;
  }
  *out = static_cast<std::int32_t>(j.get<std::uint64_t>());
  return Got::kOk;
}

Got Checker::number(const json& o, const char* key, const std::string& where, double* out) {
  const json* j = nullptr;
  const Got got = typed(
      o, key, where, false, "a number", [](const json& v) { return v.is_number(); }, &j);
  if (got != Got::kOk)
    return got;
  const double v = j->get<double>();
  if (!std::isfinite(v)) {
    add(where, std::string(key) + " is not finite");
    return Got::kBad;
  }
  *out = v;
  return Got::kOk;
}

Got Checker::bounded(const json& o,
                     const char* key,
                     const std::string& where,
                     double* out,
                     double min,
                     bool exclusive) {
  double v = 0.0;
  const Got got = number(o, key, where, &v);
  if (got != Got::kOk)
    return got;
  if (exclusive ? !(v > min) : !(v >= min)) {
    add(where, std::string(key) + " must be " + (exclusive ? "> " : ">= ") + formatNumber(min) +
                   ", got " + formatNumber(v));
    return Got::kBad;
  }
  *out = v;
  return Got::kOk;
}

Got Checker::vector(const json& o,
                    const char* key,
                    std::size_t n,
                    const std::string& where,
                    double* out) {
  const json* j = find(o, key);
  if (!j)
    return Got::kAbsent;
  if (!j->is_array() || j->size() != n) {
    add(where, std::string(key) + " must be an array of " + std::to_string(n) + " numbers");
    return Got::kBad;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const json& e = (*j)[i];
    const std::string item = std::string(key) + "[" + std::to_string(i) + "]";
    if (!e.is_number()) {
      add(where, item + " must be a number, got " + e.type_name());
      return Got::kBad;
    }
    out[i] = e.get<double>();
    if (!std::isfinite(out[i])) {
      add(where, item + " is not finite");
      return Got::kBad;
    }
  }
  return Got::kOk;
}

Got Checker::vec3(const json& o, const char* key, const std::string& where, geom::Vec3* out) {
  double v[3];
  const Got got = vector(o, key, 3, where, v);
  if (got == Got::kOk)
    *out = {v[0], v[1], v[2]};
  return got;
}

Got Checker::quaternion(const json& o, const char* key, const std::string& where, geom::Quat* out) {
  double v[4];
  const Got got = vector(o, key, 4, where, v);
  if (got != Got::kOk)
    return got;
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
  if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
    add(where, std::string(key) + " is not a unit quaternion (norm " + formatNumber(norm) +
                   "; tolerance " + formatNumber(kUnitQuaternionTolerance) + ")");
    return Got::kBad;
  }
  *out = geom::Quat(v[3] / norm, v[0] / norm, v[1] / norm, v[2] / norm);
  return Got::kOk;
}

Got Checker::strings(const json& o,
                     const char* key,
                     const std::string& where,
                     std::vector<std::string>* out) {
  const auto all_strings = [](const json& j) {
    if (!j.is_array())
      return false;
    for (const json& e : j) {
      if (!e.is_string())
        return false;
    }
    return true;
  };
  const json* j = nullptr;
  const Got got = typed(o, key, where, false, "an array of strings", all_strings, &j);
  if (got == Got::kOk) {
    for (const json& e : *j)
      out->push_back(e.get<std::string>());
  }
  return got;
}

Got Checker::choice(const json& o,
                    const char* key,
                    const std::string& where,
                    const std::vector<std::string>& names,
                    std::size_t* out) {
  std::string s;
  const Got got = string(o, key, where, &s);
  if (got != Got::kOk)
    return got;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == s) {
      *out = i;
      return Got::kOk;
    }
  }
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : ", ") + inQuotes(names[i]);
  add(where, std::string(key) + " " + inQuotes(s) + " is not one of " + list);
  return Got::kBad;
}

Got Checker::missing(const std::string& where, const char* key, bool required) {
  if (!required)
    return Got::kAbsent;
  add(where, std::string("required property ") + key + " is missing");
  return Got::kBad;
}

Got Checker::wrong(const std::string& where, const char* key, const char* expected, const json& j) {
  add(where, std::string(key) + " must be " + expected + ", got " + j.type_name());
  return Got::kBad;
}

}  // namespace hapticd::scene::detail
