#pragma once
/// \file
/// An enum's names from one table: its text (config files, the command line, the status) and
/// its parser, so that the two never disagree. Any thread; names() and parse() allocate only for
/// the error.

#include <cstddef>
#include <string>
#include <string_view>

#include "core/common/result.h"

namespace hapticd::daemon {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

/// The name of `v` in `table`, "?" when it has none.
template <class E, std::size_t N>
const char* nameIn(const EnumName<E> (&table)[N], E v) {
  for (const auto& e : table)
    if (e.value == v)
      return e.name;
  return "?";
}

/// The value named `text`. Error: `prefix` then "\"TEXT\" is not one of \"a\", \"b\"".
template <class E, std::size_t N>
Result<E> parseIn(const EnumName<E> (&table)[N], std::string_view text, const char* prefix = "") {
  std::string names;
  for (const auto& e : table) {
    if (text == e.name)
      return e.value;
    names += (names.empty() ? "\"" : ", \"") + std::string(e.name) + "\"";
  }
  return Error{std::string(prefix) + "\"" + std::string(text) + "\" is not one of " + names};
}

}  // namespace hapticd::daemon
