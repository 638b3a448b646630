#pragma once
// The control API of the fake DHD library (fake_dhd.cpp, built as a shared library by the
// tests), and a loader that binds it from the same library the device loads (dlopen of the same
// path gives the same instance).
#include <dlfcn.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

inline constexpr std::uint64_t kFakeDhdForceCapacity = 1 << 16;

/// One recorded force call, in the SDK's frame, and whether forces were on when it came.
struct FakeDhdForce {
  double force[3];
  double torque[3];
  double gripper;
  int forces_on;
};

struct FakeDhdState {
  bool open, forces_on, brakes, gravity;
  std::uint64_t force_calls;  ///< every force call, including those past the record's capacity
  std::uint64_t opens;
};

extern "C" {
/// device_count devices of SDK system type `type` (104 sigma.7, 35 omega.7, 33 omega.3), all
/// present, closed, at the origin, nothing recorded.
void fakedhd_reset(int device_count, int type);
/// SDK frame: position (m) and orientation frame (row-major 3x3).
void fakedhd_set_pose(int index, const double p[3], const double R[9]);
void fakedhd_set_buttons(int index, unsigned mask, double gripper_rad);
/// The next `count` calls on the device fail with SDK error `error`.
void fakedhd_fail(int index, int error, int count);
/// Unplugged (0: every call fails with DHD_ERROR_COM, the device count drops) or back (1).
void fakedhd_set_present(int index, int present);
FakeDhdState fakedhd_state(int index);
const FakeDhdForce* fakedhd_forces(int index);
}

/// The control API bound from the fake library at `path`.
struct FakeDhd {
  decltype(&fakedhd_reset) reset;
  decltype(&fakedhd_set_pose) set_pose;
  decltype(&fakedhd_set_buttons) set_buttons;
  decltype(&fakedhd_fail) fail;
  decltype(&fakedhd_set_present) set_present;
  decltype(&fakedhd_state) state;
  decltype(&fakedhd_forces) forces;

  explicit FakeDhd(const std::string& path) {
    void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (h == nullptr)
      throw std::runtime_error("cannot load " + path);
    bind(h, reset, "fakedhd_reset");
    bind(h, set_pose, "fakedhd_set_pose");
    bind(h, set_buttons, "fakedhd_set_buttons");
    bind(h, fail, "fakedhd_fail");
    bind(h, set_present, "fakedhd_set_present");
    bind(h, state, "fakedhd_state");
    bind(h, forces, "fakedhd_forces");
  }

 private:
  template <class Fn>
  static void bind(void* h, Fn& fn, const char* name) {
    void* p = dlsym(h, name);
    if (p == nullptr)
      throw std::runtime_error(std::string("fake DHD lacks ") + name);
    std::memcpy(&fn, &p, sizeof fn);
  }
};
