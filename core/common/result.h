#pragma once
/// \file
/// A small result type for failures outside the servo thread (C++20 has no std::expected).

#include <string>
#include <utility>
#include <variant>

namespace hapticd {

/// What went wrong, in words a user can act on.
struct Error {
  std::string message;
};

/// Either a value or an Error. Any thread.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace hapticd
