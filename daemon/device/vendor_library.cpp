#include "daemon/device/vendor_library.h"

#include <dlfcn.h>

#include <cstdlib>

namespace hapticd::device {

std::vector<std::string> VendorLibrary::candidates(const std::string& configured,
                                                   const char* env_var,
                                                   std::initializer_list<const char*> defaults) {
  if (!configured.empty())
    return {configured};
  if (const char* env = std::getenv(env_var); env != nullptr && *env != '\0')
    return {env};
  return {defaults.begin(), defaults.end()};
}

Result<VendorLibrary> VendorLibrary::open(const std::vector<std::string>& names) {
  std::string tried, last_error;
  for (const std::string& name : names) {
    if (void* h = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL); h != nullptr) {
      VendorLibrary lib;
      lib.handle_ = h;
      lib.path_ = name;
      return lib;
    }
    const char* e = dlerror();
    last_error = e != nullptr ? e : "not found";
    tried += (tried.empty() ? "" : ", ") + name;
  }
  return Error{"tried " + tried + ": " + last_error};
}

void* VendorLibrary::symbol(const char* name) const {
  return handle_ != nullptr ? dlsym(handle_, name) : nullptr;
}

}  // namespace hapticd::device
