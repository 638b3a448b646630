#pragma once
// The control API of the fake OpenHaptics HD library (fake_hd.cpp, built as a shared library by
// the tests), bound from the same library the device loads (fake_vendor.h).
#include <cstdint>

#include "tests/daemon/device/fake_vendor.h"

inline constexpr std::uint64_t kFakeHdForceCapacity = 1 << 16;

/// One frame's output as the fake received it: force (N) and gimbal torque (mN m).
struct FakeHdFrame {
  double force[3];
  double torque[3];
};

/// What happens at a scheduler frame (fakehd_at).
enum FakeHdEvent : int {
  kFakeHdDisconnect = 1,  ///< every call fails with HD_COMM_ERROR until reconnected
  kFakeHdReconnect = 2,
  kFakeHdError = 3,   ///< one error `arg` on the stack
  kFakeHdPause = 4,   ///< the scheduler waits here until fakehd_resume()
  kFakeHdButtons = 5  ///< the buttons become `arg`
};

/// The control API of the fake HD library: the table its one exported function, fakehd_control(),
/// returns.
struct FakeHdControl {
  /// One device named "Default Device" (also the default), model `model`, input DOF 6, output
  /// DOF `output_dof`, nominal continuous force `force_n`, torque `torque_mnm`; at the origin;
  /// nothing recorded or scripted.
  void (*reset)(const char* model, int output_dof, double force_n, double torque_mnm);
  /// The stylus position (mm) and orientation (column-major 3x3).
  void (*set_pose)(const double p_mm[3], const double R[9]);
  void (*set_calibration)(int state);
  /// Schedules an event at scheduler frame `frame` (from 1; up to 16 events).
  void (*at)(std::uint64_t frame, int event, int arg);
  /// True while the scheduler waits at a kFakeHdPause.
  int (*paused)();
  void (*resume)();
  std::uint64_t (*frames)();
  /// Frames whose output was recorded (every frame that set a force), and the record.
  std::uint64_t (*frame_count)();
  const FakeHdFrame* (*records)();
  /// Calls of the state functions outside hdBeginFrame / hdEndFrame, and from a thread other
  /// than the scheduler's (both must stay 0).
  std::uint64_t (*misuse)();
  /// Called at the end of every frame on the scheduler thread (the tests count allocations
  /// there).
  void (*set_frame_hook)(void (*hook)(void*), void* data);
};

extern "C" const FakeHdControl* fakehd_control();

#ifdef HAPTICD_FAKE_HD
/// The control API of the fake library the tests' devices load (HAPTICD_FAKE_HD, its path).
inline const FakeHdControl& fakeHd() {
  return fakeControl<FakeHdControl>(HAPTICD_FAKE_HD, "fakehd_control");
}
#endif
