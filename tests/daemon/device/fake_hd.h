#pragma once
// The control API of the fake OpenHaptics HD library (fake_hd.cpp, built as a shared library by
// the tests), and a loader that binds it from the same library the device loads.
#include <dlfcn.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

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

extern "C" {
/// One device named "Default Device" (also the default), model `model`, input DOF 6, output DOF
/// `output_dof`, nominal continuous force `force_n`, torque `torque_mnm`; at the origin; nothing
/// recorded or scripted.
void fakehd_reset(const char* model, int output_dof, double force_n, double torque_mnm);
/// The stylus position (mm) and orientation (column-major 3x3).
void fakehd_set_pose(const double p_mm[3], const double R[9]);
void fakehd_set_calibration(int state);
/// Schedules an event at scheduler frame `frame` (from 1; up to 16 events).
void fakehd_at(std::uint64_t frame, int event, int arg);
/// True while the scheduler waits at a kFakeHdPause.
int fakehd_paused();
void fakehd_resume();
std::uint64_t fakehd_frames();
/// Frames whose output was recorded (every frame that set a force), and the record.
std::uint64_t fakehd_frame_count();
const FakeHdFrame* fakehd_records();
/// Calls of the state functions outside hdBeginFrame / hdEndFrame, and from a thread other than
/// the scheduler's (both must stay 0).
std::uint64_t fakehd_misuse();
/// Called at the end of every frame on the scheduler thread (the tests count allocations there).
void fakehd_set_frame_hook(void (*hook)(void*), void* data);
}

struct FakeHd {
  decltype(&fakehd_reset) reset;
  decltype(&fakehd_set_pose) set_pose;
  decltype(&fakehd_set_calibration) set_calibration;
  decltype(&fakehd_at) at;
  decltype(&fakehd_paused) paused;
  decltype(&fakehd_resume) resume;
  decltype(&fakehd_frames) frames;
  decltype(&fakehd_frame_count) frame_count;
  decltype(&fakehd_records) records;
  decltype(&fakehd_misuse) misuse;
  decltype(&fakehd_set_frame_hook) set_frame_hook;

  explicit FakeHd(const std::string& path) {
    void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (h == nullptr)
      throw std::runtime_error("cannot load " + path);
    bind(h, reset, "fakehd_reset");
    bind(h, set_pose, "fakehd_set_pose");
    bind(h, set_calibration, "fakehd_set_calibration");
    bind(h, at, "fakehd_at");
    bind(h, paused, "fakehd_paused");
    bind(h, resume, "fakehd_resume");
    bind(h, frames, "fakehd_frames");
    bind(h, frame_count, "fakehd_frame_count");
    bind(h, records, "fakehd_records");
    bind(h, misuse, "fakehd_misuse");
    bind(h, set_frame_hook, "fakehd_set_frame_hook");
  }

 private:
  template <class Fn>
  static void bind(void* h, Fn& fn, const char* name) {
    void* p = dlsym(h, name);
    if (p == nullptr)
      throw std::runtime_error(std::string("fake HD lacks ") + name);
    std::memcpy(&fn, &p, sizeof fn);
  }
};
