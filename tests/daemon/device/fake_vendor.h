#pragma once
// What the fake vendor libraries share (fake_dhd.cpp, fake_hd.cpp: shared libraries built by the
// tests and loaded by path like the real SDKs): the scripted pose a fake device reports, and, on
// the tests' side, the loader of a fake's control API. Each fake exports one control function that
// returns its table of control functions (fake_dhd.h, fake_hd.h); dlopen of the path the device
// loads gives the same instance, so the table drives the very library the device calls.
#include <dlfcn.h>

#include <atomic>
#include <cstring>
#include <stdexcept>
#include <string>

/// A scripted pose, in the SDK's own units and layout (position, 3x3 orientation as 9 numbers);
/// atomic: the test thread sets it while the servo thread reads it. Starts at the origin.
struct FakePose {
  std::atomic<double> p[3] = {0.0, 0.0, 0.0};
  std::atomic<double> R[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};

  void set(const double p_in[3], const double R_in[9]) {
    for (int i = 0; i < 3; ++i)
      p[i] = p_in[i];
    for (int i = 0; i < 9; ++i)
      R[i] = R_in[i];
  }
  /// Back to the origin, unrotated.
  void reset() {
    const double origin[3] = {0.0, 0.0, 0.0};
    const double identity[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
    set(origin, identity);
  }
};

namespace fake_vendor_detail {
template <class Control>
const Control& bindControl(const std::string& path, const char* symbol) {
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (h == nullptr)
    throw std::runtime_error("cannot load " + path);
  void* p = dlsym(h, symbol);
  if (p == nullptr)
    throw std::runtime_error(path + " lacks " + symbol);
  const Control* (*table)() = nullptr;
  std::memcpy(&table, &p, sizeof table);
  return *table();
}
}  // namespace fake_vendor_detail

/// The control table of the fake library at `path`: what its exported function `symbol` returns,
/// bound at the first call (one library per Control type). Throws std::runtime_error naming the
/// library when it cannot be loaded or lacks the symbol. Allocates nothing once bound (the tests
/// call it on the servo thread while counting allocations).
template <class Control>
const Control& fakeControl(const char* path, const char* symbol) {
  static const Control& c = fake_vendor_detail::bindControl<Control>(path, symbol);
  return c;
}
