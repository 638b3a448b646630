#pragma once
// The control API of the fake DHD library (fake_dhd.cpp, built as a shared library by the
// tests), bound from the same library the device loads (fake_vendor.h).
#include <cstdint>

#include "tests/daemon/device/fake_vendor.h"

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

/// The control API of the fake DHD library: the table its one exported function,
/// fakedhd_control(), returns.
struct FakeDhdControl {
  /// device_count devices of SDK system type `type` (104 sigma.7, 35 omega.7, 33 omega.3), all
  /// present, closed, at the origin, nothing recorded.
  void (*reset)(int device_count, int type);
  /// SDK frame: position (m) and orientation frame (row-major 3x3).
  void (*set_pose)(int index, const double p[3], const double R[9]);
  void (*set_buttons)(int index, unsigned mask, double gripper_rad);
  /// The next `count` calls on the device fail with SDK error `error`.
  void (*fail)(int index, int error, int count);
  /// Unplugged (0: every call fails with DHD_ERROR_COM, the device count drops) or back (1).
  void (*set_present)(int index, int present);
  FakeDhdState (*state)(int index);
  const FakeDhdForce* (*forces)(int index);
};

extern "C" const FakeDhdControl* fakedhd_control();

#ifdef HAPTICD_FAKE_DHD
/// The control API of the fake library the tests' devices load (HAPTICD_FAKE_DHD, its path).
inline const FakeDhdControl& fakeDhd() {
  return fakeControl<FakeDhdControl>(HAPTICD_FAKE_DHD, "fakedhd_control");
}
#endif
