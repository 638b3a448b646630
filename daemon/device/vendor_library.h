#pragma once
/// \file
/// A vendor's proprietary shared library (the Force Dimension DHD SDK, ...), opened at run time
/// with dlopen so that hapticd builds and runs without it; its functions are bound by name into
/// typed pointers declared by the backend from the vendor's public documentation (no vendor
/// header is included).
///
/// Threads: open() and bind() off the servo thread; the bound pointers may be called from any
/// thread the vendor allows.

#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "core/common/result.h"

namespace hapticd::device {

class VendorLibrary {
 public:
  /// The names to try, in order: `configured` alone when not empty, else the value of the
  /// environment variable `env_var` when set and not empty, else `defaults`.
  static std::vector<std::string> candidates(const std::string& configured,
                                             const char* env_var,
                                             std::initializer_list<const char*> defaults);
  /// Opens the first of `names` that loads (RTLD_NOW | RTLD_LOCAL). The library stays loaded for
  /// the life of the process (vendor libraries run threads of their own; unloading one is not
  /// safe). Fails with every name tried and the loader's last message.
  static Result<VendorLibrary> open(const std::vector<std::string>& names);

  /// The name that loaded.
  const std::string& path() const { return path_; }
  /// Binds `fn` to the exported symbol `name`; false (fn null) when it is missing.
  template <class Fn>
  bool bind(Fn*& fn, const char* name) const {
    void* p = symbol(name);
    static_assert(sizeof(fn) == sizeof(p));
    std::memcpy(&fn, &p, sizeof fn);  // object pointer to function pointer, as dlsym returns it
    return p != nullptr;
  }

 private:
  void* symbol(const char* name) const;
  void* handle_ = nullptr;
  std::string path_;
};

/// Binds a vendor library's functions by name, collecting the names that are missing.
class SymbolBinder {
 public:
  explicit SymbolBinder(const VendorLibrary& library) : library_(library) {}
  template <class Fn>
  void operator()(Fn*& fn, const char* name) {
    if (!library_.bind(fn, name))
      missing_ += (missing_.empty() ? "" : ", ") + std::string(name);
  }
  /// The missing names, comma-separated ("" when all were found).
  const std::string& missing() const { return missing_; }

 private:
  const VendorLibrary& library_;
  std::string missing_;
};

}  // namespace hapticd::device
